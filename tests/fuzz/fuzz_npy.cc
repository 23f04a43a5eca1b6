// NumPy .npy arrays (3DOVS's poses_bounds.npy; splat/npy.h).
#include "splat/npy.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto file = fuzz::work_dir() / "poses_bounds.npy";
  fuzz::write_file(file, data, size);
  std::vector<size_t> shape;
  fuzz::expect_only_input_errors([&] { splat::read_npy(file, &shape); });
  return 0;
}
