#include "eval/metrics/photo_geometry.h"

#include <spdlog/spdlog.h>

#include <utility>
#include <vector>

#include "splat/sfm/sfm_run.h"
#include "splat/sfm/undistort_id_maps.h"

namespace eval {
namespace fs = std::filesystem;

namespace {

std::map<std::string, splat::ColmapCamera> cameras_by_image(const fs::path& model_dir) {
  const splat::ColmapModel model = splat::read_colmap_model(model_dir);
  std::map<std::string, splat::ColmapCamera> out;
  for (const auto& [id, image] : model.images) out[image.name] = model.cameras.at(image.camera_id);
  return out;
}

}  // namespace

PhotoGeometry::PhotoGeometry(const fs::path& scene) {
  const fs::path photo = scene / splat::kPhotoCamerasDir;
  if (!fs::is_directory(photo)) return;
  photo_ = cameras_by_image(photo);
  undistorted_ = cameras_by_image(scene / "sparse" / "0");
  spdlog::info("{}: renders are resampled into the photos' geometry before scoring",
               photo.string());
}

ObjectMasks PhotoGeometry::to_photo(const std::string& view_name, ObjectMasks masks) const {
  const auto photo = photo_.find(view_name);
  const auto undistorted = undistorted_.find(view_name);
  if (photo == photo_.end() || undistorted == undistorted_.end() || masks.empty()) return masks;
  // Every mask of a view has the render's size; the sources are found once.
  std::pair<int, int> size{-1, -1};
  std::vector<int64_t> sources;
  for (auto& [id, mask] : masks) {
    if (size != std::pair{mask.width, mask.height}) {
      size = {mask.width, mask.height};
      sources =
          splat::photo_pixel_sources(photo->second, undistorted->second, mask.width, mask.height);
    }
    Mask moved(int(photo->second.width), int(photo->second.height));
    for (size_t i = 0; i < sources.size(); ++i)
      if (sources[i] >= 0) moved.on[i] = mask.on[size_t(sources[i])];
    mask = std::move(moved);
  }
  return masks;
}

}  // namespace eval
