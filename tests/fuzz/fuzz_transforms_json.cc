// nerfstudio / instant-ngp transforms.json (splat/sfm/transforms_json.h),
// beside one real 8x6 photo, images/a.png, that frames may name.
#include "splat/image.h"
#include "splat/sfm/transforms_json.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto dir = fuzz::work_dir() / "capture";
  static const bool photo = [&] {
    splat::write_image_rgb(dir / "images" / "a.png", splat::ImageRGB(8, 6));
    return true;
  }();
  (void)photo;
  fuzz::write_file(dir / "transforms.json", data, size);
  fuzz::expect_only_input_errors(
      [&] { splat::read_transforms_json(dir / "transforms.json", dir / "images"); });
  return 0;
}
