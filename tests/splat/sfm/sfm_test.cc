// op2gs-sfm's run with the real COLMAP on a small synthetic scene generated
// without its model: every view registers, the poses match the true ones
// after a similarity alignment, a rerun reuses the finished steps, and the
// user's folder is left as it was.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/colmap_model.h"
#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/npy.h"
#include "splat/photo_cameras.h"
#include "splat/sfm/alignment.h"
#include "splat/sfm/sfm_run.h"
#include "synth/generator.h"
#include "tests/test_util.h"

namespace splat {
namespace {

namespace fs = std::filesystem;
using testing_util::TempDir;

constexpr size_t kViews = 12;

// The first 12 views of the default scene (40 views around the orbit, 9
// degrees apart, 320x240) without sparse/, the same views in the 3DOVS
// layout, and the true model of all 40. Made once for all the tests of this
// binary (it takes longer than most of them).
struct SfmScene {
  fs::path scene, truth, ovs;
  double orbit_radius;
};
synth::SynthOptions sfm_scene_options() {
  synth::SynthOptions o;
  o.supersample = 2;
  return o;
}
void make_sfm_scene(const fs::path& d) {
  synth::SynthOptions o = sfm_scene_options();
  o.ovs_dir = d / "ovs_all";
  synth::generate_scene(o, d / "full", true);
  for (size_t i = 0; i < kViews; ++i) {
    const std::string name = fmt::format("frame_{:05d}.png", i);
    for (const char* folder : {"images", "sam2"}) {
      fs::create_directories(d / "scene" / folder);
      fs::copy_file(d / "full" / folder / name, d / "scene" / folder / name);
    }
    fs::create_directories(d / "ovs" / "images");
    const std::string ovs_name = fmt::format("{:02d}.png", i);
    fs::copy_file(d / "ovs_all/images" / ovs_name, d / "ovs/images" / ovs_name);
  }
  std::vector<size_t> shape;
  std::vector<double> poses = read_npy(d / "ovs_all/poses_bounds.npy", &shape);
  poses.resize(kViews * 17);
  write_npy_f64(d / "ovs/poses_bounds.npy", poses, {kViews, 17});
}
const SfmScene& sfm_scene() {
  static const SfmScene s = [] {
    const fs::path d = testing_util::shared_test_data("sfm_scene", make_sfm_scene);
    return SfmScene{d / "scene", d / "full" / "sparse" / "0", d / "ovs",
                    sfm_scene_options().orbit_radius};
  }();
  return s;
}

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> files;
  for (const auto& f : fs::recursive_directory_iterator(dir))
    files.push_back(f.path().string() + " " +
                    std::to_string(f.is_regular_file() ? f.file_size() : 0));
  std::sort(files.begin(), files.end());
  return files;
}

// COLMAP's own reconstruction of the 12 photos, made once.
struct Reconstruction {
  fs::path out;
  SfmResult result;
  std::vector<std::string> user_files_before;
};
const Reconstruction& colmap_reconstruction() {
  static const Reconstruction r = [] {
    const auto before = listing(sfm_scene().scene);
    const fs::path out = testing_util::process_temp_dir("sfm_colmap");
    SfmOptions o;
    o.gpu = SfmOptions::Gpu::kOff;
    return Reconstruction{out, run_sfm(sfm_scene().scene, out, o), before};
  }();
  return r;
}

TEST(Sfm, RegistersEveryViewWithAccuratePosesAndReusesSteps) {
  const fs::path out = colmap_reconstruction().out;
  const auto before = colmap_reconstruction().user_files_before;
  SfmOptions o;
  o.gpu = SfmOptions::Gpu::kOff;
  const SfmResult& r = colmap_reconstruction().result;
  EXPECT_EQ(r.registered, kViews);
  EXPECT_TRUE(r.unregistered.empty());
  EXPECT_EQ(listing(sfm_scene().scene), before);  // the user's folder is untouched

  const ColmapModel model = read_colmap_model(r.scene / "sparse" / "0");
  for (const auto& [id, cam] : model.cameras) EXPECT_EQ(cam.model_id, 1);  // PINHOLE
  EXPECT_GT(model.points3d.size(), 100u);
  EXPECT_TRUE(fs::exists(r.scene / "images" / "frame_00000.png"));
  // The ID maps were undistorted with the images: same size, no longer a link.
  EXPECT_FALSE(fs::is_symlink(r.scene / "sam2"));
  for (const auto& [id, image] : model.images) {
    const IdMap map = read_id_map(r.scene / "sam2" / image.name);
    EXPECT_EQ(map.width, int(model.cameras.at(image.camera_id).width)) << image.name;
    EXPECT_EQ(map.height, int(model.cameras.at(image.camera_id).height)) << image.name;
  }

  const PoseAccuracy acc = pose_accuracy(model, read_colmap_model(sfm_scene().truth));
  EXPECT_EQ(acc.matched, kViews);
  EXPECT_LT(acc.center_rmse, 0.01 * sfm_scene().orbit_radius);

  // A rerun reuses extraction, matching and mapping.
  const auto log_size = fs::file_size(out / "colmap.log");
  run_sfm(sfm_scene().scene, out, o);
  EXPECT_EQ(fs::file_size(out / "colmap.log"), log_size);
}

TEST(Sfm, ImportsAnExistingModel) {
  TempDir out;
  SfmOptions o;
  o.import_model = sfm_scene().truth;
  const fs::path full = sfm_scene().truth.parent_path().parent_path();
  const SfmResult r = run_sfm(full, out.path(), o);
  EXPECT_EQ(r.registered, 40u);
  EXPECT_EQ(read_colmap_model(r.scene / "sparse" / "0"), read_colmap_model(sfm_scene().truth));
}

// A user's scene holding `model` in sparse/0/: its images and ID maps
// (links to the synthetic scene's) and a downscaled copy images_2/.
fs::path scene_with_model(const fs::path& dir, const ColmapModel& model) {
  const fs::path full = sfm_scene().truth.parent_path().parent_path();
  for (const auto& [id, image] : model.images)
    for (const char* folder : {"images", "sam2"}) {
      fs::create_directories(dir / folder);
      fs::create_symlink(full / folder / image.name, dir / folder / image.name);
    }
  testing_util::write_file(dir / "images_2" / "frame_00000.png", "x");
  write_colmap_model(model, dir / "sparse" / "0", ColmapFormat::kText);
  return dir;
}

// The true model restricted to the 12 views of the SfM scene.
ColmapModel truth_of_first_views() {
  ColmapModel model = read_colmap_model(sfm_scene().truth);
  std::erase_if(model.images, [](const auto& kv) { return kv.second.name >= "frame_00012.png"; });
  return model;
}

TEST(Sfm, ImportedPinholeModelNeedsNoColmapAndKeepsTheUsersFiles) {
  TempDir user, out;
  const ColmapModel model = truth_of_first_views();
  const fs::path scene = scene_with_model(user.path(), model);
  SfmOptions o;
  o.import_model = scene / "sparse" / "0";
  o.colmap.binary = "/nonexistent/colmap";
  const SfmResult r = run_sfm(scene, out.path(), o);
  EXPECT_EQ(r.registered, kViews);
  EXPECT_EQ(read_colmap_model(r.scene / "sparse" / "0"), model);
  // Nothing was resampled, so the ID maps and the downscaled copies are the user's.
  EXPECT_TRUE(fs::is_symlink(r.scene / "sam2"));
  EXPECT_TRUE(fs::is_symlink(r.scene / "images_2"));
  EXPECT_FALSE(fs::exists(r.scene / kPhotoCamerasDir));  // the views are the photos
}

TEST(Sfm, ImportedDistortedModelIsUndistorted) {
  TempDir user, out;
  ColmapModel model = truth_of_first_views();
  for (auto& [id, cam] : model.cameras) {
    cam.model_id = 4;  // OPENCV: fx fy cx cy k1 k2 p1 p2
    cam.params.insert(cam.params.end(), {-0.08, 0.01, 0.0, 0.0});
  }
  const fs::path scene = scene_with_model(user.path(), model);
  SfmOptions o;
  o.import_model = scene / "sparse" / "0";
  const SfmResult r = run_sfm(scene, out.path(), o);
  const ColmapModel undistorted = read_colmap_model(r.scene / "sparse" / "0");
  ASSERT_EQ(undistorted.images.size(), kViews);
  for (const auto& [id, cam] : undistorted.cameras) EXPECT_EQ(cam.model_id, 1);  // PINHOLE
  EXPECT_FALSE(fs::is_symlink(r.scene / "sam2"));
  for (const auto& [id, image] : undistorted.images) {
    const ColmapCamera& cam = undistorted.cameras.at(image.camera_id);
    const IdMap map = read_id_map(r.scene / "sam2" / image.name);
    EXPECT_EQ(map.width, int(cam.width)) << image.name;
    EXPECT_EQ(map.height, int(cam.height)) << image.name;
  }
  // The user's downscaled photos keep the distortion: not linked.
  EXPECT_FALSE(fs::exists(fs::symlink_status(r.scene / "images_2")));
  // The photos' cameras, for scoring against ground truth drawn on them.
  const ColmapModel photos = read_colmap_model(r.scene / kPhotoCamerasDir);
  EXPECT_EQ(photos.cameras, model.cameras);
  EXPECT_EQ(photos.images.size(), kViews);
  EXPECT_TRUE(photos.points3d.empty());
}

TEST(Sfm, ImportedModelNamingAMissingImageIsAnInputError) {
  TempDir user, out;
  const fs::path scene = scene_with_model(user.path(), truth_of_first_views());
  fs::remove(scene / "images" / "frame_00003.png");
  SfmOptions o;
  o.import_model = scene / "sparse" / "0";
  try {
    run_sfm(scene, out.path(), o);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame_00003.png"), std::string::npos) << e.what();
  }
}

TEST(Sfm, LlffCamerasAreKeptAndPointsTriangulated) {
  TempDir out;
  SfmOptions o;
  o.gpu = SfmOptions::Gpu::kOff;
  o.llff = true;
  const SfmResult r = run_sfm(sfm_scene().ovs, out.path(), o);
  EXPECT_EQ(r.registered, kViews);
  const ColmapModel model = read_colmap_model(r.scene / "sparse" / "0");
  EXPECT_GT(model.points3d.size(), 100u);
  // The cameras are the true ones (3DOVS names its images 00.png, 01.png, ...
  // in the order of the LERF-Mask layout's frame_NNNNN.png).
  ColmapModel truth = read_colmap_model(sfm_scene().truth);
  for (auto& [id, image] : truth.images)
    image.name = image.name.substr(image.name.size() - 6);  // "frame_00012.png" -> "12.png"
  const PoseAccuracy acc = pose_accuracy(model, truth);
  EXPECT_EQ(acc.matched, kViews);
  EXPECT_LT(acc.center_rmse, 1e-6);
  EXPECT_NEAR(acc.alignment.scale, 1.0, 1e-9);
}

// An instant-ngp transforms.json of `model`'s cameras (PINHOLE), without
// points, beside the photos of the SfM scene; one frame names a photo that
// is not there.
fs::path instant_ngp_capture(const fs::path& dir, const ColmapModel& model) {
  nlohmann::json frames = nlohmann::json::array();
  for (const auto& [id, image] : model.images) {
    const Eigen::Matrix3d r =
        Eigen::Quaterniond(image.qvec[0], image.qvec[1], image.qvec[2], image.qvec[3])
            .toRotationMatrix();
    Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
    c2w.topLeftCorner<3, 3>() = r.transpose();
    c2w.topRightCorner<3, 1>() = -r.transpose() * image.tvec;
    c2w.col(1) *= -1;  // OpenCV to OpenGL axes
    c2w.col(2) *= -1;
    nlohmann::json m = nlohmann::json::array();
    for (int i = 0; i < 4; ++i) m.push_back({c2w(i, 0), c2w(i, 1), c2w(i, 2), c2w(i, 3)});
    frames.push_back(
        {{"file_path", "images/" + fs::path(image.name).stem().string()}, {"transform_matrix", m}});
  }
  frames.push_back(
      {{"file_path", "images/frame_00099"}, {"transform_matrix", frames[0]["transform_matrix"]}});
  const ColmapCamera& c = model.cameras.begin()->second;
  const nlohmann::json t = {{"camera_angle_x", 2 * std::atan(0.5 * c.width / c.params[0])},
                            {"fl_x", c.params[0]},
                            {"fl_y", c.params[1]},
                            {"cx", c.params[2]},
                            {"cy", c.params[3]},
                            {"aabb_scale", 16},
                            {"frames", frames}};
  for (const char* folder : {"images", "sam2"})
    fs::create_directory_symlink(sfm_scene().scene / folder, dir / folder);
  testing_util::write_file(dir / "transforms.json", t.dump(2));
  return dir / "transforms.json";
}

// A capture's poses are kept, its points triangulated by COLMAP; the poses
// agree with COLMAP's own reconstruction of the same photos.
TEST(Sfm, CaptureWithoutPointsIsTriangulatedAndAgreesWithColmapSfm) {
  TempDir user, out;
  SfmOptions o;
  o.gpu = SfmOptions::Gpu::kOff;
  o.import_model = instant_ngp_capture(user.path(), truth_of_first_views());
  const SfmResult r = run_sfm(user.path(), out.path(), o);
  EXPECT_EQ(r.registered, kViews);
  const ColmapModel model = read_colmap_model(r.scene / "sparse" / "0");
  EXPECT_GT(model.points3d.size(), 100u);
  const nlohmann::json summary = nlohmann::json::parse(read_text_file(out / "sfm.json"));
  EXPECT_EQ(summary["frames_without_photo"], nlohmann::json({"images/frame_00099"}));
  const PoseAccuracy truth = pose_accuracy(model, read_colmap_model(sfm_scene().truth));
  EXPECT_LT(truth.center_rmse, 1e-6);
  const ColmapModel colmap =
      read_colmap_model(colmap_reconstruction().result.scene / "sparse" / "0");
  const PoseAccuracy acc = pose_accuracy(model, colmap);
  EXPECT_EQ(acc.matched, kViews);
  EXPECT_LT(acc.center_rmse / acc.alignment.scale, 0.01 * sfm_scene().orbit_radius);
  EXPECT_LT(acc.rotation_error_deg, 1.0);
}

TEST(Sfm, MissingColmapSaysHowToInstallIt) {
  TempDir out;
  SfmOptions o;
  o.colmap.binary = "/nonexistent/colmap";
  try {
    run_sfm(sfm_scene().scene, out.path(), o);
    FAIL() << "expected an error";
  } catch (const ColmapError& e) {
    EXPECT_NE(std::string(e.what()).find("apt-get install colmap"), std::string::npos) << e.what();
  }
}

// The ID map folders are replaced inside the output scene: anything but a
// plain folder name could point elsewhere.
TEST(Sfm, IdMapFoldersMustBePlainNames) {
  for (const char* bad : {"", ".", "..", "/", "../sam2", "a/b", "images", "sparse"}) {
    SfmOptions o;
    o.id_map_dirs = {"sam2", bad};
    EXPECT_THROW(o.Check(), std::invalid_argument) << "'" << bad << "'";
  }
  SfmOptions o;
  o.id_map_dirs = {"sam2", "masks_v2"};
  EXPECT_NO_THROW(o.Check());
}

TEST(Sfm, TooFewImagesIsAnInputError) {
  TempDir scene, out;
  testing_util::write_file(scene / "images/a.png", "x");
  EXPECT_THROW(run_sfm(scene.path(), out.path(), SfmOptions{}), InputError);
}

}  // namespace
}  // namespace splat
