// Training checkpoints (splat/checkpoint.h).
#include "splat/checkpoint.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto file = fuzz::work_dir() / "latest.ckpt";
  fuzz::write_file(file, data, size);
  fuzz::expect_only_input_errors([&] { splat::read_checkpoint_model(file); });
  fuzz::expect_only_input_errors([&] { splat::read_checkpoint_iteration(file); });
  return 0;
}
