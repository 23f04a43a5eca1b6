#pragma once
// Colours for object labels, so that label maps and masks are images a
// person can look at. Label 0 (background) is black; other labels get
// distinct, stable colours (golden-ratio hue steps).

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "splat/image.h"

namespace splat {

std::array<float, 3> label_color(int32_t label);

// A label map (W * H) as an RGB image.
ImageRGB colorize_labels(std::span<const int32_t> labels, int width, int height);

// A label map (W * H) as two PNGs: <folder>/<stem>.png with the exact IDs
// (16 bit, for the evaluation) and <folder>_color/<stem>.png to look at.
void write_label_map(const std::filesystem::path& folder, const std::string& stem,
                     std::span<const int32_t> labels, int width, int height);

}  // namespace splat
