#include "splat/photo_cameras.h"

#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace splat {
namespace {

namespace fs = std::filesystem;

const ColmapCamera kView{1, 1, 8, 6, {10, 10, 4, 3}};  // PINHOLE 8x6

TEST(PhotoCameras, EmptyWhenTheViewsAreThePhotos) {
  const testing_util::TempDir scene;
  write_colmap_model(testing_util::one_view_model(kView, "a.png"), scene / "sparse/0",
                     ColmapFormat::kText);
  EXPECT_TRUE(PhotoCameras::load(scene.path()).empty());
}

TEST(PhotoCameras, UndistortedPhotoSamplesTheRenderPixelForPixel) {
  const testing_util::TempDir scene;
  write_colmap_model(testing_util::one_view_model(kView, "a.png"), scene / "sparse/0",
                     ColmapFormat::kText);
  write_colmap_model(testing_util::one_view_model(kView, "a.png"), scene / kPhotoCamerasDir,
                     ColmapFormat::kBinary);
  const PhotoCameras cameras = PhotoCameras::load(scene.path());
  ASSERT_FALSE(cameras.empty());
  EXPECT_FALSE(cameras.sampling("other.png", 8, 6).has_value());

  const auto same = cameras.sampling("a.png", 8, 6);
  ASSERT_TRUE(same.has_value());
  EXPECT_EQ(same->width, 8);
  EXPECT_EQ(same->height, 6);
  for (size_t i = 0; i < same->sources.size(); ++i) EXPECT_EQ(same->sources[i], int64_t(i));

  // A render at half the size: each photo pixel takes the render pixel it falls in.
  const auto half = cameras.sampling("a.png", 4, 3);
  ASSERT_TRUE(half.has_value());
  EXPECT_EQ(half->sources[0], 0);
  EXPECT_EQ(half->sources[1], 0);
  EXPECT_EQ(half->sources[2], 1);
  EXPECT_EQ(half->sources[size_t(5 * 8 + 7)], int64_t(2 * 4 + 3));
  const std::vector<int> render = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  const std::vector<int> photo = half->gather<int>(render, -1);
  EXPECT_EQ(photo[0], 1);
  EXPECT_EQ(photo[2], 2);
  EXPECT_EQ(photo.back(), 12);
}

TEST(PhotoCameras, PixelsTheViewCroppedAwayAreOutside) {
  const testing_util::TempDir scene;
  // The photo is wider than the view around the same centre: its outer
  // columns fall outside the render.
  const ColmapCamera photo{1, 1, 12, 6, {10, 10, 6, 3}};
  write_colmap_model(testing_util::one_view_model(kView, "a.png"), scene / "sparse/0",
                     ColmapFormat::kText);
  write_colmap_model(testing_util::one_view_model(photo, "a.png"), scene / kPhotoCamerasDir,
                     ColmapFormat::kText);
  const auto s = PhotoCameras::load(scene.path()).sampling("a.png", 8, 6);
  ASSERT_TRUE(s.has_value());
  const std::vector<float> render(48, 1.f);
  const std::vector<float> out = s->gather<float>(render, -1.f);
  EXPECT_EQ(out[0], -1.f);      // column 0 lies left of the view
  EXPECT_EQ(out[11], -1.f);     // column 11 right of it
  EXPECT_EQ(out[6], 1.f);       // the centre is seen
  EXPECT_EQ(s->sources[2], 0);  // photo column 2 is view column 0
}

}  // namespace
}  // namespace splat
