#include "splat/scene.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "splat/colmap_model.h"
#include "splat/error.h"
#include "splat/image.h"
#include "splat/packed_image.h"
#include "splat/pose_file.h"

namespace splat {
namespace fs = std::filesystem;

void SceneOptions::Check() const {
  if (downscale != 1 && downscale != 2 && downscale != 4 && downscale != 8)
    throw std::invalid_argument(fmt::format("downscale must be 1, 2, 4 or 8, not {}", downscale));
  if (max_width < 0) throw std::invalid_argument("max_width must be >= 0");
  if (cache_bytes == 0) throw std::invalid_argument("cache_bytes must be > 0");
}

namespace {

// The resolution a view is trained at, from its full size and the options.
std::pair<int, int> target_size(int width, int height, const SceneOptions& o) {
  if (o.max_width > 0 && width > o.max_width) {
    const double s = double(o.max_width) / width;
    return {o.max_width, std::max(1, int(std::lround(height * s)))};
  }
  return downscaled_size(width, height, o.downscale);
}

}  // namespace

namespace {

// Files in images_N/ may differ from the computed size by a rounding pixel.
void check_file_size(const View& v, int width, int height) {
  const int slack = v.file_is_downscaled ? 1 : 0;
  if (std::abs(width - v.file_width) > slack || std::abs(height - v.file_height) > slack)
    throw InputError(v.file, fmt::format("image is {}x{} but its camera in the COLMAP model says "
                                         "{}x{}",
                                         width, height, v.file_width, v.file_height));
}

}  // namespace

std::unique_ptr<Scene> Scene::load(const fs::path& root, const SceneOptions& options) {
  options.Check();
  auto scene = std::make_unique<Scene>();
  scene->root_ = root;
  const fs::path sparse = root / options.sparse_dir;
  const ColmapModel model = read_colmap_model(sparse);
  if (model.images.empty()) throw InputError(sparse, "COLMAP model has no registered images");

  const fs::path full_dir = root / options.images_dir;
  const fs::path scaled_dir = root / fmt::format("{}_{}", options.images_dir, options.downscale);
  const bool use_scaled =
      options.downscale > 1 && options.max_width == 0 && fs::is_directory(scaled_dir);

  size_t capped = 0, widest = 0;
  for (const auto& [id, im] : model.images) {
    View v;
    v.name = im.name;
    const Camera full = pinhole_camera(model, im, sparse);
    const auto [w, h] = target_size(full.width, full.height, options);
    if (options.max_width > 0 && full.width > options.max_width)
      ++capped, widest = std::max<size_t>(widest, size_t(full.width));
    v.camera = full.resized(w, h);
    v.file = (use_scaled ? scaled_dir : full_dir) / im.name;
    v.file_is_downscaled = use_scaled;
    v.file_width = use_scaled ? w : full.width;
    v.file_height = use_scaled ? h : full.height;
    if (!fs::exists(v.file))
      throw InputError(v.file, fmt::format("image '{}' of the COLMAP model is missing", im.name));
    // Every header now, so that a wrong or unreadable file stops the stage
    // before it writes anything, not at the view's first use.
    const ImageInfo info = read_image_info(v.file);
    check_file_size(v, info.width, info.height);
    scene->views_.push_back(std::move(v));
  }
  std::sort(scene->views_.begin(), scene->views_.end(),
            [](const View& a, const View& b) { return a.name < b.name; });
  if (capped > 0)
    spdlog::info(
        "{} of {} views are wider than {} px (up to {}): scaled down to that width, as "
        "the 3DGS reference scales large photos (--max-width 0 keeps them)",
        capped, scene->views_.size(), options.max_width, widest);

  for (const auto& [id, p] : model.points3d) {
    scene->points_.push_back(p.xyz);
    scene->point_colors_.emplace_back(p.rgb[0] / 255.f, p.rgb[1] / 255.f, p.rgb[2] / 255.f);
  }
  scene->extent_ = scene_extent(scene->cameras());
  if (!options.poses.empty()) scene->replace_poses(options.poses);
  Scene* raw = scene.get();
  scene->cache_ = std::make_unique<ViewCache>([raw](size_t i) { return raw->load_view(i); },
                                              options.cache_bytes);
  return scene;
}

void Scene::replace_poses(const fs::path& file) {
  for (const NamedPose& p : read_pose_file(file)) {
    const int v = find_view(p.name);
    if (v < 0) throw InputError(file, fmt::format("image '{}' is not in the scene", p.name));
    views_[size_t(v)].camera.R = p.R;
    views_[size_t(v)].camera.t = p.t;
  }
}

PackedImageRGB Scene::load_view(size_t i) const {
  const View& v = views_.at(i);
  PackedImageRGB image = read_packed_image_rgb(v.file);
  check_file_size(v, image.width(), image.height());
  if (image.width() == v.camera.width && image.height() == v.camera.height) return image;
  return PackedImageRGB::pack(resize_area(image.unpack(), v.camera.width, v.camera.height));
}

std::vector<Camera> Scene::cameras() const {
  std::vector<Camera> cams;
  for (const View& v : views_) cams.push_back(v.camera);
  return cams;
}

int Scene::find_view(const std::string& name) const {
  for (size_t i = 0; i < views_.size(); ++i)
    if (views_[i].name == name) return int(i);
  return -1;
}

}  // namespace splat
