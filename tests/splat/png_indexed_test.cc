#include "splat/png_indexed.h"

#include <gtest/gtest.h>
#include <png.h>

#include <string>
#include <vector>

#include "splat/error.h"
#include "splat/id_maps.h"
#include "tests/test_util.h"

namespace splat {
namespace {

using testing_util::TempDir;

// Writes a palette PNG as SAM2's tools do (PIL, mode "P"), with libpng's own
// writer. The palette has `entries` RGB colours; every index is < entries.
void write_palette_png(const std::filesystem::path& file, int width, int height,
                       const std::vector<uint8_t>& indices, int entries,
                       const std::vector<uint8_t>& palette_rgb) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = width;
  image.height = height;
  image.format = PNG_FORMAT_RGB_COLORMAP;
  image.colormap_entries = entries;
  ASSERT_TRUE(
      png_image_write_to_file(&image, file.c_str(), 0, indices.data(), width, palette_rgb.data()))
      << image.message;
}

// The bit depth stored in a PNG's header.
int png_bit_depth(const std::filesystem::path& file) {
  return uint8_t(testing_util::read_file(file).at(24));
}

// A palette like DAVIS's: distinct colours for the first IDs, then unused
// black entries, so colour alone cannot tell IDs 0 and 200 apart.
std::vector<uint8_t> davis_like_palette() {
  std::vector<uint8_t> rgb(3 * 256, 0);
  for (int i = 1; i < 8; ++i) rgb[3 * i] = uint8_t(32 * i);
  return rgb;
}

TEST(PngIndexed, ReadsTheIndicesNotTheColours) {
  TempDir dir;
  const std::vector<uint8_t> ids = {0, 1, 2, 7, 200, 255, 3, 0};
  write_palette_png(dir / "f.png", 4, 2, ids, 256, davis_like_palette());
  ASSERT_EQ(png_bit_depth(dir / "f.png"), 8);
  const IdMap map = read_id_map(dir / "f.png");
  EXPECT_EQ(map.width, 4);
  EXPECT_EQ(map.height, 2);
  EXPECT_EQ(map.ids, (std::vector<uint16_t>{0, 1, 2, 7, 200, 255, 3, 0}));
}

TEST(PngIndexed, UnpacksLowBitDepths) {
  TempDir dir;
  std::vector<uint8_t> ids(13 * 3);
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = uint8_t(i % 5);
  const std::vector<uint8_t> palette(3 * 5, 9);  // five entries, all one colour
  write_palette_png(dir / "f.png", 13, 3, ids, 5, palette);
  ASSERT_LT(png_bit_depth(dir / "f.png"), 8);  // packed: several pixels per byte
  const IdMap map = read_id_map(dir / "f.png");
  EXPECT_EQ(map.ids, std::vector<uint16_t>(ids.begin(), ids.end()));
}

TEST(PngIndexed, OtherFilesAreLeftToTheGeneralReader) {
  TempDir dir;
  IdMap grey(2, 1);
  grey.ids = {4, 9};
  write_id_map(dir / "grey.png", grey, 8);
  testing_util::write_file(dir / "text.png", "not an image");
  EXPECT_FALSE(read_png_palette_indices(dir / "grey.png"));
  EXPECT_FALSE(read_png_palette_indices(dir / "text.png"));
  EXPECT_FALSE(read_png_palette_indices(dir / "missing.png"));
}

TEST(PngIndexed, TruncatedFileIsAnErrorNamingIt) {
  TempDir dir;
  std::vector<uint8_t> ids(64 * 64);
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = uint8_t(i * 7919 % 251);
  write_palette_png(dir / "f.png", 64, 64, ids, 256, davis_like_palette());
  const std::string bytes = testing_util::read_file(dir / "f.png");
  testing_util::write_file(dir / "cut.png", bytes.substr(0, bytes.size() / 2));
  try {
    read_id_map(dir / "cut.png");
    FAIL() << "a truncated PNG was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.png"), std::string::npos) << e.what();
  }
}

// Found by fuzzing: a few hundred bytes whose text chunk claims 1.9 GB made
// libpng allocate it before finding the file too short.
TEST(PngIndexed, AChunkLongerThanTheFileIsRefusedBeforeAnyAllocation) {
  TempDir dir;
  write_palette_png(dir / "f.png", 8, 8, std::vector<uint8_t>(64, 1), 2, davis_like_palette());
  std::string bytes = testing_util::read_file(dir / "f.png");
  // After the signature and IHDR (8 + 25 bytes): a tEXt chunk claiming 2^30 bytes.
  bytes.insert(33, std::string("\x40\x00\x00\x00tEXtComment\0x", 17));
  testing_util::write_file(dir / "lying.png", bytes);
  try {
    read_id_map(dir / "lying.png");
    FAIL() << "a PNG with a chunk longer than the file was read";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("lying.png"), std::string::npos) << what;
    EXPECT_NE(what.find("'tEXt' claims 1073741824 bytes"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace splat
