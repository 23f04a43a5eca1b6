// op2gs-query's results as the stages after it read them.

#include <gtest/gtest.h>

#include "splat/error.h"
#include "splat/query/query_run.h"
#include "tests/test_util.h"

namespace splat {
namespace {

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
