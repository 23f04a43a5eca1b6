#include "splat/packed_image.h"

#include <gtest/gtest.h>

#include <cstring>

#include "splat/image_codec.h"
#include "tests/test_util.h"

namespace splat {
namespace {

using testing_util::TempDir;

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

template <typename T>
void write_png(const std::filesystem::path& file, int w, int h, const std::vector<T>& px,
               SampleType type) {
  write_image_file(file, {w, h, 3, type}, type, px.data());
}

TEST(PackedImage, EveryCodeValueRoundTripsAsACode) {
  ImageRGB im(256, 1);
  for (int k = 0; k < 256; ++k)
    im.data[3 * k] = im.data[3 * k + 1] = im.data[3 * k + 2] = code_value(uint8_t(k));
  const PackedImageRGB p = PackedImageRGB::pack(im);
  EXPECT_TRUE(p.holds_codes());
  EXPECT_EQ(p.floats(), nullptr);  // nothing to read in place: unpack it
  EXPECT_EQ(p.bytes(), im.data.size());
  EXPECT_TRUE(same_bits(p.unpack().data, im.data));
}

TEST(PackedImage, OtherValuesAreKeptAsFloats) {
  ImageRGB im(4, 3);
  for (size_t i = 0; i < im.data.size(); ++i) im.data[i] = code_value(uint8_t(i));
  im.data[7] = std::nextafter(im.data[7], 1.f);  // one value off by an ulp
  const PackedImageRGB p = PackedImageRGB::pack(im);
  EXPECT_FALSE(p.holds_codes());
  EXPECT_EQ(p.bytes(), im.data.size() * sizeof(float));
  EXPECT_TRUE(same_bits(p.unpack().data, im.data));
  // Read in place, the same image.
  ASSERT_NE(p.floats(), nullptr);
  EXPECT_EQ(p.floats()->width, 4);
  EXPECT_EQ(p.floats()->height, 3);
  EXPECT_TRUE(same_bits(p.floats()->data, im.data));
}

TEST(PackedImage, UnpackReusesTheBuffer) {
  ImageRGB im(8, 8);
  const PackedImageRGB p = PackedImageRGB::pack(im);
  ImageRGB out(8, 8);
  const float* before = out.data.data();
  p.unpack_into(out);
  EXPECT_EQ(out.data.data(), before);
  EXPECT_EQ(out.width, 8);
  EXPECT_EQ(out.height, 8);
}

// The decoder's floats for an 8-bit photo are exactly the code values, so the
// cache keeps such views as codes; a 16-bit photo's are not.
TEST(PackedImage, EightBitPhotosPackAsCodesSixteenBitAsFloats) {
  TempDir dir;
  std::vector<uint8_t> px8(3 * 256);
  for (size_t i = 0; i < px8.size(); ++i) px8[i] = uint8_t(i * 7);
  write_png<uint8_t>(dir / "a8.png", 256, 1, px8, SampleType::uint8);
  const ImageRGB im8 = read_image_rgb(dir / "a8.png");
  const PackedImageRGB p8 = PackedImageRGB::pack(im8);
  EXPECT_TRUE(p8.holds_codes());
  EXPECT_TRUE(same_bits(p8.unpack().data, im8.data));
  const PackedImageRGB read8 = read_packed_image_rgb(dir / "a8.png");
  EXPECT_TRUE(read8.holds_codes());
  EXPECT_TRUE(same_bits(read8.unpack().data, im8.data));

  std::vector<uint16_t> px16(3 * 256);
  for (size_t i = 0; i < px16.size(); ++i) px16[i] = uint16_t(i * 97 + 1);
  write_png<uint16_t>(dir / "a16.png", 256, 1, px16, SampleType::uint16);
  const ImageRGB im16 = read_image_rgb(dir / "a16.png");
  const PackedImageRGB p16 = PackedImageRGB::pack(im16);
  EXPECT_FALSE(p16.holds_codes());
  EXPECT_TRUE(same_bits(p16.unpack().data, im16.data));
  EXPECT_TRUE(same_bits(read_packed_image_rgb(dir / "a16.png").unpack().data, im16.data));
}

// RGBA photos and JPEGs: the alpha channel left out, the same floats.
TEST(PackedImage, ReadsAsReadImageRgbDoes) {
  TempDir dir;
  std::vector<uint8_t> rgba(4 * 64 * 8);
  for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = uint8_t(i * 13 + 5);
  write_image_file(dir / "a.png", {64, 8, 4}, SampleType::uint8, rgba.data());
  ImageRGB im(64, 8);
  for (size_t i = 0; i < im.data.size(); ++i) im.data[i] = float(i % 97) / 96.f;
  write_image_rgb(dir / "b.jpg", im);
  for (const char* f : {"a.png", "b.jpg"}) {
    const PackedImageRGB p = read_packed_image_rgb(dir / f);
    EXPECT_TRUE(p.holds_codes()) << f;
    EXPECT_TRUE(same_bits(p.unpack().data, read_image_rgb(dir / f).data)) << f;
  }
}

}  // namespace
}  // namespace splat
