// The 3DOVS metric on hand-computed cases and the layout the synthetic
// generator writes.

#include "eval/metrics/ovs.h"

#include <gtest/gtest.h>

#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "synth/generator.h"
#include "tests/test_util.h"
#include "tests/tiny_scene.h"

namespace eval {
namespace {

Mask pixels_on(int w, int h, std::vector<int> on) {
  Mask m(w, h);
  for (int p : on) m.on[p] = 1;
  return m;
}

TEST(Ovs, OneHotArgmaxIouAndAccuracy) {
  // 4 pixels, classes a, b. Ground truth: a on {0, 1}, b on {2}; pixel 3 has
  // no class (always wrong for the accuracy).
  const std::vector<Mask> truth = {pixels_on(4, 1, {0, 1}), pixels_on(4, 1, {2})};
  // Scores: pixel 0 -> a, 1 -> b, 2 -> b, 3: all zero -> a (the first class).
  const std::vector<std::vector<float>> scores = {{0.9f, 0.2f, 0.1f, 0.f}, {0.1f, 0.6f, 0.8f, 0.f}};
  const OvsViewScore s = score_ovs_view(truth, scores, 4, 1);
  EXPECT_DOUBLE_EQ(s.iou[0], 1.0 / 3.0);    // pred a {0, 3}, gt a {0, 1}
  EXPECT_DOUBLE_EQ(s.iou[1], 1.0 / 2.0);    // pred b {1, 2}, gt b {2}
  EXPECT_DOUBLE_EQ(s.accuracy, 2.0 / 4.0);  // pixels 0 and 2
}

TEST(Ovs, AbsentClassScoresZeroNotNan) {
  const std::vector<Mask> truth = {pixels_on(2, 1, {0, 1}), Mask(2, 1)};
  const OvsViewScore s = score_ovs_view(truth, {{1.f, 1.f}, {0.f, 0.f}}, 2, 1);
  EXPECT_DOUBLE_EQ(s.iou[0], 1.0);
  EXPECT_DOUBLE_EQ(s.iou[1], 0.0);
}

TEST(Ovs, OracleTakesTheBestObjectPerClass) {
  testing_util::TempDir dir;
  // Images a..c; segmentations for views 0 and 2; classes cup, bear (sorted: bear, cup).
  for (const char* v : {"a.png", "b.png", "c.png"})
    testing_util::write_file(dir / "images" / v, "x");
  testing_util::write_file(dir / "segmentations/classes.txt", "cup\nbear\n");
  auto write = [&](const std::string& f, std::vector<int> on) {
    const Mask m = pixels_on(4, 1, on);
    splat::write_mask_png(dir / "segmentations" / f, 4, 1, m.on);
  };
  write("00/cup.png", {0, 1});
  write("00/bear.png", {2, 3});
  write("02/cup.png", {0});
  const OvsGroundTruth gt = read_ovs_ground_truth(dir.path());
  EXPECT_EQ(gt.classes, (std::vector<std::string>{"bear", "cup"}));
  EXPECT_EQ(gt.views, (std::vector<size_t>{0, 2}));
  EXPECT_TRUE(gt.masks[1][0].empty());  // no bear in view 2
  // Object 5 is the cup (pixels 0, 1), object 9 the bear (2, 3), in both views.
  const auto masks_of = [](size_t) {
    return ObjectMasks{{5, pixels_on(4, 1, {0, 1})}, {9, pixels_on(4, 1, {2, 3})}};
  };
  const OvsScore s = score_ovs_oracle(gt, masks_of);
  EXPECT_EQ(s.objects, (std::vector<int32_t>{9, 5}));
  // View 0: both exact. View 2: bear absent but predicted on {2, 3} -> IoU 0;
  // cup {0} against predicted {0, 1} -> 0.5.
  EXPECT_DOUBLE_EQ(s.miou, (1.0 + 1.0 + 0.0 + 0.5) / 4);
  EXPECT_DOUBLE_EQ(s.views[0].accuracy, 1.0);
  EXPECT_DOUBLE_EQ(s.views[1].accuracy, 1.0 / 4);  // only pixel 0 matches its one-hot row
}

TEST(Ovs, LerfMaskScoringOnOvsMasksSkipsAbsentClassesAndCanDownsample) {
  testing_util::TempDir dir;
  for (const char* v : {"a.png", "b.png"}) testing_util::write_file(dir / "images" / v, "x");
  testing_util::write_file(dir / "segmentations/classes.txt", "cup\nbear\n");
  Mask cup(8, 2), empty(8, 2);
  for (int x = 0; x < 4; ++x) cup.on[x] = cup.on[8 + x] = 1;  // left half
  splat::write_mask_png(dir / "segmentations/01/cup.png", 8, 2, cup.on);
  splat::write_mask_png(dir / "segmentations/01/bear.png", 8, 2, empty.on);
  const LerfMaskGroundTruth gt = lerf_mask_from_ovs(read_ovs_ground_truth(dir.path()));
  EXPECT_EQ(gt.test_views, (std::vector<std::string>{"b.png"}));
  EXPECT_EQ(gt.masks[0].size(), 1u);  // the absent bear is not scored
  // A 4x1 prediction of the left half, scored at ground-truth width 4.
  const auto masks_of = [](size_t) { return ObjectMasks{{3, pixels_on(4, 1, {0, 1})}}; };
  const SceneScore s = score_oracle(gt, masks_of, 4);
  ASSERT_EQ(s.queries.size(), 1u);
  EXPECT_EQ(s.queries[0].object, 3);
  EXPECT_DOUBLE_EQ(s.miou, 1.0);
}

TEST(Ovs, ReadsTheSyntheticLayoutAndOnly255IsForeground) {
  testing_util::TempDir dir;
  testing_util::generate_small_scene_in_both_layouts(dir.path());
  const OvsGroundTruth gt = read_ovs_ground_truth(dir / "ovs");
  EXPECT_TRUE(std::is_sorted(gt.classes.begin(), gt.classes.end()));
  EXPECT_EQ(gt.images.size(), 6u);
  EXPECT_EQ(gt.views.size(), 2u);
  size_t present = 0;
  for (const auto& f : gt.masks[0]) present += !f.empty();
  EXPECT_GT(present, 3u);
  // 254 is not foreground; resizing keeps the rule.
  splat::IdMap grey(2, 1);
  grey.ids = {255, 254};
  splat::write_id_map(dir / "m.png", grey, 8);
  EXPECT_EQ(read_ovs_mask(dir / "m.png", 4, 2).on, (std::vector<uint8_t>{1, 1, 0, 0, 1, 1, 0, 0}));
  EXPECT_THROW(read_ovs_ground_truth(dir / "lerf"), splat::InputError);
}

}  // namespace
}  // namespace eval
