#pragma once
// Integers read from the JSON files stages hand each other, checked.
// nlohmann's get<int32_t>() converts whatever number it finds: a float beyond
// the type's range (1e32 where an object ID belongs, met by fuzzing) is
// undefined behaviour, a large integer wraps around. These refuse both.

#include <fmt/format.h>

#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <vector>

#include "splat/error.h"

namespace splat {

template <typename Int>
Int json_integer(const nlohmann::json& value, const std::filesystem::path& file,
                 const char* field) {
  const bool fits = (value.is_number_unsigned() &&
                     value.get<uint64_t>() <= uint64_t(std::numeric_limits<Int>::max())) ||
                    (value.is_number_integer() && !value.is_number_unsigned() &&
                     value.get<int64_t>() >= int64_t(std::numeric_limits<Int>::min()) &&
                     value.get<int64_t>() <= int64_t(std::numeric_limits<Int>::max()));
  if (!fits)
    throw InputError(file, fmt::format("\"{}\" is {}, not an integer from {} to {}", field,
                                       value.dump().substr(0, 40), std::numeric_limits<Int>::min(),
                                       std::numeric_limits<Int>::max()));
  return Int(value.get<int64_t>());
}

template <typename Int>
std::vector<Int> json_integers(const nlohmann::json& array, const std::filesystem::path& file,
                               const char* field) {
  if (!array.is_array()) throw InputError(file, fmt::format("\"{}\" is not a list", field));
  std::vector<Int> out;
  for (const nlohmann::json& v : array) out.push_back(json_integer<Int>(v, file, field));
  return out;
}

}  // namespace splat
