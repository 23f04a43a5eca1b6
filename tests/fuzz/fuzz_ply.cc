// PLY files: 3DGS models and point clouds (splat/ply.h).
#include "splat/ply.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto file = fuzz::work_dir() / "model.ply";
  fuzz::write_file(file, data, size);
  fuzz::expect_only_input_errors([&] { splat::read_gaussian_ply(file); });
  fuzz::expect_only_input_errors([&] { splat::read_point_ply(file); });
  return 0;
}
