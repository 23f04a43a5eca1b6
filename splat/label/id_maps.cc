#include "splat/label/id_maps.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "splat/error.h"

namespace splat {
namespace fs = std::filesystem;

fs::path find_id_map(const fs::path& folder, const std::string& view_name) {
  const fs::path file = folder / (fs::path(view_name).stem().string() + ".png");
  return fs::is_regular_file(file) ? file : fs::path();
}

fs::path require_id_map(const fs::path& folder, const std::string& view_name,
                        const std::string& hint) {
  const fs::path file = find_id_map(folder, view_name);
  if (file.empty())
    throw InputError(folder / (fs::path(view_name).stem().string() + ".png"),
                     "no ID map for training view " + view_name + (hint.empty() ? "" : " " + hint));
  return file;
}

std::vector<int32_t> ids_in_map(const IdMap& map) {
  std::vector<uint8_t> seen(65536, 0);
  for (uint16_t id : map.ids) seen[id] = 1;
  std::vector<int32_t> ids;
  for (int32_t id = 0; id < 65536; ++id)
    if (seen[id]) ids.push_back(id);
  return ids;
}

namespace {
// Source index of every destination index, as Pillow's nearest filter picks it.
std::vector<int> nearest_sources(int src, int dst) {
  std::vector<int> index(static_cast<size_t>(dst));
  const double scale = double(src) / dst;
  double acc = 0.5 * scale;
  for (int x = 0; x < dst; ++x, acc += scale) index[x] = std::min(int(std::floor(acc)), src - 1);
  return index;
}
}  // namespace

IdMap resize_id_map_nearest(const IdMap& map, int width, int height) {
  if (map.width == width && map.height == height) return map;
  const std::vector<int> xs = nearest_sources(map.width, width);
  const std::vector<int> ys = nearest_sources(map.height, height);
  IdMap out(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) out.at(x, y) = map.at(xs[x], ys[y]);
  return out;
}

void check_id_map_aspect(const fs::path& file, const IdMap& map, int width, int height) {
  // Same aspect ratio up to rounding: a map of round(W/s) x round(H/s) has
  // |map_h * W - map_w * H| <= (W + H) / 2 (and likewise when s < 1).
  const double cross = std::abs(double(map.height) * width - double(map.width) * height);
  const double slack = 0.5 * std::max(width + height, map.width + map.height) + 1e-9;
  if (cross > slack)
    throw InputError(file, fmt::format("ID map is {}x{}, not the aspect ratio of its view ({}x{})",
                                       map.width, map.height, width, height));
}

IdMap read_id_map_for_view(const fs::path& file, int width, int height) {
  const IdMap map = read_id_map(file);
  check_id_map_aspect(file, map, width, height);
  return resize_id_map_nearest(map, width, height);
}

}  // namespace splat
