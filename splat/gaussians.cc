#include "splat/gaussians.h"

namespace splat {

void GaussianModel::resize(size_t n) {
  const size_t old = size();
  means.resize(3 * n, 0.f);
  sh_dc.resize(3 * n, 0.f);
  sh_rest.resize(kShRestFloats * n, 0.f);
  opacity_logits.resize(n, 0.f);
  log_scales.resize(3 * n, 0.f);
  rotations.resize(4 * n, 0.f);
  for (size_t i = old; i < n; ++i) rotations[4 * i] = 1.f;
  instance_opacity_logits.resize(n, 0.f);
  labels.resize(n, 0);
}

}  // namespace splat
