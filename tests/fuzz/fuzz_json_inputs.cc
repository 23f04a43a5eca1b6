// The JSON files stages read from each other: query answers and object
// embeddings (splat/query/).
#include "splat/query/embed_run.h"
#include "splat/query/query_run.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto file = fuzz::work_dir() / "input.json";
  fuzz::write_file(file, data, size);
  fuzz::expect_only_input_errors([&] { splat::read_query_results(file); });
  fuzz::expect_only_input_errors([&] { splat::read_object_embeddings(file); });
  return 0;
}
