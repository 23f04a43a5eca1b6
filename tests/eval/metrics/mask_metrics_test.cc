// The LERF-Mask protocol's mask metrics on hand-computed cases.

#include "eval/metrics/mask_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/image_codec.h"
#include "tests/test_util.h"

namespace eval {
namespace {

Mask rect(int w, int h, int x0, int y0, int x1, int y1) {
  Mask m(w, h);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) m.on[size_t(y) * w + x] = 1;
  return m;
}

TEST(MaskMetrics, IouAndEmptyUnion) {
  const Mask a = rect(10, 10, 0, 0, 4, 4);  // 16 pixels
  const Mask b = rect(10, 10, 2, 0, 6, 4);  // 16, overlap 8
  EXPECT_DOUBLE_EQ(mask_iou(a, b), 8.0 / 24.0);
  EXPECT_DOUBLE_EQ(mask_iou(a, a), 1.0);
  EXPECT_TRUE(std::isnan(mask_iou(Mask(10, 10), Mask(10, 10))));
}

TEST(MaskMetrics, BoundaryWidthRoundsHalfToEven) {
  EXPECT_EQ(boundary_width(75, 100), 2);   // 0.02 * 125 = 2.5 -> 2
  EXPECT_EQ(boundary_width(105, 140), 4);  // 0.02 * 175 = 3.5 -> 4
  EXPECT_EQ(boundary_width(10, 10), 1);    // 0.28 -> 0 -> at least 1
  EXPECT_EQ(boundary_width(1440, 1080), 36);
}

TEST(MaskMetrics, BoundaryErodesWithZerosOutsideTheImage) {
  const Mask full = rect(10, 10, 0, 0, 10, 10);
  const Mask b1 = mask_boundary(full, 1);
  EXPECT_EQ(b1.count(), 100u - 64u);  // the outer ring
  const Mask b2 = mask_boundary(full, 2);
  EXPECT_EQ(b2.count(), 100u - 36u);
  // A 3x3 square in the middle eroded by 1 keeps its centre only.
  const Mask small = rect(10, 10, 4, 4, 7, 7);
  EXPECT_EQ(mask_boundary(small, 1).count(), 8u);
  EXPECT_FALSE(mask_boundary(small, 1).on[5 * 10 + 5]);
}

TEST(MaskMetrics, BoundaryIouOfShiftedSquares) {
  const Mask a = rect(50, 50, 10, 10, 30, 30);
  EXPECT_DOUBLE_EQ(boundary_iou(a, a), 1.0);
  const Mask b = rect(50, 50, 11, 10, 31, 30);
  const double biou = boundary_iou(a, b);
  EXPECT_GT(biou, 0.0);
  EXPECT_LT(biou, mask_iou(a, b));  // boundaries punish the shift harder
}

TEST(MaskMetrics, ReadsMasksAsPillowsGreyscaleAboveHalf) {
  testing_util::TempDir dir;
  // RGB: Pillow's luma of (129,129,129) is 129 (on), of (128,...) 128 (off),
  // of pure red 76 (off), of pure green 150 (on).
  const uint8_t rgb[4][3] = {{129, 129, 129}, {128, 128, 128}, {255, 0, 0}, {0, 255, 0}};
  const std::string file = (dir / "m.png").string();
  splat::write_image_file(file, {4, 1, 3}, splat::SampleType::uint8, rgb);
  EXPECT_EQ(read_mask(file).on, (std::vector<uint8_t>{1, 0, 0, 1}));
  // RGBA: Pillow's greyscale leaves the alpha out, so a white pixel that is
  // nearly transparent is still on, and a black opaque one off.
  const uint8_t rgba[2][4] = {{255, 255, 255, 10}, {0, 0, 0, 255}};
  splat::write_image_file(dir / "a.png", {2, 1, 4}, splat::SampleType::uint8, rgba);
  EXPECT_EQ(read_mask(dir / "a.png").on, (std::vector<uint8_t>{1, 0}));
  // Grey 8-bit masks of 0 and 255.
  splat::IdMap grey(3, 1);
  grey.ids = {0, 255, 129};
  splat::write_id_map(dir / "g.png", grey, 8);
  EXPECT_EQ(read_mask(dir / "g.png").on, (std::vector<uint8_t>{0, 1, 1}));
}

TEST(MaskMetrics, NearestResizeOfPredictions) {
  const Mask m = rect(4, 4, 0, 0, 2, 4);  // left half
  const Mask r = resize_mask_nearest(m, 8, 8);
  EXPECT_EQ(r.count(), 32u);
  EXPECT_TRUE(r.on[3]);
  EXPECT_FALSE(r.on[4]);
}

}  // namespace
}  // namespace eval
