#include "splat/masks/mask_import.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <stdexcept>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/png_indexed.h"

namespace splat {
namespace fs = std::filesystem;

void MaskImportOptions::Check() const {
  if (!fs::is_directory(masks)) throw InputError(masks, "no such folder of masks");
  if (!fs::is_directory(images)) throw InputError(images, "no such folder of images");
  if (!pattern.empty() && layout == Layout::kPerFrame)
    throw std::invalid_argument("--pattern applies to per-object masks only");
  if (!pattern.empty()) MaskPattern{pattern};  // throws on a bad pattern
}

namespace {

// The scene's images by stem (sorted), and their files.
std::map<std::string, fs::path> images_by_stem(const fs::path& images) {
  std::map<std::string, fs::path> by_stem;
  for (const auto& entry : fs::directory_iterator(images)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file() || name.empty() || name[0] == '.') continue;
    if (!by_stem.emplace(entry.path().stem().string(), entry.path()).second)
      throw InputError(entry.path(), "another image in the folder has the same stem");
  }
  if (by_stem.empty()) throw InputError(images, "holds no images");
  return by_stem;
}

IdMap empty_map_for(const fs::path& image) {
  const ImageInfo info = read_image_info(image);
  return IdMap(info.width, info.height);
}

int bits_for(const IdMap& map) {
  return *std::max_element(map.ids.begin(), map.ids.end()) > 255 ? 16 : 8;
}

// A binary mask: inside where a colour channel (alpha is ignored) holds more
// than half the file's largest value.
struct BinaryMask {
  int width = 0, height = 0;
  std::vector<uint8_t> inside;
  size_t area = 0;
};

BinaryMask read_binary_mask(const fs::path& file) {
  const IntegerImage image = read_integer_image(file);
  const int colour =
      image.channels == 2 || image.channels == 4 ? image.channels - 1 : image.channels;
  uint16_t largest = 0;
  for (size_t p = 0, n = size_t(image.width) * image.height; p < n; ++p)
    for (int c = 0; c < colour; ++c)
      largest = std::max(largest, image.samples[p * image.channels + c]);
  BinaryMask mask{image.width, image.height,
                  std::vector<uint8_t>(size_t(image.width) * image.height)};
  if (largest == 0) return mask;
  for (size_t p = 0; p < mask.inside.size(); ++p) {
    bool in = false;
    for (int c = 0; c < colour; ++c) in |= 2u * image.samples[p * image.channels + c] > largest;
    mask.inside[p] = in;
    mask.area += in;
  }
  return mask;
}

// One frame's map from its objects' masks, the smallest mask on top
// (mask_import.h). ids[i] is the ID of files[i].
IdMap compose_frame(const std::vector<std::pair<int, fs::path>>& masks, size_t& overlap) {
  std::vector<BinaryMask> read;
  for (const auto& [id, file] : masks) {
    read.push_back(read_binary_mask(file));
    if (read.back().width != read.front().width || read.back().height != read.front().height)
      throw InputError(
          file, fmt::format("is {}x{}, another mask of its frame ({}) is {}x{}", read.back().width,
                            read.back().height, masks.front().second.filename().string(),
                            read.front().width, read.front().height));
  }
  std::vector<size_t> order(masks.size());
  std::iota(order.begin(), order.end(), 0);
  // Painted last wins: largest first, and of equal areas the higher ID first.
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (read[a].area != read[b].area) return read[a].area > read[b].area;
    return masks[a].first > masks[b].first;
  });
  IdMap map(read.front().width, read.front().height);
  for (size_t i : order)
    for (size_t p = 0; p < map.ids.size(); ++p) {
      if (!read[i].inside[p]) continue;
      overlap += map.ids[p] != 0;
      map.ids[p] = uint16_t(masks[i].first);
    }
  return map;
}

void write_names(const fs::path& out, const std::vector<std::string>& names) {
  nlohmann::json objects = nlohmann::json::array();
  for (size_t i = 0; i < names.size(); ++i) objects.push_back({{"id", i + 1}, {"name", names[i]}});
  write_text_atomically(out / "objects.json", objects.dump(2) + "\n");
}

MaskImportResult import_per_object(const MaskImportOptions& o, const std::string& pattern_text,
                                   const std::map<std::string, fs::path>& images,
                                   const std::vector<std::string>& stems, const fs::path& out) {
  MaskImportResult result;
  result.layout = MaskLayout::kPerObject;
  result.pattern = pattern_text;
  const MaskPattern pattern(pattern_text);
  const auto files =
      find_object_masks(o.masks, pattern, stems, o.frame_naming, result.skipped_files);
  if (files.empty())
    throw InputError(o.masks, "no mask file matches --pattern '" + pattern_text +
                                  "' with a frame of " + o.images.string());
  for (const auto& f : files) result.names.push_back(f.object);
  std::sort(result.names.begin(), result.names.end());
  result.names.erase(std::unique(result.names.begin(), result.names.end()), result.names.end());
  if (result.names.size() > 65535)
    throw InputError(o.masks,
                     fmt::format("{} objects: ID maps hold at most 65535", result.names.size()));
  result.max_id = int(result.names.size());
  result.bits = result.max_id > 255 ? 16 : 8;

  std::map<std::string, std::vector<std::pair<int, fs::path>>> by_frame;
  std::map<std::pair<std::string, std::string>, fs::path> seen;
  for (const auto& f : files) {
    const auto [it, fresh] = seen.emplace(std::make_pair(f.object, f.frame), f.path);
    if (!fresh)
      throw InputError(f.path, "a second mask of object '" + f.object + "' in frame " + f.frame +
                                   " (the first: " + it->second.filename().string() + ")");
    const int id = int(std::lower_bound(result.names.begin(), result.names.end(), f.object) -
                       result.names.begin()) +
                   1;
    by_frame[f.frame].emplace_back(id, f.path);
  }

  std::atomic<size_t> overlap{0}, empty{0};
  tbb::parallel_for(size_t(0), stems.size(), [&](size_t i) {
    const std::string& stem = stems[i];
    const auto masks = by_frame.find(stem);
    if (masks == by_frame.end()) {  // no object in view: background only
      ++empty;
      write_id_map(out / (stem + ".png"), empty_map_for(images.at(stem)), result.bits);
      return;
    }
    size_t frame_overlap = 0;
    write_id_map(out / (stem + ".png"), compose_frame(masks->second, frame_overlap), result.bits);
    overlap += frame_overlap;
  });
  result.frames = stems.size();
  result.frames_without_masks = empty;
  result.overlap_pixels = overlap;
  write_names(out, result.names);
  return result;
}

// One per-frame map: palette indices or grey values as they are, RGB colours
// through `colours` (the IDs given so far, in order of first appearance).
IdMap read_instance_map(const fs::path& file, std::map<uint64_t, int>& colours, bool& rgb) {
  rgb = false;
  if (auto indexed = read_png_palette_indices(file)) return std::move(*indexed);
  const IntegerImage image = read_integer_image(file);
  IdMap map(image.width, image.height);
  const size_t n = map.ids.size();
  if (image.channels <= 2) {  // grey, perhaps with alpha
    for (size_t p = 0; p < n; ++p) map.ids[p] = image.samples[p * image.channels];
    return map;
  }
  rgb = true;
  for (size_t p = 0; p < n; ++p) {
    const uint16_t* s = &image.samples[p * image.channels];
    const uint64_t key = uint64_t(s[0]) << 32 | uint64_t(s[1]) << 16 | s[2];
    if (key == 0) continue;
    auto it = colours.find(key);
    if (it == colours.end()) {
      if (colours.size() >= 65535)
        throw InputError(file, "more than 65535 colours over the frames: not an instance map");
      it = colours.emplace(key, int(colours.size()) + 1).first;
    }
    map.ids[p] = uint16_t(it->second);
  }
  return map;
}

// The per-frame map of each image: <stem>.png, or with FrameNaming::kIndex
// <index>.png with the index written with any number of leading zeros.
std::map<std::string, fs::path> instance_map_files(const MaskImportOptions& o,
                                                   const std::vector<std::string>& stems) {
  std::map<std::string, fs::path> files;
  for (const auto& entry : fs::directory_iterator(o.masks)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".png") continue;
    const std::string token = entry.path().stem().string();
    const auto stem = o.frame_naming == FrameNaming::kIndex
                          ? match_frame(token, stems, FrameNaming::kIndex)
                          : std::optional<std::string>(token);
    if (!stem) continue;
    const auto [it, fresh] = files.emplace(*stem, entry.path());
    if (!fresh)
      throw InputError(entry.path(), "names the same frame as " + it->second.filename().string());
  }
  return files;
}

MaskImportResult import_per_frame(const MaskImportOptions& o,
                                  const std::map<std::string, fs::path>& images,
                                  const std::vector<std::string>& stems, const fs::path& out) {
  MaskImportResult result;
  result.layout = MaskLayout::kPerFrame;
  std::map<uint64_t, int> colours;
  bool any_colour = false;
  const std::map<std::string, fs::path> files = instance_map_files(o, stems);
  for (const auto& [stem, image] : images) {
    const auto found = files.find(stem);
    const fs::path file = found == files.end() ? fs::path() : found->second;
    IdMap map;
    if (!file.empty()) {
      bool rgb = false;
      map = read_instance_map(file, colours, rgb);
      any_colour |= rgb;
    } else {
      map = empty_map_for(image);
      ++result.frames_without_masks;
    }
    const int bits = bits_for(map);
    result.bits = std::max(result.bits, bits);
    result.max_id = std::max(result.max_id, int(*std::max_element(map.ids.begin(), map.ids.end())));
    write_id_map(out / (stem + ".png"), map, bits);
    ++result.frames;
  }
  if (any_colour) {
    // Names from the colours: "#rrggbb" (16-bit colours by their high bytes).
    result.names.resize(colours.size());
    const bool wide = std::any_of(colours.begin(), colours.end(), [](const auto& c) {
      return (c.first >> 40) > 0xff || ((c.first >> 16) & 0xffff) > 0xff ||
             (c.first & 0xffff) > 0xff;
    });
    for (const auto& [key, id] : colours) {
      const int shift = wide ? 8 : 0;
      result.names[id - 1] = fmt::format("#{:02x}{:02x}{:02x}", (key >> 32 & 0xffff) >> shift,
                                         (key >> 16 & 0xffff) >> shift, (key & 0xffff) >> shift);
    }
    write_names(out, result.names);
  } else if (fs::is_regular_file(o.masks / "objects.json")) {
    write_text_atomically(out / "objects.json", read_text_file(o.masks / "objects.json"));
  }
  return result;
}

}  // namespace

MaskImportResult import_masks(const MaskImportOptions& o, const fs::path& out) {
  o.Check();
  const std::map<std::string, fs::path> images = images_by_stem(o.images);
  std::vector<std::string> stems;
  for (const auto& [stem, file] : images) stems.push_back(stem);

  MaskImportOptions::Layout layout = o.layout;
  std::string pattern = o.pattern;
  if (!pattern.empty()) layout = MaskImportOptions::Layout::kPerObject;
  if (layout == MaskImportOptions::Layout::kAuto ||
      (pattern.empty() && layout == MaskImportOptions::Layout::kPerObject)) {
    const DetectedMasks detected = detect_mask_layout(o.masks, stems, o.frame_naming);
    if (layout == MaskImportOptions::Layout::kPerObject && detected.layout == MaskLayout::kPerFrame)
      throw InputError(o.masks,
                       "its files are named after the images, one per frame: give "
                       "--pattern for per-object masks");
    layout = detected.layout == MaskLayout::kPerFrame ? MaskImportOptions::Layout::kPerFrame
                                                      : MaskImportOptions::Layout::kPerObject;
    pattern = detected.pattern;
  }
  if (layout == MaskImportOptions::Layout::kPerFrame)
    return import_per_frame(o, images, stems, out);
  return import_per_object(o, pattern, images, stems, out);
}

}  // namespace splat
