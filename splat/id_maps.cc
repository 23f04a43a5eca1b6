#include "splat/id_maps.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "splat/error.h"
#include "splat/image_codec.h"
#include "splat/png_indexed.h"

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

namespace {

void check_aspect(const fs::path& file, int map_width, int map_height, int width, int height) {
  // Same aspect ratio up to rounding: a map of round(W/s) x round(H/s) has
  // |map_h * W - map_w * H| <= (W + H) / 2 (and likewise when s < 1).
  const double cross = std::abs(double(map_height) * width - double(map_width) * height);
  const double slack = 0.5 * std::max(width + height, map_width + map_height) + 1e-9;
  if (cross > slack)
    throw InputError(file, fmt::format("ID map is {}x{}, not the aspect ratio of its view ({}x{})",
                                       map_width, map_height, width, height));
}

}  // namespace

void check_id_map_aspect(const fs::path& file, const IdMap& map, int width, int height) {
  check_aspect(file, map.width, map.height, width, height);
}

void check_id_map_header(const fs::path& file, int width, int height) {
  const ImageInfo info = read_image_info(file);
  check_aspect(file, info.width, info.height, width, height);
}

IdMap read_id_map_for_view(const fs::path& file, int width, int height) {
  const IdMap map = read_id_map(file);
  check_id_map_aspect(file, map, width, height);
  return resize_id_map_nearest(map, width, height);
}

IdMap read_id_map(const fs::path& file) {
  if (auto indexed = read_png_palette_indices(file)) return std::move(*indexed);
  IntegerImage image = read_integer_image(file);
  if (image.channels != 1)
    throw InputError(file,
                     fmt::format("ID map must be single-channel, has {} channels", image.channels));
  IdMap map;
  map.width = image.width;
  map.height = image.height;
  map.ids = std::move(image.samples);
  return map;
}

IntegerImage read_integer_image(const fs::path& file) {
  ImageFileReader in(file);
  const ImageFileSpec& spec = in.spec();
  IntegerImage image;
  image.width = spec.width;
  image.height = spec.height;
  image.channels = spec.channels;
  // Read in the file's own integer type: converting 8 to 16 bit through
  // OpenImageIO would rescale the values (255 -> 65535).
  if (spec.type == SampleType::uint8) {
    const auto px = in.read_all<uint8_t>(SampleType::uint8);
    image.samples.assign(px.begin(), px.end());
  } else if (spec.type == SampleType::uint16) {
    image.samples = in.read_all<uint16_t>(SampleType::uint16);
  } else {
    throw InputError(
        file, fmt::format("must hold 8- or 16-bit unsigned integers, holds {}", spec.type_name));
  }
  return image;
}

void write_id_map(const fs::path& file, const IdMap& map, int bits) {
  if (bits == 16) {
    write_image_file(file, {map.width, map.height, 1, SampleType::uint16}, SampleType::uint16,
                     map.ids.data());
    return;
  }
  if (bits != 8) throw std::invalid_argument("write_id_map: bits must be 8 or 16");
  std::vector<uint8_t> px(map.ids.size());
  for (size_t i = 0; i < px.size(); ++i) {
    if (map.ids[i] > 255)
      throw InputError(file, fmt::format("ID {} does not fit in an 8-bit ID map", map.ids[i]));
    px[i] = uint8_t(map.ids[i]);
  }
  write_image_file(file, {map.width, map.height, 1}, SampleType::uint8, px.data());
}

}  // namespace splat
