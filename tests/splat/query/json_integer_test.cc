// The JSON the query stages read: integers are checked, not cast.

#include "splat/query/json_integer.h"

#include <gtest/gtest.h>

#include "splat/query/query_run.h"
#include "tests/test_util.h"

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

// Found by fuzzing: an object ID of 1.4e32 was cast to int (undefined).
TEST(JsonInteger, AQueryResultWithAHugeObjectIdNamesTheFileAndField) {
  testing_util::TempDir dir;
  testing_util::write_file(dir / "query.json",
                           R"({"objects": [1, 2], "queries": [{"query": "red chair",
                               "object": 144444444444444444444444444444444,
                               "similarity": 0.3, "similarities": [0.3, 0.1]}]})");
  try {
    read_query_results(dir / "query.json");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("query.json"), std::string::npos) << what;
    EXPECT_NE(what.find("\"object\""), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace splat
