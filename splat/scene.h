#pragma once
// A scene folder as users bring it (docs/inputs.md): images/,
// optional images_2/4/8/, and a COLMAP model in sparse/0/. Views are decoded
// lazily through a bounded cache.

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "splat/camera.h"
#include "splat/view_cache.h"

namespace splat {

struct SceneOptions {
  std::string images_dir = "images";     // folder of full-resolution images
  std::string sparse_dir = "sparse/0";   // COLMAP model, relative to the scene
  int downscale = 1;                     // 1, 2, 4 or 8 (uses images_N/ if present)
  int max_width = 0;                     // if > 0, scale down so width <= max_width
  size_t cache_bytes = size_t(2) << 30;  // views kept in memory (packed: view_cache.h)
  // If set, a pose file (pose_file.h) whose poses replace the COLMAP model's
  // for the views it names: the poses refined by an earlier stage. The scene
  // extent stays that of the model's poses.
  std::filesystem::path poses;

  // Throws std::invalid_argument with a one-line message for bad values.
  void Check() const;
};

struct View {
  std::string name;            // image name as in the COLMAP model
  Camera camera;               // at the loaded resolution
  std::filesystem::path file;  // decoded and area-resized to camera's size on load
  // The size the file must have: the camera's full size for images/, within a
  // pixel of the downscaled size for an images_N/ folder.
  int file_width = 0, file_height = 0;
  bool file_is_downscaled = false;
};

class Scene {
 public:
  // Reads the COLMAP model and the list of views; decodes no image yet.
  // Throws InputError for missing files, distorted cameras, or a model whose
  // images are not in the images folder.
  static std::unique_ptr<Scene> load(const std::filesystem::path& root,
                                     const SceneOptions& options);

  const std::filesystem::path& root() const { return root_; }
  const std::vector<View>& views() const { return views_; }
  std::vector<Camera> cameras() const;
  // Index of the view with this image name, or -1.
  int find_view(const std::string& name) const;

  // The decoded image of view i, exactly camera.width x camera.height.
  std::shared_ptr<const ImageRGB> image(size_t i) { return cache_->get(i); }
  std::shared_ptr<const PackedImageRGB> packed_image(size_t i) { return cache_->packed(i); }
  // Decodes these views now, on all cores, as far as the cache holds them
  // (ViewCache::preload); returns how many are held.
  size_t preload(const std::vector<size_t>& views) { return cache_->preload(views); }
  const ViewCache& cache() const { return *cache_; }

  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  const std::vector<Eigen::Vector3f>& point_colors() const { return point_colors_; }
  double extent() const { return extent_; }

 private:
  PackedImageRGB load_view(size_t i) const;
  void replace_poses(const std::filesystem::path& file);

  std::filesystem::path root_;
  std::vector<View> views_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<Eigen::Vector3f> point_colors_;  // RGB in [0, 1]
  double extent_ = 0;
  std::unique_ptr<ViewCache> cache_;
};

}  // namespace splat
