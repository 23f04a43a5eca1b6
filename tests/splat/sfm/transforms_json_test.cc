// nerfstudio and instant-ngp transforms.json read into COLMAP models: the
// poses of the generator's true cameras come back exactly (after the
// similarity nerfstudio's applied_transform adds), intrinsics and distortion
// map to COLMAP's camera models, missing photos are skipped and listed, and
// malformed files fail naming the file.

#include "splat/sfm/transforms_json.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "splat/error.h"
#include "splat/image.h"
#include "splat/ply.h"
#include "splat/sfm/alignment.h"
#include "synth/generator.h"
#include "synth/render_scene.h"
#include "synth/world.h"
#include "tests/test_util.h"

namespace splat {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using testing_util::TempDir;

synth::SynthOptions small_capture(synth::OutputFormat format) {
  synth::SynthOptions o;
  o.views = 8;
  o.width = 64;
  o.height = 48;
  o.supersample = 1;
  o.num_points = 300;
  o.format = format;
  return o;
}

// The generator's true cameras as a COLMAP model named like the capture.
ColmapModel true_model(const synth::SynthOptions& o) {
  ColmapModel m;
  const auto cameras = synth::orbit_cameras(o, synth::default_world(o.seed));
  m.cameras[1] = synth::photo_camera(o, cameras.front());
  for (size_t i = 0; i < cameras.size(); ++i) {
    ColmapImage image;
    image.image_id = uint32_t(i + 1);
    image.camera_id = 1;
    image.qvec = quaternion_from_rotation(cameras[i].R);
    image.tvec = cameras[i].t;
    image.name = synth::view_name(int(i), ".jpg");
    m.images[image.image_id] = image;
  }
  return m;
}

TEST(TransformsJson, NerfstudioPosesAreTheTrueOnesUpToItsAppliedTransform) {
  TempDir dir;
  synth::SynthOptions o = small_capture(synth::OutputFormat::kNerfstudio);
  o.distortion = {-0.05, 0.01, 0.001, -0.002};
  synth::generate_scene(o, dir / "ns", false);
  const TransformsCapture c = read_transforms_json(dir / "ns/transforms.json", dir / "ns/images");
  EXPECT_EQ(c.flavour, "nerfstudio");
  EXPECT_TRUE(c.missing.empty());
  ASSERT_EQ(c.model.images.size(), 8u);
  ASSERT_EQ(c.model.cameras.size(), 1u);
  const ColmapModel truth = true_model(o);
  EXPECT_EQ(c.model.cameras.begin()->second.model_id, camera_model_by_name("OPENCV")->id);
  for (size_t k = 0; k < 8; ++k)
    EXPECT_NEAR(c.model.cameras.begin()->second.params[k], truth.cameras.at(1).params[k], 1e-9);
  const PoseAccuracy acc = pose_accuracy(c.model, truth);
  EXPECT_EQ(acc.matched, 8u);
  EXPECT_LT(acc.center_rmse, 1e-9);
  EXPECT_LT(acc.rotation_error_deg, 1e-6);
  EXPECT_NEAR(acc.alignment.scale, 1.0, 1e-9);
  // The points of sparse_pc.ply, in the frame of the poses: each projects
  // into at least one view.
  ASSERT_TRUE(c.has_points);
  EXPECT_GT(c.model.points3d.size(), 100u);
  const std::vector<double>& k = c.model.cameras.begin()->second.params;
  size_t seen = 0;
  for (const auto& [id, p] : c.model.points3d) {
    for (const auto& [iid, image] : c.model.images) {
      const Eigen::Quaterniond q(image.qvec[0], image.qvec[1], image.qvec[2], image.qvec[3]);
      const Eigen::Vector3d x = q.toRotationMatrix() * p.xyz + image.tvec;
      if (x.z() <= 0) continue;
      const double u = k[0] * x.x() / x.z() + k[2], v = k[1] * x.y() / x.z() + k[3];
      if (u > -10 && u < 74 && v > -10 && v < 58) {
        ++seen;
        break;
      }
    }
  }
  EXPECT_GT(seen, c.model.points3d.size() * 9 / 10);
}

TEST(TransformsJson, InstantNgpWithoutExtensionsAndWithMissingPhotos) {
  TempDir dir;
  const synth::SynthOptions o = small_capture(synth::OutputFormat::kInstantNgp);
  synth::generate_scene(o, dir / "ngp", false);
  fs::remove(dir / "ngp/images/frame_00003.jpg");
  const TransformsCapture c = read_transforms_json(dir / "ngp/transforms.json", dir / "ngp/images");
  EXPECT_EQ(c.flavour, "instant-ngp");
  EXPECT_EQ(c.missing, std::vector<std::string>{"images/frame_00003"});
  EXPECT_EQ(c.model.images.size(), 7u);
  EXPECT_FALSE(c.has_points);
  const PoseAccuracy acc = pose_accuracy(c.model, true_model(o));
  EXPECT_EQ(acc.matched, 7u);
  EXPECT_LT(acc.center_rmse, 1e-9);
  EXPECT_NEAR(acc.alignment.scale, 1.0, 1e-9);
}

TEST(TransformsJson, PhotosLinkedFromElsewhereKeepTheLinksNames) {
  TempDir dir;
  const synth::SynthOptions o = small_capture(synth::OutputFormat::kNerfstudio);
  synth::generate_scene(o, dir / "capture", false);
  // The scene links each photo of a capture kept elsewhere, under its name.
  fs::create_directories(dir / "scene/images");
  for (const auto& photo : fs::directory_iterator(dir / "capture/images"))
    fs::create_symlink(photo.path(), dir / "scene/images" / photo.path().filename());
  fs::copy_file(dir / "capture/transforms.json", dir / "scene/transforms.json");
  fs::copy_file(dir / "capture/sparse_pc.ply", dir / "scene/sparse_pc.ply");
  const TransformsCapture c =
      read_transforms_json(dir / "scene/transforms.json", dir / "scene/images");
  EXPECT_EQ(c.model.images.size(), 8u);
  EXPECT_TRUE(c.missing.empty());
}

// A capture of two 8x6 photos with the given top-level keys.
fs::path capture(const fs::path& dir, json top) {
  ImageRGB image(8, 6);
  write_image_rgb(dir / "images/a.png", image);
  write_image_rgb(dir / "images/b.png", image);
  const json pose = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 2}, {0, 0, 0, 1}};
  top["frames"] = {{{"file_path", "images/a.png"}, {"transform_matrix", pose}},
                   {{"file_path", "images/b.png"}, {"transform_matrix", pose}}};
  testing_util::write_file(dir / "transforms.json", top.dump());
  return dir / "transforms.json";
}

ColmapCamera camera_of(const fs::path& dir, const json& top) {
  return read_transforms_json(capture(dir, top), dir / "images").model.cameras.at(1);
}

TEST(TransformsJson, IntrinsicsMapToColmapCameraModels) {
  TempDir dir;
  const json base = {{"fl_x", 10}, {"fl_y", 11}, {"cx", 4}, {"cy", 3}, {"w", 8}, {"h", 6}};
  EXPECT_EQ(camera_of(dir.path(), base).params, (std::vector<double>{10, 11, 4, 3}));
  json opencv = base;
  opencv.update({{"k1", 0.1}, {"k2", 0.2}, {"p1", 0.3}, {"p2", 0.4}});
  EXPECT_EQ(camera_of(dir.path(), opencv).model_id, camera_model_by_name("OPENCV")->id);
  EXPECT_EQ(camera_of(dir.path(), opencv).params,
            (std::vector<double>{10, 11, 4, 3, 0.1, 0.2, 0.3, 0.4}));
  json full = opencv;
  full["k3"] = 0.5;
  EXPECT_EQ(camera_of(dir.path(), full).model_id, camera_model_by_name("FULL_OPENCV")->id);
  EXPECT_EQ(camera_of(dir.path(), full).params[8], 0.5);
  json fisheye = base;
  fisheye.update({{"camera_model", "OPENCV_FISHEYE"}, {"k1", 0.1}, {"k4", 0.4}});
  EXPECT_EQ(camera_of(dir.path(), fisheye).model_id, camera_model_by_name("OPENCV_FISHEYE")->id);
  EXPECT_EQ(camera_of(dir.path(), fisheye).params,
            (std::vector<double>{10, 11, 4, 3, 0.1, 0, 0, 0.4}));
  // instant-ngp: the focal length from the field of view; the size and the
  // principal point from the photo.
  const ColmapCamera angle = camera_of(dir.path(), {{"camera_angle_x", 2 * std::atan(0.5)}});
  EXPECT_NEAR(angle.params[0], 8.0, 1e-9);
  EXPECT_NEAR(angle.params[1], 8.0, 1e-9);
  EXPECT_EQ(angle.params[2], 4.0);
  EXPECT_EQ(angle.params[3], 3.0);
}

std::string error_of(const fs::path& dir, const json& top) {
  try {
    read_transforms_json(capture(dir, top), dir / "images");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(TransformsJson, BadFilesSayWhatIsWrongNamingTheFile) {
  TempDir dir;
  const json base = {{"fl_x", 10}, {"w", 8}, {"h", 6}};
  const std::string file = (dir / "transforms.json").string();
  auto expect = [&](const json& top, const std::string& what) {
    const std::string e = error_of(dir.path(), top);
    EXPECT_NE(e.find(file), std::string::npos) << e;
    EXPECT_NE(e.find(what), std::string::npos) << e;
  };
  expect({{"w", 8}, {"h", 6}}, "no focal length");
  expect({{"fl_x", 10}, {"w", 9}, {"h", 6}}, "the photo is 8x6, the file says 9x6");
  json k4 = base;
  k4.update({{"k1", 0.1}, {"k4", 0.1}});
  expect(k4, "k4");
  json eq = base;
  eq["camera_model"] = "EQUIRECTANGULAR";
  expect(eq, "EQUIRECTANGULAR");

  testing_util::write_file(dir / "transforms.json", "{\"frames\": [");
  EXPECT_THROW(read_transforms_json(dir / "transforms.json", dir / "images"), InputError);
  testing_util::write_file(dir / "transforms.json", "{\"fl_x\": 1}");
  EXPECT_THROW(read_transforms_json(dir / "transforms.json", dir / "images"), InputError);
  json scaled = {{"fl_x", 10},
                 {"frames",
                  {{{"file_path", "images/a.png"},
                    {"transform_matrix", {{2, 0, 0, 0}, {0, 2, 0, 0}, {0, 0, 2, 0}}}}}}};
  testing_util::write_file(dir / "transforms.json", scaled.dump());
  try {
    read_transforms_json(dir / "transforms.json", dir / "images");
    FAIL() << "a scaled rotation passed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a rotation"), std::string::npos) << e.what();
  }
  json none = {{"fl_x", 10}, {"frames", {{{"file_path", "images/gone.png"}}}}};
  testing_util::write_file(dir / "transforms.json", none.dump());
  EXPECT_THROW(read_transforms_json(dir / "transforms.json", dir / "images"), InputError);
}

TEST(PointPly, ReadsAsciiAndBinaryClouds) {
  TempDir dir;
  testing_util::write_file(dir / "a.ply",
                           "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty "
                           "float y\nproperty float z\nproperty uint8 red\nproperty uint8 "
                           "green\nproperty uint8 blue\nend_header\n1 2 3 10 20 30\n-1 0.5 2 0 0 "
                           "255\n");
  const PointCloud a = read_point_ply(dir / "a.ply");
  ASSERT_EQ(a.xyz.size(), 2u);
  EXPECT_EQ(a.xyz[1], Eigen::Vector3d(-1, 0.5, 2));
  EXPECT_EQ(a.rgb[0], (std::array<uint8_t, 3>{10, 20, 30}));
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty double x\nproperty "
      "double y\nproperty double z\nend_header\n";
  const double xyz[3] = {0.25, -4, 8};
  binary.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  testing_util::write_file(dir / "b.ply", binary);
  const PointCloud b = read_point_ply(dir / "b.ply");
  ASSERT_EQ(b.xyz.size(), 1u);
  EXPECT_EQ(b.xyz[0], Eigen::Vector3d(0.25, -4, 8));
  EXPECT_EQ(b.rgb[0], (std::array<uint8_t, 3>{128, 128, 128}));  // no colour in the file
  testing_util::write_file(dir / "c.ply",
                           "ply\nformat ascii 1.0\nelement vertex 1\nproperty float "
                           "x\nend_header\n1\n");
  EXPECT_THROW(read_point_ply(dir / "c.ply"), InputError);
  // Found by fuzzing: a NaN colour was cast to a byte.
  testing_util::write_file(dir / "d.ply",
                           "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty "
                           "float y\nproperty float z\nproperty float red\nend_header\n1 2 3 "
                           "nan\n1 2 3 4\n");
  try {
    read_point_ply(dir / "d.ply");
    FAIL() << "a NaN colour was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("1 of 2 points have NaN"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace splat
