#include "splat/masks/mask_import.h"

#include <gtest/gtest.h>
#include <png.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/masks/mask_files.h"
#include "tests/test_util.h"

namespace splat {
namespace {

namespace fs = std::filesystem;
using testing_util::TempDir;

constexpr int kW = 6, kH = 4;

// images/ with one 6x4 photo per stem.
fs::path make_images(const TempDir& dir, const std::vector<std::string>& stems) {
  const fs::path images = dir / "images";
  fs::create_directories(images);
  for (const auto& stem : stems) write_image_rgb(images / (stem + ".jpg"), ImageRGB(kW, kH));
  return images;
}

// A binary mask, 0/`on`, inside on the columns [x0, x1).
void write_mask(const fs::path& file, int x0, int x1, uint16_t on = 255) {
  fs::create_directories(file.parent_path());
  IdMap m(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = x0; x < x1; ++x) m.at(x, y) = on;
  write_id_map(file, m, on > 255 ? 16 : 8);
}

std::vector<uint16_t> row(const IdMap& m, int y) {
  return {m.ids.begin() + y * m.width, m.ids.begin() + (y + 1) * m.width};
}

nlohmann::json names(const fs::path& out) {
  return nlohmann::json::parse(testing_util::read_file(out / "objects.json"));
}

MaskImportResult run(const fs::path& masks, const fs::path& images, const fs::path& out,
                     const std::string& pattern = "") {
  fs::create_directories(out);
  MaskImportOptions o;
  o.masks = masks;
  o.images = images;
  o.pattern = pattern;
  return import_masks(o, out);
}

TEST(MaskFiles, FramesMatchByNameOrNumber) {
  const std::vector<std::string> stems = {"000001", "000002", "frame_00003"};
  EXPECT_EQ(match_frame("000002", stems), "000002");
  EXPECT_EQ(match_frame("2", stems), "000002");
  EXPECT_EQ(match_frame("00001", stems), "000001");
  EXPECT_FALSE(match_frame("3", stems));  // "frame_00003" is not a number
  EXPECT_FALSE(match_frame("7", stems));
  EXPECT_EQ(match_frame("7", {"07", "7"}), "7");  // the same string first
  EXPECT_FALSE(match_frame("007", {"07", "7"}));  // two numbers equal: ambiguous
}

TEST(MaskFiles, PatternsKeepObjectAndFrame) {
  const MaskPattern tracebot("{*}_{object}_{frame}.png");
  EXPECT_EQ(tracebot.match("003_container_001_000104.png"),
            std::make_pair(std::string("container_001"), std::string("000104")));
  const MaskPattern sam2("{object}/{frame}.png");
  EXPECT_EQ(sam2.match("red mug/00012.png"),
            std::make_pair(std::string("red mug"), std::string("00012")));
  EXPECT_FALSE(sam2.match("00012.png"));
  const MaskPattern bop("{frame}_{object}.png");
  EXPECT_EQ(bop.match("000001_000002.png"),
            std::make_pair(std::string("000002"), std::string("000001")));
  // Regex characters in the literal parts are literal.
  EXPECT_FALSE(MaskPattern("{object}.({frame}).png").match("a.x1).png"));
  EXPECT_TRUE(MaskPattern("{object}.({frame}).png").match("a.(1).png"));
  EXPECT_THROW(MaskPattern("{object}.png"), std::invalid_argument);
  EXPECT_THROW(MaskPattern("{frame}_{frame}_{object}.png"), std::invalid_argument);
}

TEST(MaskFiles, DetectsEachLayout) {
  TempDir dir;
  const std::vector<std::string> stems = {"000001", "000002"};
  write_mask(dir / "a" / "mug" / "1.png", 0, 2);
  write_mask(dir / "a" / "mug" / "2.png", 0, 2);
  EXPECT_EQ(detect_mask_layout(dir / "a", stems).pattern, "{object}/{frame}.png");
  write_mask(dir / "b" / "000001_000000.png", 0, 2);
  write_mask(dir / "b" / "000002_000000.png", 0, 2);
  EXPECT_EQ(detect_mask_layout(dir / "b", stems).pattern, "{frame}_{object}.png");
  write_mask(dir / "c" / "003_container_000_000001.png", 0, 2);
  write_mask(dir / "c" / "003_container_000_000002.png", 0, 2);
  EXPECT_EQ(detect_mask_layout(dir / "c", stems).pattern, "{*}_{object}_{frame}.png");
  write_mask(dir / "d" / "000001.png", 0, 2);
  EXPECT_EQ(detect_mask_layout(dir / "d", stems).layout, MaskLayout::kPerFrame);
  write_mask(dir / "e" / "holiday.png", 0, 2);
  EXPECT_THROW(detect_mask_layout(dir / "e", stems), InputError);
  fs::create_directories(dir / "f");
  EXPECT_THROW(detect_mask_layout(dir / "f", stems), InputError);
}

TEST(MaskImport, TracebotNamesBecomeOneIdPerObjectInstance) {
  TempDir dir;
  const fs::path images = make_images(dir, {"000001", "000002", "000003"});
  const fs::path masks = dir / "masks";
  write_mask(masks / "003_container_000_000001.png", 0, 2);
  write_mask(masks / "003_container_001_000001.png", 4, 6);
  write_mask(masks / "003_container_000_000002.png", 1, 3);
  write_mask(masks / "003_container_001_000002.png", 3, 4);
  // Frame 3 has no mask at all: an empty map of the photo's size.
  const MaskImportResult r = run(masks, images, dir / "out");
  EXPECT_EQ(r.layout, MaskLayout::kPerObject);
  EXPECT_EQ(r.names, (std::vector<std::string>{"container_000", "container_001"}));
  EXPECT_EQ(r.frames, 3u);
  EXPECT_EQ(r.frames_without_masks, 1u);
  EXPECT_EQ(r.overlap_pixels, 0u);
  EXPECT_EQ(row(read_id_map(dir / "out" / "000001.png"), 0),
            (std::vector<uint16_t>{1, 1, 0, 0, 2, 2}));
  EXPECT_EQ(row(read_id_map(dir / "out" / "000002.png"), 3),
            (std::vector<uint16_t>{0, 1, 1, 2, 0, 0}));
  const IdMap empty = read_id_map(dir / "out" / "000003.png");
  EXPECT_EQ(empty.width, kW);
  EXPECT_EQ(empty.ids, std::vector<uint16_t>(kW * kH, 0));
  EXPECT_EQ(names(dir / "out"),
            nlohmann::json::parse(
                R"([{"id":1,"name":"container_000"},{"id":2,"name":"container_001"}])"));
}

TEST(MaskImport, OverlapsGoToTheSmallerMaskThenTheLowerId) {
  TempDir dir;
  const fs::path images = make_images(dir, {"f1", "f2"});
  const fs::path masks = dir / "masks";
  write_mask(masks / "a_table" / "f1.png", 0, 6);  // the whole frame
  write_mask(masks / "b_cup" / "f1.png", 2, 4);    // on the table
  write_mask(masks / "a_table" / "f2.png", 0, 3);  // equal areas, overlapping on column 2
  write_mask(masks / "b_cup" / "f2.png", 2, 5);
  const MaskImportResult r = run(masks, images, dir / "out");
  EXPECT_EQ(row(read_id_map(dir / "out" / "f1.png"), 1), (std::vector<uint16_t>{1, 1, 2, 2, 1, 1}));
  EXPECT_EQ(row(read_id_map(dir / "out" / "f2.png"), 1), (std::vector<uint16_t>{1, 1, 1, 2, 2, 0}));
  EXPECT_EQ(r.overlap_pixels, size_t(2 * kH + kH));
}

TEST(MaskImport, BinaryMasksOfZeroAndOneOr16Bit) {
  TempDir dir;
  const fs::path images = make_images(dir, {"0"});
  write_mask(dir / "masks" / "x" / "0.png", 0, 1, 1);      // 0/1
  write_mask(dir / "masks" / "y" / "0.png", 5, 6, 65535);  // 16 bit
  run(dir / "masks", images, dir / "out");
  EXPECT_EQ(row(read_id_map(dir / "out" / "0.png"), 2), (std::vector<uint16_t>{1, 0, 0, 0, 0, 2}));
}

TEST(MaskImport, FilesOfFramesWithoutAnImageAreSkippedAndCounted) {
  TempDir dir;
  const fs::path images = make_images(dir, {"00010"});
  write_mask(dir / "masks" / "mug" / "10.png", 0, 1);
  write_mask(dir / "masks" / "mug" / "11.png", 0, 1);
  const MaskImportResult r = run(dir / "masks", images, dir / "out", "{object}/{frame}.png");
  EXPECT_EQ(r.skipped_files, std::vector<std::string>{"mug/11.png"});
  EXPECT_EQ(read_id_map(dir / "out" / "00010.png").at(0, 0), 1);
}

TEST(MaskImport, RefusesMasksOfOneFrameWithDifferentSizes) {
  TempDir dir;
  const fs::path images = make_images(dir, {"a"});
  write_mask(dir / "masks" / "x" / "a.png", 0, 1);
  IdMap big(12, 8);
  fs::create_directories(dir / "masks" / "y");
  write_id_map(dir / "masks" / "y" / "a.png", big, 8);
  try {
    run(dir / "masks", images, dir / "out");
    FAIL() << "accepted masks of two sizes";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("y/a.png: is 12x8"), std::string::npos) << e.what();
  }
}

TEST(MaskImport, RefusesTwoMasksOfOneObjectInOneFrame) {
  TempDir dir;
  const fs::path images = make_images(dir, {"7"});
  write_mask(dir / "masks" / "x" / "7.png", 0, 1);
  write_mask(dir / "masks" / "x" / "007.png", 0, 1);
  EXPECT_THROW(run(dir / "masks", images, dir / "out", "{object}/{frame}.png"), InputError);
}

TEST(MaskImport, GreyInstanceMapsKeepTheirIdsAndNames) {
  TempDir dir;
  const fs::path images = make_images(dir, {"a", "b"});
  IdMap m(kW, kH);
  m.at(0, 0) = 7;
  m.at(5, 3) = 300;
  write_id_map(dir / "deva" / "a.png", m, 16);
  testing_util::write_file(dir / "deva" / "objects.json", R"({"7": "mug"})");
  const MaskImportResult r = run(dir / "deva", images, dir / "out");
  EXPECT_EQ(r.layout, MaskLayout::kPerFrame);
  EXPECT_EQ(r.max_id, 300);
  EXPECT_EQ(r.frames_without_masks, 1u);
  const IdMap a = read_id_map(dir / "out" / "a.png");
  EXPECT_EQ(a.at(0, 0), 7);
  EXPECT_EQ(a.at(5, 3), 300);
  EXPECT_EQ(testing_util::read_file(dir / "out" / "objects.json"), R"({"7": "mug"})");
}

TEST(MaskImport, PaletteMapsKeepTheirIndices) {
  TempDir dir;
  const fs::path images = make_images(dir, {"a"});
  std::vector<uint8_t> indices(kW * kH, 0);
  indices[3] = 200;  // DAVIS's palette gives 200 the colour black, like the background
  std::vector<uint8_t> palette(3 * 256, 0);
  palette[3] = 128;
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = kW;
  image.height = kH;
  image.format = PNG_FORMAT_RGB_COLORMAP;
  image.colormap_entries = 256;
  fs::create_directories(dir / "sam2_raw");
  ASSERT_TRUE(png_image_write_to_file(&image, (dir / "sam2_raw" / "a.png").c_str(), 0,
                                      indices.data(), kW, palette.data()));
  const MaskImportResult r = run(dir / "sam2_raw", images, dir / "out");
  EXPECT_EQ(r.max_id, 200);
  EXPECT_EQ(read_id_map(dir / "out" / "a.png").at(3, 0), 200);
  EXPECT_FALSE(fs::exists(dir / "out" / "objects.json"));
}

TEST(MaskImport, RgbColoursBecomeIdsInOrderOfFirstAppearance) {
  TempDir dir;
  const fs::path images = make_images(dir, {"a", "b"});
  ImageRGB a(kW, kH), b(kW, kH);
  auto paint = [](ImageRGB& im, int x, int r, int g, int bl) {
    for (int y = 0; y < kH; ++y) {
      im.pixel(x, y)[0] = r / 255.0f;
      im.pixel(x, y)[1] = g / 255.0f;
      im.pixel(x, y)[2] = bl / 255.0f;
    }
  };
  paint(a, 1, 255, 0, 0);
  paint(b, 0, 0, 128, 255);
  paint(b, 2, 255, 0, 0);
  fs::create_directories(dir / "rgb");
  write_image_rgb(dir / "rgb" / "a.png", a);
  write_image_rgb(dir / "rgb" / "b.png", b);
  const MaskImportResult r = run(dir / "rgb", images, dir / "out");
  EXPECT_EQ(r.names, (std::vector<std::string>{"#ff0000", "#0080ff"}));
  EXPECT_EQ(row(read_id_map(dir / "out" / "a.png"), 0), (std::vector<uint16_t>{0, 1, 0, 0, 0, 0}));
  EXPECT_EQ(row(read_id_map(dir / "out" / "b.png"), 3), (std::vector<uint16_t>{2, 0, 1, 0, 0, 0}));
  EXPECT_EQ(names(dir / "out")[1]["name"], "#0080ff");
}

TEST(MaskImport, FrameNumbersCanBePositionsInTheSortedImages) {
  TempDir dir;
  // Phone photos, and SAM2's masks of their numbered copies 00000.jpg, 00001.jpg, ...
  const fs::path images = make_images(dir, {"IMG_0412", "IMG_0415", "IMG_0420"});
  write_mask(dir / "masks" / "mug" / "00001.png", 0, 2);
  write_mask(dir / "masks" / "mug" / "00002.png", 1, 2);
  write_mask(dir / "masks" / "mug" / "00003.png", 1, 2);  // no fourth photo
  MaskImportOptions o;
  o.masks = dir / "masks";
  o.images = images;
  o.frame_naming = FrameNaming::kIndex;
  fs::create_directories(dir / "out");
  const MaskImportResult r = import_masks(o, dir / "out");
  EXPECT_EQ(r.pattern, "{object}/{frame}.png");
  EXPECT_EQ(r.frames_without_masks, 1u);
  EXPECT_EQ(r.skipped_files, std::vector<std::string>{"mug/00003.png"});
  EXPECT_EQ(read_id_map(dir / "out" / "IMG_0412.png").at(0, 0), 0);
  EXPECT_EQ(read_id_map(dir / "out" / "IMG_0415.png").at(0, 0), 1);
  EXPECT_EQ(read_id_map(dir / "out" / "IMG_0420.png").at(1, 0), 1);
  EXPECT_EQ(match_frame("2", {"a", "b", "c"}, FrameNaming::kIndex), "c");
  EXPECT_FALSE(match_frame("3", {"a", "b", "c"}, FrameNaming::kIndex));
  EXPECT_FALSE(match_frame("b", {"a", "b", "c"}, FrameNaming::kIndex));
}

TEST(MaskImport, ChecksItsOptions) {
  TempDir dir;
  MaskImportOptions o;
  o.masks = dir / "none";
  o.images = dir.path();
  EXPECT_THROW(o.Check(), InputError);
  o.masks = dir.path();
  o.pattern = "{object}.png";
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o.pattern = "{object}/{frame}.png";
  o.layout = MaskImportOptions::Layout::kPerFrame;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace splat
