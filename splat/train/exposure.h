#pragma once
// Exposure compensation: a learned colour transform per training view,
//
//   c' = A_v c + b_v    (A_v 3x3, b_v 3; identity at the start),
//
// applied to the rendered colour before the image loss, so that a view's
// auto-exposure and white balance are explained by its transform instead of
// by floaters and view-dependent colour in the model (NeRF in the Wild's
// appearance codes; the affine form of Kerbl et al. 2024, "A Hierarchical 3D
// Gaussian Representation", with its learning rate 0.01 -> 0.001). A weak L2
// pull towards the identity keeps views that the model already explains
// where they are. Off by default: the paper's recipe has none. Test views are
// rendered without a transform.

#include <array>
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <span>
#include <vector>

namespace splat {

struct ExposureOptions {
  bool enabled = false;
  float lr_init = 0.01f;  // decays exponentially to lr_final over the schedule
  float lr_final = 0.001f;
  float regularization = 1e-3f;  // weight of |A - I|^2 + |b|^2 in the loss

  void Check() const;  // throws std::invalid_argument with a one-line message
};

class ViewColorTransforms {
 public:
  ViewColorTransforms() = default;
  explicit ViewColorTransforms(size_t views);  // all identity
  size_t size() const { return params_.size(); }

  // out = A_v in + b_v for every RGB pixel (in and out may be the same).
  void apply(size_t view, std::span<const float> in, std::span<float> out) const;

  // Given dLoss/d(out) of apply(view, in, out) in grad, turns grad into
  // dLoss/d(in) and takes one Adam step on the view's transform (with the
  // regularisation's gradient added).
  void backward_and_step(size_t view, std::span<const float> in, std::span<float> grad, float lr,
                         float regularization);

  // A_v (row-major) then b_v.
  const std::array<float, 12>& params(size_t view) const { return params_[view]; }

  void save(std::ostream& out) const;
  void load(std::istream& in);  // throws std::runtime_error on a malformed stream

 private:
  std::vector<std::array<float, 12>> params_, m_, v_;
  std::vector<uint32_t> steps_;
};

// The colour transform that maps the render to the photo best (least
// squares) over the pixel columns [0, fit_width), applied to the columns
// [fit_width, width): NeRF in the Wild's evaluation of appearance-compensated
// models, fitting on a test view's left half and scoring its right half.
// Returns the PSNR of the right part.
double psnr_after_fit(std::span<const float> render, std::span<const float> photo, int width,
                      int height, int fit_width);

}  // namespace splat
