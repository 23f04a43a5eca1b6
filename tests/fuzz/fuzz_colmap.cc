// COLMAP models, text or binary (splat/colmap_model.h): the input is split
// at zero bytes into cameras, images and points3D. COLMAP_FORMAT picks the
// format at build time.
#include <fstream>

#include "splat/colmap_model.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto dir = fuzz::work_dir() / "sparse";
  std::filesystem::create_directories(dir);
  const std::vector<std::string> parts = fuzz::split(data, size, 3);
  const char* ext = COLMAP_BINARY ? ".bin" : ".txt";
  const char* names[3] = {"cameras", "images", "points3D"};
  for (int i = 0; i < 3; ++i)
    std::ofstream(dir / (std::string(names[i]) + ext), std::ios::binary | std::ios::trunc)
        << parts[i];
  fuzz::expect_only_input_errors([&] {
    splat::read_colmap_model(dir,
                             COLMAP_BINARY ? splat::ColmapFormat::kBinary : splat::ColmapFormat::kText);
  });
  return 0;
}
