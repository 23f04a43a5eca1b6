#include "splat/sfm/undistort_id_maps.h"

#include <algorithm>
#include <map>
#include <stdexcept>

#include "splat/camera_distortion.h"
#include "splat/error.h"
#include "splat/id_maps.h"

namespace splat {
namespace fs = std::filesystem;

size_t undistort_id_map_folder(const fs::path& from, const fs::path& to,
                               const ColmapModel& distorted, const ColmapModel& undistorted) {
  std::map<std::string, const ColmapImage*> before;
  for (const auto& [id, image] : distorted.images) before[image.name] = &image;
  fs::remove_all(to);
  fs::create_directories(to);
  for (const auto& f : fs::directory_iterator(from))
    if (f.path().extension() != ".png")
      fs::create_symlink(fs::absolute(f.path()), to / f.path().filename());
  size_t written = 0;
  for (const auto& [id, image] : undistorted.images) {
    const fs::path stem = fs::path(image.name).stem();
    const fs::path file = from / (stem.string() + ".png");
    const auto it = before.find(image.name);
    if (!fs::exists(file) || it == before.end()) continue;
    IdMap map;
    try {
      map = undistort_id_map(read_id_map(file), distorted.cameras.at(it->second->camera_id),
                             undistorted.cameras.at(image.camera_id));
    } catch (const std::invalid_argument& e) {
      throw InputError(file, e.what());
    }
    const bool wide =
        std::any_of(map.ids.begin(), map.ids.end(), [](uint16_t v) { return v > 255; });
    write_id_map(to / (stem.string() + ".png"), map, wide ? 16 : 8);
    ++written;
  }
  return written;
}

}  // namespace splat
