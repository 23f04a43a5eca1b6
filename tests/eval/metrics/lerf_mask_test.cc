// The LERF-Mask layout and oracle scoring on a hand-built scene folder.

#include "eval/metrics/lerf_mask.h"

#include <gtest/gtest.h>

#include <cmath>

#include "splat/error.h"
#include "splat/image.h"
#include "tests/test_util.h"

namespace eval {
namespace {

namespace fs = std::filesystem;

void write_mask(const fs::path& file, const Mask& m) {
  splat::write_mask_png(file, m.width, m.height, m.on);
}

Mask columns(int x0, int x1) {
  Mask m(8, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = x0; x < x1; ++x) m.on[size_t(y) * 8 + x] = 1;
  return m;
}

// Views a, b (train), c, d, e; test views c, d, e get k = 0, 1, 2.
fs::path make_scene(const testing_util::TempDir& dir) {
  const fs::path s = dir.path() / "scene";
  for (const char* v : {"a.png", "b.png", "c.png", "d.png", "e.png"})
    testing_util::write_file(s / "images" / v, "x");
  for (const char* v : {"a.png", "b.png"}) testing_util::write_file(s / "images_train" / v, "x");
  fs::create_directories(s / "test_mask/0");
  fs::create_directories(s / "test_mask/2");
  write_mask(s / "test_mask/0/cup.png", columns(0, 4));
  write_mask(s / "test_mask/2/cup.png", columns(0, 2));
  write_mask(s / "test_mask/2/bear.png", columns(4, 8));
  return s;
}

TEST(LerfMask, ReadsTestViewsAndMasks) {
  testing_util::TempDir dir;
  const auto gt = read_lerf_mask_ground_truth(make_scene(dir));
  EXPECT_EQ(gt.test_views, (std::vector<std::string>{"c.png", "d.png", "e.png"}));
  EXPECT_EQ(gt.queries, (std::vector<std::string>{"bear", "cup"}));
  EXPECT_EQ(gt.masks[0].size(), 1u);
  EXPECT_TRUE(gt.masks[1].empty());  // a gap, as teatime's view 1 in the download
  EXPECT_EQ(gt.masks[2].size(), 2u);
  EXPECT_EQ(gt.without_truth, std::vector<std::string>{"d.png"});
}

TEST(LerfMask, OraclePicksTheBestIdOnTheFirstViewAndScoresItEverywhere) {
  testing_util::TempDir dir;
  const auto gt = read_lerf_mask_ground_truth(make_scene(dir));
  // Predictions at half resolution (4x2), as label maps: view 0 has label 7
  // on columns 0-3 (exact cup) and 3 on the rest; view 2 has label 7 on
  // columns 0-3 again (cup is only 0-1 there) and 3 on 4-7 (exact bear).
  auto masks_of = [](size_t k) {
    std::vector<int32_t> labels(8);
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 4; ++x) labels[y * 4 + x] = x < 2 ? 7 : 3;
    return masks_from_label_map(labels, 4, 2);
  };
  const SceneScore s = score_oracle(gt, masks_of);
  ASSERT_EQ(s.queries.size(), 2u);
  const QueryScore& bear = s.queries[0];
  const QueryScore& cup = s.queries[1];
  EXPECT_EQ(cup.object, 7);
  EXPECT_EQ(cup.views, (std::vector<size_t>{0, 2}));
  EXPECT_DOUBLE_EQ(cup.iou[0], 1.0);
  EXPECT_DOUBLE_EQ(cup.iou[1], 0.5);
  EXPECT_DOUBLE_EQ(cup.mean_iou, 0.75);
  EXPECT_EQ(bear.object, 3);
  EXPECT_DOUBLE_EQ(bear.mean_iou, 1.0);
  EXPECT_DOUBLE_EQ(s.miou, (0.75 + 1.0) / 2);
}

TEST(LerfMask, EmptyUnionPropagatesNan) {
  testing_util::TempDir dir;
  const fs::path s = make_scene(dir);
  write_mask(s / "test_mask/2/bear.png", Mask(8, 4));  // an empty ground truth
  const auto gt = read_lerf_mask_ground_truth(s);
  const SceneScore score = score_oracle(gt, [](size_t) { return ObjectMasks{{1, Mask(8, 4)}}; });
  EXPECT_TRUE(std::isnan(score.queries[0].mean_iou));
  EXPECT_TRUE(std::isnan(score.miou));
}

TEST(LerfMask, BadFolderNameIsAnError) {
  testing_util::TempDir dir;
  const fs::path s = make_scene(dir);
  fs::create_directories(s / "test_mask/x1");
  EXPECT_THROW(read_lerf_mask_ground_truth(s), splat::InputError);
}

}  // namespace
}  // namespace eval
