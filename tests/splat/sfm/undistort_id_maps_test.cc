// ID maps resampled as COLMAP undistorts the photos: checked against COLMAP's
// own undistorter, run on an ID map saved as a photo.

#include "splat/sfm/undistort_id_maps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "splat/camera_distortion.h"
#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/sfm/colmap_command.h"
#include "tests/test_util.h"

namespace splat {
namespace {

namespace fs = std::filesystem;
using testing_util::TempDir;

// IDs 1.. in 16x16 blocks, so that most pixels lie far from a boundary.
IdMap block_map(int width, int height, int block) {
  IdMap map(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      map.ids[size_t(y) * width + x] = uint16_t(1 + (x / block) + 11 * (y / block));
  return map;
}

ColmapCamera camera(int model_id, int width, int height, std::vector<double> params) {
  ColmapCamera c;
  c.camera_id = 1;
  c.model_id = model_id;
  c.width = width;
  c.height = height;
  c.params = std::move(params);
  return c;
}

// A photo whose red channel is the column and green the row: COLMAP's
// interpolated output then tells where it sampled each undistorted pixel.
ImageRGB coordinate_photo(int width, int height) {
  ImageRGB photo(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      photo.pixel(x, y)[0] = float(x) / 255;
      photo.pixel(x, y)[1] = float(y) / 255;
      photo.pixel(x, y)[2] = 0;
    }
  return photo;
}

// COLMAP's undistorter run on the coordinate photo of `distorted`, in `dir`:
// the PINHOLE camera it chose, and its output image.
std::pair<ColmapCamera, ImageRGB> colmap_undistortion(const ColmapCamera& distorted,
                                                      const fs::path& dir) {
  ColmapCommand colmap;
  if (!colmap.available())
    throw std::runtime_error("COLMAP is needed (scripts/setup.sh installs it)");
  write_image_rgb(dir / "images" / "view.png",
                  coordinate_photo(int(distorted.width), int(distorted.height)));
  write_colmap_model(testing_util::one_view_model(distorted, "view.png"), dir / "model",
                     ColmapFormat::kText);
  colmap.log_file = dir / "colmap.log";
  colmap.run("undistortion", "image_undistorter",
             {"--image_path", (dir / "images").string(), "--input_path", (dir / "model").string(),
              "--output_path", (dir / "und").string(), "--output_type", "COLMAP"});
  const ColmapModel und = read_colmap_model(dir / "und" / "sparse");
  return {und.cameras.begin()->second, read_image_rgb(dir / "und" / "images" / "view.png")};
}

class AgainstColmap : public ::testing::TestWithParam<ColmapCamera> {};

TEST_P(AgainstColmap, SamplesWhereColmapsUndistorterSamples) {
  TempDir dir;
  const ColmapCamera distorted = GetParam();
  const int W = int(distorted.width), H = int(distorted.height);
  const auto [pinhole, sampled] = colmap_undistortion(distorted, dir.path());

  // ID = column + 1: the nearest-neighbour result says which column we took.
  IdMap columns(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) columns.ids[size_t(y) * W + x] = uint16_t(x + 1);
  const IdMap ours = undistort_id_map(columns, distorted, pinhole);
  ASSERT_EQ(ours.width, sampled.width);
  ASSERT_EQ(ours.height, sampled.height);

  double sum_dx = 0, sum_dy = 0;
  size_t n = 0, far_column = 0;
  for (int y = 2; y < ours.height - 2; ++y)
    for (int x = 2; x < ours.width - 2; ++x) {
      const Eigen::Vector2d s = distorted_position(distorted, pinhole, x + 0.5, y + 0.5);
      if (s.x() < 2 || s.y() < 2 || s.x() > W - 2 || s.y() > H - 2) continue;
      // COLMAP interpolates with pixel centres at integers: column = x - 0.5.
      const double colmap_x = 255 * sampled.pixel(x, y)[0], colmap_y = 255 * sampled.pixel(x, y)[1];
      sum_dx += colmap_x - (s.x() - 0.5);
      sum_dy += colmap_y - (s.y() - 0.5);
      far_column += std::abs(ours.ids[size_t(y) * ours.width + x] - 1 - colmap_x) > 1.01;
      ++n;
    }
  ASSERT_GT(n, size_t(ours.width) * ours.height / 2);
  // Quantised to whole columns, so only the mean is sub-pixel; half a pixel
  // of error (the usual pixel-centre mistake) would show as 0.5.
  EXPECT_LT(std::abs(sum_dx / n), 0.05);
  EXPECT_LT(std::abs(sum_dy / n), 0.05);
  EXPECT_EQ(far_column, 0u) << "of " << n;
}

// Undistorted renders go back to the photos' geometry for scoring: the
// inverse positions map forward onto the photo pixels they came from, and
// an ID map undistorted and sent back is the original, away from the ID
// boundaries (where nearest-neighbour sampling twice may move them a pixel).
TEST_P(AgainstColmap, PhotoPixelSourcesInvertTheUndistortion) {
  TempDir dir;
  const ColmapCamera distorted = GetParam();
  const int W = int(distorted.width), H = int(distorted.height);
  const ColmapCamera pinhole = colmap_undistortion(distorted, dir.path()).first;
  size_t inverted = 0;
  for (int y = 0; y < H; y += 7)
    for (int x = 0; x < W; x += 7) {
      const Eigen::Vector2d q = undistorted_position(distorted, pinhole, x + 0.5, y + 0.5);
      ASSERT_TRUE(q.allFinite()) << x << "," << y;
      const Eigen::Vector2d p = distorted_position(distorted, pinhole, q.x(), q.y());
      EXPECT_NEAR(p.x(), x + 0.5, 1e-5);
      EXPECT_NEAR(p.y(), y + 0.5, 1e-5);
      ++inverted;
    }
  EXPECT_GT(inverted, 500u);

  const IdMap photo = block_map(W, H, 16);
  const IdMap undistorted = undistort_id_map(photo, distorted, pinhole);
  const std::vector<int64_t> sources =
      photo_pixel_sources(distorted, pinhole, undistorted.width, undistorted.height);
  ASSERT_EQ(sources.size(), size_t(W) * H);
  size_t covered = 0, interior = 0, wrong = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int64_t s = sources[size_t(y) * W + x];
      if (s < 0) continue;
      ++covered;
      if (x % 16 < 3 || x % 16 > 12 || y % 16 < 3 || y % 16 > 12) continue;  // near a boundary
      ++interior;
      wrong += undistorted.ids[size_t(s)] != photo.ids[size_t(y) * W + x];
    }
  // COLMAP's undistorted view keeps most of the photo (it crops the rim).
  EXPECT_GT(covered, size_t(W) * H / 2);
  EXPECT_EQ(wrong, 0u) << "of " << interior;
}

INSTANTIATE_TEST_SUITE_P(
    Models, AgainstColmap,
    ::testing::Values(
        camera(4, 200, 150, {160, 155, 101, 74, -0.25, 0.06, 0.003, -0.002}),  // OPENCV
        camera(2, 200, 150, {160, 99, 76, 0.15}),                              // SIMPLE_RADIAL
        camera(5, 200, 150, {120, 118, 100, 75, 0.05, -0.02, 0.01, -0.003}),   // OPENCV_FISHEYE
        camera(3, 200, 150, {160, 99, 76, 0.12, -0.05}),                       // RADIAL
        camera(6, 200, 150,
               {160, 155, 101, 74, 0.1, -0.03, 0.002, 0.001, 0.01, 0.02, 0.005, 0.001}),
        camera(8, 200, 150, {120, 100, 75, 0.04}),          // SIMPLE_RADIAL_FISHEYE
        camera(9, 200, 150, {120, 100, 75, 0.04, -0.01})),  // RADIAL_FISHEYE
    [](const auto& info) { return camera_model_by_id(info.param.model_id)->name; });

TEST(UndistortIdMap, MapOfAnotherSizeIsScaledFirst) {
  // No distortion and the same intrinsics: the identity, whatever the map's size.
  const ColmapCamera cam = camera(4, 160, 120, {150, 150, 80, 60, 0, 0, 0, 0});
  const ColmapCamera pinhole = camera(1, 160, 120, {150, 150, 80, 60});
  const IdMap full = block_map(160, 120, 16);
  EXPECT_EQ(undistort_id_map(full, cam, pinhole).ids, full.ids);
  EXPECT_EQ(undistort_id_map(block_map(80, 60, 8), cam, pinhole).ids, full.ids);
}

TEST(UndistortIdMap, PixelsOutsideTheMapAreBackground) {
  const ColmapCamera cam = camera(4, 100, 100, {100, 100, 50, 50, 0, 0, 0, 0});
  const ColmapCamera wider = camera(1, 120, 100, {100, 100, 60, 50});  // 10 px more each side
  const IdMap out = undistort_id_map(block_map(100, 100, 16), cam, wider);
  EXPECT_EQ(out.ids[0], 0);
  EXPECT_EQ(out.ids[9], 0);
  EXPECT_EQ(out.ids[10], 1);
  EXPECT_EQ(out.ids[119], 0);
}

TEST(UndistortIdMap, UnsupportedModelIsAnErrorNamingTheMap) {
  TempDir dir;
  const ColmapCamera fov = camera(7, 40, 30, {40, 40, 20, 15, 0.9});
  write_id_map(dir / "sam2" / "v.png", block_map(40, 30, 8), 8);
  const ColmapModel distorted = testing_util::one_view_model(fov, "v.jpg");
  const ColmapModel undistorted =
      testing_util::one_view_model(camera(1, 40, 30, {40, 40, 20, 15}), "v.jpg");
  try {
    undistort_id_map_folder(dir / "sam2", dir / "out", distorted, undistorted);
    FAIL() << "FOV was undistorted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("v.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("FOV"), std::string::npos) << e.what();
  }
}

TEST(UndistortIdMap, FolderKeepsOtherFilesAndSkipsViewsWithoutMaps) {
  TempDir dir;
  write_id_map(dir / "sam2" / "a.png", block_map(40, 30, 8), 8);
  testing_util::write_file(dir / "sam2" / "objects.json", "[]");
  const ColmapCamera cam = camera(2, 40, 30, {40, 20, 15, 0.1});
  ColmapModel distorted = testing_util::one_view_model(cam, "a.jpg");
  ColmapImage b = distorted.images.at(1);
  b.image_id = 2;
  b.name = "b.jpg";  // no map
  distorted.images[2] = b;
  ColmapModel undistorted = distorted;
  undistorted.cameras[1] = camera(1, 38, 28, {40, 40, 19, 14});
  EXPECT_EQ(undistort_id_map_folder(dir / "sam2", dir / "out", distorted, undistorted), 1u);
  EXPECT_EQ(read_id_map(dir / "out" / "a.png").width, 38);
  EXPECT_TRUE(fs::exists(dir / "out" / "objects.json"));
  EXPECT_FALSE(fs::exists(dir / "out" / "b.png"));
}

}  // namespace
}  // namespace splat
