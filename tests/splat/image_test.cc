#include "splat/image.h"

#include <gtest/gtest.h>
#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#endif

#include <cmath>
#include <stdexcept>

#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/image_codec.h"
#include "tests/test_util.h"

namespace splat {
namespace {

using testing_util::TempDir;
using testing_util::write_file;

// Writes raw pixels straight through the codec, bypassing our RGB and ID
// map writers.
template <typename T>
void write_raw(const std::filesystem::path& file, int w, int h, int channels,
               const std::vector<T>& px, SampleType type) {
  write_image_file(file, {w, h, channels, type}, type, px.data());
}

ImageRGB gradient(int w, int h) {
  ImageRGB im(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* p = im.pixel(x, y);
      p[0] = float(x) / (w - 1);
      p[1] = float(y) / (h - 1);
      p[2] = 0.25f;
    }
  return im;
}

TEST(Image, Reads8And16BitPngToUnitRange) {
  TempDir dir;
  write_raw<uint8_t>(dir / "a8.png", 2, 1, 3, {0, 128, 255, 255, 0, 51}, SampleType::uint8);
  write_raw<uint16_t>(dir / "a16.png", 2, 1, 3, {0, 32768, 65535, 65535, 0, 13107},
                      SampleType::uint16);
  for (const char* f : {"a8.png", "a16.png"}) {
    const ImageRGB im = read_image_rgb(dir / f);
    ASSERT_EQ(im.width, 2);
    EXPECT_FLOAT_EQ(im.data[0], 0.f);
    EXPECT_NEAR(im.data[1], 0.5f, 0.002f);
    EXPECT_FLOAT_EQ(im.data[2], 1.f);
    EXPECT_NEAR(im.data[5], 0.2f, 1e-6f);
  }
}

TEST(Image, GreyIsReplicatedAndAlphaDropped) {
  TempDir dir;
  write_raw<uint8_t>(dir / "g.png", 1, 1, 1, {255}, SampleType::uint8);
  write_raw<uint8_t>(dir / "rgba.png", 1, 1, 4, {0, 255, 0, 10}, SampleType::uint8);
  EXPECT_EQ(read_image_rgb(dir / "g.png").data, (std::vector<float>{1, 1, 1}));
  EXPECT_EQ(read_image_rgb(dir / "rgba.png").data, (std::vector<float>{0, 1, 0}));
}

TEST(Image, DownscaledSizesAreRoundedAndNeverEmpty) {
  EXPECT_EQ(downscaled_size(986, 728, 1.0), std::make_pair(986, 728));
  EXPECT_EQ(downscaled_size(986, 728, 4.0), std::make_pair(247, 182));  // 246.5 rounds up
  EXPECT_EQ(downscaled_size(640, 360, 2.0), std::make_pair(320, 180));
  EXPECT_EQ(downscaled_size(3, 2, 8.0), std::make_pair(1, 1));
}

TEST(Image, PngJpegExrWriteAndReadBack) {
  TempDir dir;
  const ImageRGB im = gradient(32, 24);
  for (const auto& [name, tol] : std::vector<std::pair<std::string, float>>{
           {"a.png", 0.5f / 255}, {"a.jpg", 0.05f}, {"a.exr", 1e-3f}, {"a.tif", 1e-4f}}) {
    write_image_rgb(dir / name, im);
    const ImageRGB back = read_image_rgb(dir / name);
    ASSERT_EQ(back.width, 32) << name;
    ASSERT_EQ(back.height, 24) << name;
    double max_err = 0;
    for (size_t i = 0; i < im.data.size(); ++i)
      max_err = std::max(max_err, double(std::abs(back.data[i] - im.data[i])));
    EXPECT_LE(max_err, tol) << name;
  }
}

TEST(Image, ExrValuesAreClampedToUnitRange) {
  TempDir dir;
  write_raw<float>(dir / "hdr.exr", 1, 1, 3, {2.5f, -1.f, 0.5f}, SampleType::float32);
  EXPECT_EQ(read_image_rgb(dir / "hdr.exr").data, (std::vector<float>{1, 0, 0.5f}));
}

TEST(Image, DownscaleAreaAveragesBlocks) {
  ImageRGB im(4, 2);
  for (int x = 0; x < 4; ++x) im.pixel(x, 0)[0] = float(x), im.pixel(x, 1)[0] = float(x + 4);
  const ImageRGB half = downscale_area(im, 2);
  ASSERT_EQ(half.width, 2);
  ASSERT_EQ(half.height, 1);
  EXPECT_FLOAT_EQ(half.pixel(0, 0)[0], (0 + 1 + 4 + 5) / 4.f);
  EXPECT_FLOAT_EQ(half.pixel(1, 0)[0], (2 + 3 + 6 + 7) / 4.f);
}

TEST(Image, CropCopiesTheRectangleAndRejectsOneOutside) {
  const ImageRGB im = gradient(7, 5);
  const ImageRGB c = crop(im, {3, 1, 4, 3});
  ASSERT_EQ(c.width, 4);
  ASSERT_EQ(c.height, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x)
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(c.pixel(x, y)[k], im.pixel(x + 3, y + 1)[k]) << x << "," << y;
  IdMap ids(7, 5);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) ids.at(x, y) = uint16_t(10 * y + x);
  const IdMap ci = crop(ids, {0, 2, 7, 3});
  ASSERT_EQ(ci.width, 7);
  ASSERT_EQ(ci.height, 3);
  EXPECT_EQ(ci.at(0, 0), 20);
  EXPECT_EQ(ci.at(6, 2), 46);
  EXPECT_THROW(crop(im, {4, 0, 4, 5}), std::invalid_argument);
  EXPECT_THROW(crop(im, {-1, 0, 2, 2}), std::invalid_argument);
  EXPECT_THROW(crop(ids, {0, 0, 0, 5}), std::invalid_argument);
}

TEST(Image, DownscaleRoundsOddSizes) {
  const ImageRGB im = gradient(101, 75);
  const ImageRGB q = downscale_area(im, 4);
  EXPECT_EQ(q.width, 25);
  EXPECT_EQ(q.height, 19);
  const ImageRGB e = downscale_area(im, 8);
  EXPECT_EQ(e.width, 13);
  EXPECT_EQ(e.height, 9);
}

TEST(IdMap, RoundTrip8And16Bit) {
  TempDir dir;
  IdMap m(5, 3);
  for (size_t i = 0; i < m.ids.size(); ++i) m.ids[i] = uint16_t(i * 17 % 256);
  write_id_map(dir / "m8.png", m, 8);
  EXPECT_EQ(read_id_map(dir / "m8.png").ids, m.ids);
  m.ids[4] = 60000;
  write_id_map(dir / "m16.png", m, 16);
  const IdMap back = read_id_map(dir / "m16.png");
  EXPECT_EQ(back.ids, m.ids);
  EXPECT_EQ(back.width, 5);
  EXPECT_EQ(back.height, 3);
}

TEST(IdMap, EightBitIdsAreNotRescaled) {
  // 255 in an 8-bit map is ID 255, not 65535.
  TempDir dir;
  write_raw<uint8_t>(dir / "m.png", 2, 1, 1, {255, 7}, SampleType::uint8);
  EXPECT_EQ(read_id_map(dir / "m.png").ids, (std::vector<uint16_t>{255, 7}));
}

TEST(IdMap, Rejects8BitOverflowOnWrite) {
  TempDir dir;
  IdMap m(1, 1);
  m.ids[0] = 300;
  EXPECT_THROW(write_id_map(dir / "m.png", m, 8), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "m.png"));
}

TEST(IdMap, RejectsMultiChannelAndBadFilesNamingThem) {
  TempDir dir;
  write_raw<uint8_t>(dir / "rgb.png", 1, 1, 3, {1, 2, 3}, SampleType::uint8);
  write_file(dir / "junk.png", "this is not a png");
  write_raw<float>(dir / "float.exr", 1, 1, 1, {1.f}, SampleType::float32);
  for (const char* f : {"rgb.png", "junk.png", "float.exr", "missing.png"}) {
    try {
      read_id_map(dir / f);
      FAIL() << f;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
    }
  }
}

TEST(Image, TruncatedPngIsRejected) {
  TempDir dir;
  write_image_rgb(dir / "a.png", gradient(64, 64));
  const std::string bytes = testing_util::read_file(dir / "a.png");
  write_file(dir / "cut.png", bytes.substr(0, bytes.size() / 2));
#if defined(__SANITIZE_ADDRESS__)
  // OpenImageIO 2.4's PNG reader leaks its error string when libpng longjmps
  // out of the cut file (tests/fuzz/lsan.supp). The suppression there needs
  // OpenImageIO's frame in the leak's stack, which the fast unwinder loses
  // inside libstdc++; so the leak checker skips this one read instead.
  __lsan::ScopedDisabler third_party_leak;
#endif
  EXPECT_THROW(read_image_rgb(dir / "cut.png"), InputError);
}

TEST(Image, MaskPngIs0And255) {
  TempDir dir;
  write_mask_png(dir / "m.png", 3, 1, {0, 1, 1});
  EXPECT_EQ(read_id_map(dir / "m.png").ids, (std::vector<uint16_t>{0, 255, 255}));
}

}  // namespace
}  // namespace splat
