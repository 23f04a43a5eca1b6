// ID maps as PNG files, grey or palette (splat/id_maps.h).
#include "splat/id_maps.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto file = fuzz::work_dir() / "frame_00000.png";
  fuzz::write_file(file, data, size);
  fuzz::expect_only_input_errors([&] { splat::read_id_map(file); });
  return 0;
}
