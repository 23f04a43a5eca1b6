#pragma once
// The slow, obvious renderer the fast one is tested against: double
// precision, every pixel against every Gaussian, a depth sort per pixel, no
// tiles except the reference's rule that a Gaussian only reaches the tiles of
// its 3-sigma rectangle. Written straight from the spec and the paper.

#include <vector>

#include "splat/camera.h"
#include "splat/gaussians.h"
#include "splat/render/render_types.h"

namespace splat::reference {

// The model's parameters in double, so finite differences can be taken.
struct Params {
  std::vector<double> means, sh_dc, sh_rest, opacity_logits, log_scales, rotations,
      instance_opacity_logits;
  std::vector<int> labels;
  bool has_instance_opacity = false;
  // Optional offsets added to the projected 2D means (2N), for taking
  // derivatives w.r.t. the 2D mean itself.
  std::vector<double> mean2d_offset;
  size_t size() const { return opacity_logits.size(); }
  static Params from(const GaussianModel& m);
  // The parameter arrays in a fixed order, for looping over all of them.
  std::vector<std::vector<double>*> arrays();
};

struct Output {
  std::vector<double> color, alpha, depth, instance_maps;
  std::vector<int> contributors, instance_label, baseline_label;
  std::vector<int> map_labels;
};

Output render(const Params& p, const Camera& camera, const RenderSettings& settings);

// The occupancy maps S_j with the transmittance, ordering and termination of
// `frozen` held fixed and alpha*_i evaluated with `p`: the function whose
// derivative the paper's backward path ("the gradient stops at T_i") is.
std::vector<double> instance_maps_frozen_T(const Params& frozen, const Params& p,
                                           const Camera& camera, const RenderSettings& settings);

}  // namespace splat::reference
