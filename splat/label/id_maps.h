#pragma once
// Per-view ID maps (SAM2 masks, ground-truth instance maps) as users bring
// them (../shared/spec/inputs.md): <folder>/<image stem>.png, single channel,
// 8 or 16 bit, the size of the image or another size with the same aspect
// ratio.

#include <filesystem>
#include <string>

#include "splat/image.h"

namespace splat {

// <folder>/<stem of view_name>.png; empty if there is no such file.
std::filesystem::path find_id_map(const std::filesystem::path& folder,
                                  const std::string& view_name);

// Nearest-neighbour resize with Pillow's sampling rule (source index
// floor(0.5 * s/d + x * s/d), accumulated in double), the rule the benchmark
// scripts use, so maps and masks line up with the evaluation's.
IdMap resize_id_map_nearest(const IdMap& map, int width, int height);

// Throws InputError naming the file if the map's aspect ratio differs from
// width x height beyond the rounding of one pixel.
void check_id_map_aspect(const std::filesystem::path& file, const IdMap& map, int width,
                         int height);

// Reads an ID map and brings it to width x height. Throws InputError naming
// the file if it cannot be read or its aspect ratio differs from the view's
// (beyond the rounding of one pixel).
IdMap read_id_map_for_view(const std::filesystem::path& file, int width, int height);

}  // namespace splat
