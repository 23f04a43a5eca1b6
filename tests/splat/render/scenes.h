#pragma once
// Random Gaussian scenes for the renderer tests, with the edge cases the
// rasterizer issue names: Gaussians behind the camera, straddling the image
// border, with near-zero scales, and a view with no Gaussians.

#include <random>

#include "splat/camera.h"
#include "splat/gaussians.h"

namespace splat::testing_scenes {

inline Camera test_camera(int w = 64, int h = 48) {
  return Camera::look_at({0.3, -0.2, -4}, {0, 0, 0}, Eigen::Vector3d::UnitY(), w, h, 0.9 * w,
                         0.95 * w);
}

// n Gaussians in front of test_camera, labels 0..labels.
inline GaussianModel random_scene(size_t n, unsigned seed, int labels = 4, bool edge_cases = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  std::normal_distribution<float> g;
  GaussianModel m;
  m.resize(n);
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      m.means[3 * i + k] = 1.2f * u(rng);
      m.log_scales[3 * i + k] = std::log(0.05f + 0.15f * (0.5f + 0.5f * u(rng)));
      m.sh_dc[3 * i + k] = 1.2f * g(rng);
    }
    for (int k = 0; k < 45; ++k) m.sh_rest[45 * i + k] = 0.2f * g(rng);
    for (int k = 0; k < 4; ++k) m.rotations[4 * i + k] = g(rng);
    m.opacity_logits[i] = 1.0f + 1.5f * g(rng);
    m.instance_opacity_logits[i] = 1.5f * g(rng);
    m.labels[i] = int32_t(i % (labels + 1));
  }
  if (edge_cases && n >= 4) {
    m.means[0] = 0.2f, m.means[1] = 0.f, m.means[2] = -4.5f;      // behind the camera
    m.means[3] = 1.9f, m.means[4] = 0.2f, m.means[5] = 0.f;       // across the right border
    m.log_scales[6] = m.log_scales[7] = m.log_scales[8] = -12.f;  // degenerate (near-zero) scale
    m.means[9] = -0.1f, m.means[10] = 0.f, m.means[11] = -3.85f;  // close to the near plane
  }
  m.has_labels = m.has_instance_opacity = true;
  return m;
}

}  // namespace splat::testing_scenes
