// Predicted masks rendered in undistorted views are scored in the photos'
// geometry when op2gs-sfm recorded the photos' cameras.

#include "eval/metrics/photo_geometry.h"

#include <gtest/gtest.h>

#include "eval/metrics/mask_metrics.h"
#include "splat/camera_distortion.h"
#include "splat/sfm/sfm_run.h"
#include "tests/test_util.h"

namespace eval {
namespace {

namespace fs = std::filesystem;
using testing_util::TempDir;

// A 160x120 view "view.png" of the given camera model.
splat::ColmapModel one_view(int model_id, std::vector<double> params) {
  return testing_util::one_view_model({1, model_id, 160, 120, std::move(params)}, "view.png");
}

// Object 7: a disc near the top-left corner, where the distortion is strongest.
splat::IdMap ground_truth() {
  splat::IdMap m(160, 120);
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 160; ++x)
      if ((x - 30) * (x - 30) + (y - 25) * (y - 25) < 15 * 15) m.at(x, y) = 7;
  return m;
}

Mask mask_of(const splat::IdMap& map, int id) {
  Mask m(map.width, map.height);
  for (size_t i = 0; i < map.ids.size(); ++i) m.on[i] = map.ids[i] == id;
  return m;
}

struct PhotoScene {
  TempDir dir;
  splat::ColmapModel photo = one_view(4, {140, 140, 80, 60, -0.3, 0.08, 0, 0});  // OPENCV
  splat::ColmapModel view = one_view(1, {140, 140, 80, 60});                     // PINHOLE
  PhotoScene() {
    splat::write_colmap_model(photo, dir / splat::kPhotoCamerasDir, splat::ColmapFormat::kText);
    splat::write_colmap_model(view, dir / "sparse" / "0", splat::ColmapFormat::kText);
  }
  // A perfect render: the truth undistorted as the photos were, at `scale`.
  Mask perfect_render(int scale) const {
    splat::ColmapCamera small = view.cameras.at(1);
    small.width /= scale, small.height /= scale;
    for (double& p : small.params) p /= scale;
    return mask_of(splat::undistort_id_map(ground_truth(), photo.cameras.at(1), small), 7);
  }
};

TEST(PhotoGeometry, PerfectRenderScoresAsPerfectInThePhoto) {
  PhotoScene scene;
  const PhotoGeometry photos(scene.dir.path());
  ASSERT_TRUE(photos.active());
  const Mask truth = mask_of(ground_truth(), 7);
  for (int scale : {1, 2}) {
    const Mask render = scene.perfect_render(scale);
    const ObjectMasks moved = photos.to_photo("view.png", {{7, render}});
    ASSERT_EQ(moved.at(7).width, 160);
    ASSERT_EQ(moved.at(7).height, 120);
    EXPECT_GT(mask_iou(truth, moved.at(7)), scale == 1 ? 0.95 : 0.9) << scale;
    // Compared as they are, the distortion alone costs much of the score.
    EXPECT_LT(mask_iou(truth, resize_mask_nearest(render, 160, 120)), 0.75) << scale;
  }
}

TEST(PhotoGeometry, ScenesWithoutPhotoCamerasAreScoredAsTheyAre) {
  TempDir dir;
  const PhotoGeometry photos(dir.path());
  EXPECT_FALSE(photos.active());
  const Mask render = mask_of(ground_truth(), 7);
  EXPECT_EQ(photos.to_photo("view.png", {{7, render}}).at(7).on, render.on);
}

TEST(PhotoGeometry, ViewsMissingFromTheModelsAreLeftAlone) {
  PhotoScene scene;
  const PhotoGeometry photos(scene.dir.path());
  const Mask render = scene.perfect_render(1);
  EXPECT_EQ(photos.to_photo("other.png", {{7, render}}).at(7).on, render.on);
}

}  // namespace
}  // namespace eval
