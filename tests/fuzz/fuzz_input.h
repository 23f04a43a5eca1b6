#pragma once
// What every fuzz harness shares: the parsers read files, so each input is
// written to a file of this process first; a parser may refuse any input
// with splat::InputError (that is its contract), anything else it throws,
// and any crash or sanitizer report, is a defect libFuzzer reports.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "splat/error.h"

namespace fuzz {

// A folder of this process under the temporary directory.
inline const std::filesystem::path& work_dir() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("op2gs_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

inline void write_file(const std::filesystem::path& file, const uint8_t* data, size_t size) {
  std::ofstream(file, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), std::streamsize(size));
}

// The input split at zero bytes into at most `parts` pieces (the last takes
// the rest), for parsers that read several files.
inline std::vector<std::string> split(const uint8_t* data, size_t size, size_t parts) {
  std::vector<std::string> out(1);
  for (size_t i = 0; i < size; ++i) {
    if (data[i] == 0 && out.size() < parts)
      out.emplace_back();
    else
      out.back().push_back(char(data[i]));
  }
  out.resize(parts);
  return out;
}

// Runs the parser; its refusals are expected, everything else aborts.
inline void expect_only_input_errors(const std::function<void()>& parse) {
  try {
    parse();
  } catch (const splat::InputError&) {
  }
}

}  // namespace fuzz
