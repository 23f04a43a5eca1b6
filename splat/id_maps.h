#pragma once
// Per-view ID maps (SAM2 masks, ground-truth instance maps) as users bring
// them (docs/inputs.md): <folder>/<image stem>.png, single channel,
// 8 or 16 bit, the size of the image or another size with the same aspect
// ratio.

#include <filesystem>
#include <string>
#include <vector>

#include "splat/image.h"

namespace splat {

// ID maps are single-channel 8- or 16-bit PNGs (docs/inputs.md),
// or palette PNGs whose indices are the IDs (SAM2's video tools write those;
// see png_indexed.h). Anything with more than one channel, or not an integer
// type of 8/16 bits, is rejected with an InputError naming the file.
IdMap read_id_map(const std::filesystem::path& file);

// An image's samples as stored, for masks that are not yet ID maps (binary
// masks, colour-coded instance maps): 8- or 16-bit unsigned integers, any
// number of channels, interleaved. Palette PNGs come back as their RGB
// colours (read_png_palette_indices gives their indices). Throws InputError
// naming the file when it cannot be read or holds another sample type.
struct IntegerImage {
  int width = 0, height = 0, channels = 0;
  std::vector<uint16_t> samples;  // width * height * channels
};
IntegerImage read_integer_image(const std::filesystem::path& file);
// Writes a single-channel PNG atomically with bits = 8 or 16; 8 bits requires
// every ID <= 255.
void write_id_map(const std::filesystem::path& file, const IdMap& map, int bits);

// <folder>/<stem of view_name>.png; empty if there is no such file.
std::filesystem::path find_id_map(const std::filesystem::path& folder,
                                  const std::string& view_name);

// The ID map of a view, or an InputError naming the missing file ("no ID map
// for training view <name>", then `hint` if given).
std::filesystem::path require_id_map(const std::filesystem::path& folder,
                                     const std::string& view_name, const std::string& hint = "");

// The distinct IDs in a map, ascending (0, background, included if present).
std::vector<int32_t> ids_in_map(const IdMap& map);

// Nearest-neighbour resize with Pillow's sampling rule (source index
// floor(0.5 * s/d + x * s/d), accumulated in double), the rule the benchmark
// scripts use, so maps and masks line up with the evaluation's.
IdMap resize_id_map_nearest(const IdMap& map, int width, int height);

// Throws InputError naming the file if the map's aspect ratio differs from
// width x height beyond the rounding of one pixel.
void check_id_map_aspect(const std::filesystem::path& file, const IdMap& map, int width,
                         int height);

// The same from the file's header only, without decoding it: to stop a stage
// before it writes anything rather than at the map's first use.
void check_id_map_header(const std::filesystem::path& file, int width, int height);

// Reads an ID map and brings it to width x height. Throws InputError naming
// the file if it cannot be read or its aspect ratio differs from the view's
// (beyond the rounding of one pixel).
IdMap read_id_map_for_view(const std::filesystem::path& file, int width, int height);

}  // namespace splat
