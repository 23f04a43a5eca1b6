#include "splat/photo_cameras.h"

#include "splat/camera_distortion.h"

namespace splat {
namespace fs = std::filesystem;

namespace {

std::map<std::string, ColmapCamera> cameras_by_image(const fs::path& model_dir) {
  const ColmapModel model = read_colmap_model(model_dir);
  std::map<std::string, ColmapCamera> out;
  for (const auto& [id, image] : model.images) out[image.name] = model.cameras.at(image.camera_id);
  return out;
}

}  // namespace

PhotoCameras PhotoCameras::load(const fs::path& scene) {
  PhotoCameras c;
  if (!fs::is_directory(scene / kPhotoCamerasDir)) return c;
  c.photo_ = cameras_by_image(scene / kPhotoCamerasDir);
  c.view_ = cameras_by_image(scene / "sparse" / "0");
  return c;
}

std::optional<PhotoCameras::Sampling> PhotoCameras::sampling(const std::string& image_name,
                                                             int render_width,
                                                             int render_height) const {
  const auto photo = photo_.find(image_name);
  const auto view = view_.find(image_name);
  if (photo == photo_.end() || view == view_.end()) return std::nullopt;
  return Sampling{int(photo->second.width), int(photo->second.height),
                  photo_pixel_sources(photo->second, view->second, render_width, render_height)};
}

}  // namespace splat
