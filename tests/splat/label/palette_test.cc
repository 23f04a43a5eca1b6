#include "splat/label/palette.h"

#include <gtest/gtest.h>

#include <set>

#include "splat/id_maps.h"
#include "tests/test_util.h"

namespace splat {
namespace {

TEST(Palette, BackgroundIsBlackAndLabelsGetDistinctStableColours) {
  EXPECT_EQ(label_color(0), (std::array<float, 3>{0.f, 0.f, 0.f}));
  EXPECT_EQ(label_color(-3), label_color(0));
  std::set<std::array<int, 3>> seen;
  for (int32_t label = 1; label <= 200; ++label) {
    const std::array<float, 3> c = label_color(label);
    EXPECT_EQ(c, label_color(label));
    for (float v : c) {
      EXPECT_GE(v, 0.f);
      EXPECT_LE(v, 1.f);
    }
    EXPECT_GT(c[0] + c[1] + c[2], 0.2f) << "label " << label << " looks like background";
    seen.insert({int(c[0] * 255 + 0.5f), int(c[1] * 255 + 0.5f), int(c[2] * 255 + 0.5f)});
  }
  EXPECT_EQ(seen.size(), 200u);  // DEVA's short IDs, each its own 8-bit colour
}

TEST(Palette, ColorizesEveryPixelByItsLabel) {
  const std::vector<int32_t> labels = {0, 1, 2, 1, 0, 7};
  const ImageRGB image = colorize_labels(labels, 3, 2);
  ASSERT_EQ(image.width, 3);
  ASSERT_EQ(image.height, 2);
  for (int i = 0; i < 6; ++i) {
    const float* p = image.pixel(i % 3, i / 3);
    const std::array<float, 3> c = label_color(labels[size_t(i)]);
    EXPECT_EQ((std::array<float, 3>{p[0], p[1], p[2]}), c) << "pixel " << i;
  }
}

TEST(Palette, WritesExactIdsAndAColourImage) {
  const testing_util::TempDir tmp;
  const std::vector<int32_t> labels = {0, 3, 300, 3, 65535, 0};  // beyond 8 bits
  write_label_map(tmp / "labels", "view_01", labels, 3, 2);
  const IdMap ids = read_id_map(tmp / "labels" / "view_01.png");
  ASSERT_EQ(ids.width, 3);
  ASSERT_EQ(ids.height, 2);
  for (size_t i = 0; i < labels.size(); ++i) EXPECT_EQ(ids.ids[i], labels[i]) << i;
  EXPECT_TRUE(std::filesystem::exists(tmp / "labels_color" / "view_01.png"));
}

}  // namespace
}  // namespace splat
