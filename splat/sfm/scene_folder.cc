#include "splat/sfm/scene_folder.h"

#include <spdlog/spdlog.h>

#include <set>

#include "splat/photo_cameras.h"
#include "splat/sfm/undistort_id_maps.h"

namespace splat {
namespace fs = std::filesystem;

namespace {

// Replaces `link` with a symbolic link to `target`.
void relink(const fs::path& target, const fs::path& link) {
  fs::remove_all(link);
  fs::create_directories(link.parent_path());
  fs::create_directory_symlink(fs::absolute(target), link);
}

// The cameras and poses of a model, without its points and observations.
ColmapModel cameras_only(ColmapModel model) {
  model.points3d.clear();
  for (auto& [id, image] : model.images) image.points2d.clear(), image.point3d_ids.clear();
  return model;
}

}  // namespace

void write_pinhole_scene(const ColmapModel& model, const fs::path& photos, const fs::path& scene) {
  write_colmap_model(model, scene / "sparse" / "0", ColmapFormat::kBinary);
  relink(photos, scene / "images");
}

void write_undistorted_scene(const fs::path& undistorted, const ColmapModel& distorted,
                             const fs::path& scene) {
  write_colmap_model(read_colmap_model(undistorted / "sparse"), scene / "sparse" / "0",
                     ColmapFormat::kBinary);
  relink(undistorted / "images", scene / "images");
  write_colmap_model(cameras_only(distorted), scene / kPhotoCamerasDir, ColmapFormat::kBinary);
}

void undistort_user_id_maps(const fs::path& user, const fs::path& scene,
                            const ColmapModel& distorted,
                            const std::vector<std::string>& id_map_dirs) {
  const ColmapModel undistorted = read_colmap_model(scene / "sparse" / "0");
  for (const std::string& folder : id_map_dirs) {
    if (!fs::is_directory(user / folder)) continue;
    const size_t n = undistort_id_map_folder(user / folder, scene / folder, distorted, undistorted);
    spdlog::info("{}/: {} ID maps undistorted with the images", folder, n);
  }
  for (const char* truth : {"test_mask", "segmentations"})
    if (fs::exists(user / truth))
      spdlog::warn(
          "{}/ is linked as it is: its masks have the geometry of the original photos; "
          "op2gs-eval resamples the renders into it ({}/)",
          truth, kPhotoCamerasDir);
}

void link_user_files(const fs::path& user, const fs::path& scene, const std::string& images,
                     bool undistorted) {
  // distorted/ and stereo/ are COLMAP's leftovers in the LERF-Mask download.
  std::set<std::string> own = {images, "sparse", "distorted", "stereo"};
  if (undistorted) own.insert({"images_2", "images_4", "images_8"});
  for (const auto& f : fs::directory_iterator(user)) {
    const std::string name = f.path().filename().string();
    if (own.count(name) || fs::exists(fs::symlink_status(scene / name))) continue;
    fs::create_symlink(fs::absolute(f.path()), scene / name);
  }
}

}  // namespace splat
