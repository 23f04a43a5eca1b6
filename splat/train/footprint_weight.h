#pragma once
// The footprint weight of `op2gs-learn --recipe robust-footprint` (an
// experiment, not the default): the paper's object loss, with each
// Gaussian's share of its gradient in a view (sigma*, position and shape)
// scaled by how well that view's mask agrees with the model over the
// Gaussian's footprint.
//
// Why: the generalized cross-entropy (PixelLoss::kGeneralized) is the
// cross-entropy with each pixel's gradient scaled by p^q, p the model's
// probability of the mask's value there, so a view whose mask missed part of
// an object, or leaked, is outvoted where the model disagrees with it. It
// decides per pixel, and the pixels of a Gaussian's tail past an object's
// outline are such a disagreeing minority too: its masks come out dilated
// (docs/benchmarks.md, "Stage two's own spread"). Here p^q is averaged over
// each Gaussian's footprint in the view and scales that Gaussian's gradient
// from the object loss. A Gaussian whose footprint the view's mask agrees
// with learns from all its pixels, its tail included, as under the
// cross-entropy; one inside a region the mask missed or leaked over is
// outvoted, as under the generalized loss.
//
// The footprint is the square of half-size floor(r / 3) pixels (one sigma)
// around the pixel of the Gaussian's projected mean, r its 3-sigma screen
// radius, cut to the image: a single pixel for Gaussians under 3 pixels.

#include <cstdint>
#include <span>
#include <vector>

#include "splat/image.h"
#include "splat/render/render_types.h"

namespace splat {

class FootprintWeights {
 public:
  // From the occupancy maps (one W * H plane per label, in the order of
  // `labels`) and the view's ID map: per plane, the summed-area table of
  // p^q, p = S_j where ids == labels[j], else 1 - S_j.
  void compute(std::span<const float> maps, const std::vector<int32_t>& labels, const IdMap& ids,
               double q);

  // The mean of p^q of plane j over the pixels [x0, x1) x [y0, y1).
  double box_mean(size_t plane, int x0, int y0, int x1, int y1) const;

  // The weight of a Gaussian of the plane's label projected to `mean2d`
  // (pixel coordinates) with screen radius `radius`: box_mean over its
  // footprint.
  double weight(size_t plane, float x, float y, int32_t radius) const;

  // Per Gaussian, its weight if it is visible and its label has a plane,
  // else 1. mean2d holds 2 values per Gaussian, as RenderOutput::mean2d.
  std::vector<float> per_gaussian(std::span<const int32_t> gaussian_labels,
                                  std::span<const uint8_t> visible, std::span<const float> mean2d,
                                  std::span<const int32_t> radii) const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<int32_t> labels_;
  std::vector<float> agreement_;  // p^q of the plane being summed
  // Per plane, cv::integral's (H + 1) x (W + 1) doubles: at y (W + 1) + x
  // the sum of p^q over [0, x) x [0, y).
  std::vector<std::vector<double>> sums_;
};

// into += weights[i] * from, Gaussian by Gaussian, over every parameter's
// gradient of the Gaussians visible in `into` (the others may be unwritten:
// BackwardSettings::zero_culled_gradients), and the camera's gradient.
void add_weighted(GaussianGradients& into, const GaussianGradients& from,
                  std::span<const float> weights);

}  // namespace splat
