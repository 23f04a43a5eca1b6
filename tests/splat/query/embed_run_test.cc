// The crop CLIP sees of an object (paper: C(M ⊗ I)).

#include "splat/query/embed_run.h"

#include <gtest/gtest.h>

namespace splat {
namespace {

TEST(MaskedSquareCrop, SquareAroundTheMaskWithMarginAndBackgroundOutside) {
  ImageRGB image(20, 10);
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = 0.5f;
  std::vector<uint8_t> mask(200, 0);
  // A 4 x 2 box at x 8..11, y 4..5; pixel (9, 5) is outside the mask.
  for (int y = 4; y <= 5; ++y)
    for (int x = 8; x <= 11; ++x) mask[y * 20 + x] = !(x == 9 && y == 5);
  const ImageRGB crop = masked_square_crop(image, mask, 0.25f, {1, 0, 0});
  // side = 4 * (1 + 2 * 0.25) = 6, centred on the box's centre (10, 5).
  ASSERT_EQ(crop.width, 6);
  ASSERT_EQ(crop.height, 6);
  const auto at = [&](int x, int y, int c) { return crop.data[3 * (y * 6 + x) + c]; };
  // The crop starts at (7, 2): mask pixel (8, 4) is at (1, 2).
  EXPECT_FLOAT_EQ(at(1, 2, 0), 0.5f);
  EXPECT_FLOAT_EQ(at(2, 3, 0), 1.0f);  // (9, 5): not in the mask, background red
  EXPECT_FLOAT_EQ(at(2, 3, 1), 0.0f);
  EXPECT_FLOAT_EQ(at(0, 0, 0), 1.0f);  // outside the mask
  int inside = 0;
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 6; ++x) inside += at(x, y, 1) == 0.5f;
  EXPECT_EQ(inside, 7);
}

TEST(MaskedSquareCrop, PartsOutsideTheImageAreBackground) {
  ImageRGB image(8, 8);
  std::fill(image.data.begin(), image.data.end(), 1.0f);
  std::vector<uint8_t> mask(64, 0);
  mask[0] = mask[1] = 1;  // the top-left corner, 2 x 1
  const ImageRGB crop = masked_square_crop(image, mask, 0.5f, {0, 0, 0});
  ASSERT_EQ(crop.width, 4);  // 2 * (1 + 1)
  double sum = 0;
  for (float v : crop.data) sum += v;
  EXPECT_DOUBLE_EQ(sum, 2 * 3);  // only the two mask pixels are image
  EXPECT_THROW(masked_square_crop(image, std::vector<uint8_t>(64, 0), 0.1f, {0, 0, 0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace splat
