#include "splat/colmap_model.h"

#include <gtest/gtest.h>

#include <random>

#include "splat/error.h"
#include "tests/test_util.h"

namespace splat {
namespace {

using testing_util::read_file;
using testing_util::TempDir;
using testing_util::write_file;

// A model with one camera of every COLMAP model, images with and without 2D
// points, and points with tracks; values random so nothing rounds nicely.
ColmapModel random_model(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-10, 10);
  ColmapModel m;
  uint32_t cam_id = 1;
  for (const auto& info : camera_models()) {
    ColmapCamera c{cam_id, info.id, 640 + cam_id, 480 + cam_id, {}};
    for (int k = 0; k < info.num_params; ++k) c.params.push_back(u(rng));
    m.cameras[cam_id++] = c;
  }
  for (uint32_t i = 1; i <= 5; ++i) {
    ColmapImage im;
    im.image_id = i * 3;
    im.qvec = Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized();
    im.tvec = {u(rng), u(rng), u(rng)};
    im.camera_id = 1 + i % (cam_id - 1);
    im.name = "sub dir/frame_" + std::to_string(i) + ".jpg";
    for (uint32_t k = 0; k < (i == 2 ? 0u : 7u); ++k) {
      im.points2d.emplace_back(u(rng), u(rng));
      im.point3d_ids.push_back(k % 3 == 0 ? kNoPoint3D : int64_t(k));
    }
    m.images[im.image_id] = im;
  }
  for (uint64_t p = 1; p <= 20; ++p) {
    ColmapPoint3D pt;
    pt.point3d_id = p * 7;
    pt.xyz = {u(rng), u(rng), u(rng)};
    pt.rgb = {uint8_t(p), uint8_t(255 - p), uint8_t(3 * p)};
    pt.error = std::abs(u(rng));
    for (uint32_t k = 0; k < p % 4; ++k) pt.track.push_back({3 * (1 + k), k});
    m.points3d[pt.point3d_id] = pt;
  }
  return m;
}

TEST(ColmapModel, CameraModelsByNameAndId) {
  EXPECT_EQ(camera_models().size(), 11u);
  for (const auto& info : camera_models()) {
    EXPECT_EQ(camera_model_by_name(info.name)->id, info.id);
    EXPECT_STREQ(camera_model_by_id(info.id)->name, info.name);
  }
  EXPECT_EQ(camera_model_by_name("OPENCV")->num_params, 8);
  EXPECT_EQ(camera_model_by_name("SIMPLE_RADIAL")->num_params, 4);
  EXPECT_FALSE(camera_model_by_name("NOPE"));
  EXPECT_FALSE(camera_model_by_id(42));
}

TEST(ColmapModel, BinaryRoundTrip) {
  TempDir dir;
  const ColmapModel m = random_model(1);
  write_colmap_model(m, dir.path(), ColmapFormat::kBinary);
  EXPECT_EQ(read_colmap_model(dir.path()), m);
}

TEST(ColmapModel, TextRoundTripIsExact) {
  TempDir dir;
  const ColmapModel m = random_model(2);
  write_colmap_model(m, dir.path(), ColmapFormat::kText);
  EXPECT_EQ(read_colmap_model(dir.path()), m);
}

TEST(ColmapModel, BinaryToTextToBinaryGivesIdenticalFiles) {
  TempDir dir;
  const ColmapModel m = random_model(3);
  write_colmap_model(m, dir / "bin", ColmapFormat::kBinary);
  write_colmap_model(read_colmap_model(dir / "bin"), dir / "txt", ColmapFormat::kText);
  write_colmap_model(read_colmap_model(dir / "txt"), dir / "bin2", ColmapFormat::kBinary);
  for (const char* f : {"cameras.bin", "images.bin", "points3D.bin"})
    EXPECT_EQ(read_file(dir / "bin" / f), read_file(dir / "bin2" / f)) << f;
}

TEST(ColmapModel, ReadsColmapTextWrittenByColmap) {
  // As COLMAP 3.8 writes it: comment header, CRLF tolerated, empty 2D point line.
  TempDir dir;
  write_file(dir / "cameras.txt",
             "# Camera list with one line of data per camera:\n"
             "1 SIMPLE_RADIAL 3072 2304 2559.81 1536 1152 -0.0204\r\n");
  write_file(dir / "images.txt",
             "# Image list with two lines of data per image:\n"
             "1 0.851773 0.0165051 0.503764 -0.142941 -0.737434 1.02973 3.74354 1 P1180141.JPG\n"
             "2362.39 248.498 -1 1784.7 268.254 5\n"
             "2 0.9 0.1 0.1 0.1 0 0 0 1 P1180142.JPG\n"
             "\n");
  write_file(dir / "points3D.txt", "5 1.1 2.2 3.3 10 20 30 0.5 1 1\n");
  const ColmapModel m = read_colmap_model(dir.path());
  ASSERT_EQ(m.cameras.size(), 1u);
  EXPECT_EQ(m.cameras.at(1).model_id, camera_model_by_name("SIMPLE_RADIAL")->id);
  EXPECT_EQ(m.images.at(1).name, "P1180141.JPG");
  EXPECT_EQ(m.images.at(1).point3d_ids, (std::vector<int64_t>{-1, 5}));
  EXPECT_TRUE(m.images.at(2).points2d.empty());
  EXPECT_EQ(m.points3d.at(5).track.size(), 1u);
}

TEST(ColmapModel, PinholeCameraFromPinholeAndSimplePinhole) {
  ColmapModel m;
  m.cameras[1] = {1, 0, 100, 80, {90, 50, 40}};
  m.cameras[2] = {2, 1, 100, 80, {90, 95, 49, 41}};
  ColmapImage im;
  im.camera_id = 1;
  im.tvec = {1, 2, 3};
  Camera c = pinhole_camera(m, im, "model");
  EXPECT_EQ(c.fx, 90);
  EXPECT_EQ(c.fy, 90);
  EXPECT_EQ(c.cx, 50);
  EXPECT_EQ(c.t, Eigen::Vector3d(1, 2, 3));
  im.camera_id = 2;
  c = pinhole_camera(m, im, "model");
  EXPECT_EQ(c.fy, 95);
  EXPECT_EQ(c.cy, 41);
}

TEST(ColmapModel, DistortedCameraIsRejectedWithUndistortionAdvice) {
  ColmapModel m;
  m.cameras[1] = {1, 4, 100, 80, {90, 90, 50, 40, 0.1, 0, 0, 0}};
  ColmapImage im;
  im.camera_id = 1;
  try {
    pinhole_camera(m, im, "scene/sparse/0");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("scene/sparse/0"), std::string::npos) << msg;
    EXPECT_NE(msg.find("OPENCV"), std::string::npos) << msg;
    EXPECT_NE(msg.find("op2gs-sfm"), std::string::npos) << msg;
  }
}

// Every malformed input throws InputError whose message names the bad file.
void expect_model_rejected(const std::filesystem::path& dir, const std::string& file) {
  try {
    read_colmap_model(dir);
    FAIL() << "expected InputError for " << file;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line: " << e.what();
  }
}

TEST(ColmapModel, TruncatedBinaryFilesAreRejected) {
  TempDir dir;
  write_colmap_model(random_model(4), dir.path(), ColmapFormat::kBinary);
  for (const char* f : {"cameras.bin", "images.bin", "points3D.bin"}) {
    TempDir copy;
    for (const char* g : {"cameras.bin", "images.bin", "points3D.bin"})
      write_file(copy / g, read_file(dir / g));
    const std::string bytes = read_file(dir / f);
    for (size_t cut : {size_t(3), bytes.size() / 2, bytes.size() - 1}) {
      write_file(copy / f, bytes.substr(0, cut));
      expect_model_rejected(copy.path(), f);
    }
  }
}

TEST(ColmapModel, HugeCountIsRejectedWithoutAllocating) {
  TempDir dir;
  write_colmap_model(random_model(5), dir.path(), ColmapFormat::kBinary);
  std::string bytes = read_file(dir / "points3D.bin");
  bytes[7] = char(0x7f);  // count = 2^62-ish
  write_file(dir / "points3D.bin", bytes);
  expect_model_rejected(dir.path(), "points3D.bin");
}

TEST(ColmapModel, MalformedTextIsRejected) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"cameras.txt", "1 FANCY_MODEL 10 10 1 2 3\n"},
      {"cameras.txt", "1 PINHOLE 10 10 1 2 3\n"},      // too few params
      {"cameras.txt", "1 PINHOLE 10 10 1 2 3 4 5\n"},  // too many
      {"cameras.txt", "x PINHOLE 10 10 1 2 3 4\n"},
      {"images.txt", "1 1 0 0 0 0 0 0 1 a.png\n1 2\n"},  // 2D point missing its id
      {"images.txt", "1 1 0 0 0 0 0 0 1 a.png\n"},       // no points line
      {"images.txt", "1 1 0 0 0 0 0 0 7 a.png\n\n"},     // unknown camera
      {"points3D.txt", "1 0 0 0 300 0 0 0\n"},           // colour out of range
      {"points3D.txt", "1 0 0 0 1 2 3 0 5\n"},           // half a track element
  };
  for (const auto& [file, text] : cases) {
    TempDir dir;
    write_file(dir / "cameras.txt", "1 PINHOLE 10 10 1 2 3 4\n");
    write_file(dir / "images.txt", "1 1 0 0 0 0 0 0 1 a.png\n\n");
    write_file(dir / "points3D.txt", "");
    write_file(dir / file, text);
    SCOPED_TRACE(text);
    expect_model_rejected(dir.path(), file == "images.txt" && text.find(" 7 ") != std::string::npos
                                          ? "images"
                                          : file);
  }
}

TEST(ColmapModel, MissingModelNamesTheFolder) {
  TempDir dir;
  expect_model_rejected(dir.path(), dir.path().string());
}

}  // namespace
}  // namespace splat
