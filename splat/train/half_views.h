#pragma once
// Half views for the late phase (the fast recipe): from `from_iteration` on,
// each training iteration renders and compares one half of its view instead
// of the whole, so the rasterizer, the loss and sparse Adam touch about half
// the pixels and the Gaussians of a full view. The halves split the view's
// longer side; a view shows its two halves on alternate epochs, so every
// pixel is trained on as often as every other. The render of a half is the
// same camera with its principal point moved (Camera::cropped), so each
// pixel's colour, and, with the loss weighted by the half's share of the
// view (half_share), its gradient, are those of the full view's render
// (SSIM's windows at the cut aside); densification reads the 2D means'
// gradients in the whole view's units (DensificationStats::add).
// Off in the reference recipe; test views are always rendered whole.

#include <cstddef>

#include "splat/image.h"

namespace splat {

struct HalfViewOptions {
  int from_iteration = 0;  // 0: never (the paper)

  bool applies(int iteration) const { return from_iteration > 0 && iteration >= from_iteration; }
  void Check() const;  // throws std::invalid_argument with a one-line message
};

// The half of a width x height view that `iteration` trains on. Epochs are
// counted as `training_views` iterations each; `view` is the view's index,
// so that half of the views start on each side.
PixelRect training_half(int width, int height, size_t view, int iteration, size_t training_views);

// The share of a width x height view's pixels that `half` holds: the weight
// of its mean loss, so that each pixel's gradient is the full view's.
double half_share(const PixelRect& half, int width, int height);

}  // namespace splat
