// Integers of the JSON files the stages hand each other: checked, not cast.

#include "splat/json_integer.h"

#include <gtest/gtest.h>

namespace splat {
namespace {

TEST(JsonInteger, OutOfRangeAndFractionalValuesAreRefused) {
  const nlohmann::json ok = 42, big = 4294967296LL, negative = -1, fraction = 2.5, huge = 1.4e32;
  EXPECT_EQ(json_integer<int32_t>(ok, "f.json", "object"), 42);
  EXPECT_EQ(json_integer<int32_t>(negative, "f.json", "object"), -1);
  EXPECT_EQ(json_integer<int64_t>(big, "f.json", "area"), 4294967296LL);
  for (const nlohmann::json& bad : {big, fraction, huge})
    EXPECT_THROW(json_integer<int32_t>(bad, "f.json", "object"), InputError) << bad;
}

}  // namespace
}  // namespace splat
