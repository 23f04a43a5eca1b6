#pragma once
// Mask metrics of the LERF-Mask protocol (docs/evaluation.md), as
// the public reference script computes them: IoU and boundary IoU (Cheng et
// al. 2021, dilation ratio 0.02) of binary masks.

#include <cstdint>
#include <filesystem>
#include <vector>

#include "splat/image.h"

namespace eval {

struct Mask {
  int width = 0, height = 0;
  std::vector<uint8_t> on;  // W * H, 0 or 1
  Mask() = default;
  Mask(int w, int h) : width(w), height(h), on(size_t(w) * h, 0) {}
  size_t count() const;
};

// Reads an image as 8-bit grey the way Pillow's convert('L') does: RGB
// through ITU-R 601 luma in integer arithmetic, 16-bit grey clipped to 255.
// Throws splat::InputError naming the file.
splat::IdMap read_grey_like_pillow(const std::filesystem::path& file);

// Reads a mask as the reference does: 8-bit grey (RGB through Pillow's
// ITU-R 601 luma, 16-bit grey clipped to 255 as Pillow converts it), then
// value > 128. Throws splat::InputError naming the file.
Mask read_mask(const std::filesystem::path& file);

// Nearest-neighbour resize with Pillow's sampling rule.
Mask resize_mask_nearest(const Mask& mask, int width, int height);

// |gt AND pred| / |gt OR pred|; NaN when the union is empty (the reference
// propagates it). pred must have gt's size.
double mask_iou(const Mask& gt, const Mask& pred);

// The dilation width of boundary IoU: round(ratio * diagonal), Python's
// rounding (ties to even), at least 1.
int boundary_width(int width, int height, double dilation_ratio = 0.02);

// m AND NOT erode(m) with a (2d+1) x (2d+1) square, pixels outside the image
// counting as 0.
Mask mask_boundary(const Mask& m, int d);

// IoU of the boundaries of gt and pred.
double boundary_iou(const Mask& gt, const Mask& pred, double dilation_ratio = 0.02);

}  // namespace eval
