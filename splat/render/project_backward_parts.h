#pragma once
// What the two backward passes of the projection (project_backward.cc, a
// batch of Gaussians at a time; project_backward_one.cc, one at a time)
// both write for each Gaussian, written once. Internal to splat/render/.

#include <algorithm>
#include <cstddef>

#include "splat/gaussians.h"
#include "splat/render/project.h"
#include "splat/render/render_types.h"

namespace splat::project_backward_parts {

// Zeroes every gradient of Gaussian i (a culled one).
inline void zero_gradients(GaussianGradients& g, size_t i) {
  std::fill_n(&g.means[3 * i], 3, 0.f);
  std::fill_n(&g.sh_dc[3 * i], 3, 0.f);
  std::fill_n(&g.sh_rest[kShRestFloats * i], kShRestFloats, 0.f);
  g.opacity_logits[i] = g.instance_opacity_logits[i] = 0.f;
  std::fill_n(&g.log_scales[3 * i], 3, 0.f);
  std::fill_n(&g.rotations[4 * i], 4, 0.f);
  std::fill_n(&g.mean2d_ndc[2 * i], 2, 0.f);
  g.visible[i] = 0;
}

// From the activated opacities to their logits.
inline void backward_opacities(const ProjectedGaussians& p, const ProjectedGradients& pg, size_t i,
                               GaussianGradients& g) {
  const float sigma = p.opacity[i];
  g.opacity_logits[i] = pg.opacity[i] * sigma * (1 - sigma);
  const float sigma_star = p.instance_opacity[i];
  g.instance_opacity_logits[i] = pg.instance_opacity[i] * sigma_star * (1 - sigma_star);
}

// Marks visible Gaussian i and writes its densification statistic: the 2D
// mean's gradient in normalised device units.
inline void mark_visible(const ProjectedGradients& pg, size_t i, float half_w, float half_h,
                         GaussianGradients& g) {
  g.visible[i] = 1;
  g.mean2d_ndc[2 * i] = pg.mean2d[2 * i] * half_w;
  g.mean2d_ndc[2 * i + 1] = pg.mean2d[2 * i + 1] * half_h;
}

}  // namespace splat::project_backward_parts
