#include "eval/metrics/photo_geometry.h"

#include <spdlog/spdlog.h>

#include <optional>
#include <utility>

#include "splat/photo_cameras.h"

namespace eval {
namespace fs = std::filesystem;

PhotoGeometry::PhotoGeometry(const fs::path& scene) : cameras_(splat::PhotoCameras::load(scene)) {
  if (active())
    spdlog::info("{}: renders are resampled into the photos' geometry before scoring",
                 (scene / splat::kPhotoCamerasDir).string());
}

ObjectMasks PhotoGeometry::to_photo(const std::string& view_name, ObjectMasks masks) const {
  if (!active()) return masks;
  // Every mask of a view has the render's size; the sampling is found once.
  std::optional<splat::PhotoCameras::Sampling> sampling;
  std::pair<int, int> sampled_size{-1, -1};
  for (auto& [id, mask] : masks) {
    if (sampled_size != std::pair{mask.width, mask.height}) {
      sampled_size = {mask.width, mask.height};
      sampling = cameras_.sampling(view_name, mask.width, mask.height);
    }
    if (!sampling) return masks;  // not a view of both models
    mask.on = sampling->gather<uint8_t>(mask.on);
    mask.width = sampling->width, mask.height = sampling->height;
  }
  return masks;
}

}  // namespace eval
