#include "bench/bench_scenes.h"

#include <cmath>
#include <random>
#include <vector>

namespace bench {

using namespace splat;

Camera bench_camera(int width, int height) {
  return Camera::look_at({0, 0, 0}, {0, 0, 1}, Eigen::Vector3d::UnitY(), width, height, 0.8 * width,
                         0.8 * width);
}

GaussianModel bench_scene(size_t n, int width, int height) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> u(-1, 1);
  std::normal_distribution<float> g;
  const Camera cam = bench_camera(width, height);
  // Median world scale: 1.5 px at depth 5, for the density of 200k at 640x480.
  const double density = double(n) / (double(width) * height) / (200000.0 / (640.0 * 480.0));
  const float median_scale = float(1.5 * 5.0 / cam.fx / std::sqrt(density));
  GaussianModel m;
  m.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const float z = 2.f + 6.f * (0.5f + 0.5f * u(rng));
    m.means[3 * i] = u(rng) * z * float(cam.tan_half_fov_x());
    m.means[3 * i + 1] = u(rng) * z * float(cam.tan_half_fov_y());
    m.means[3 * i + 2] = z;
    for (int k = 0; k < 3; ++k) {
      m.log_scales[3 * i + k] = std::log(median_scale) + 0.7f * g(rng);
      m.sh_dc[3 * i + k] = g(rng);
    }
    for (int k = 0; k < 45; ++k) m.sh_rest[45 * i + k] = 0.1f * g(rng);
    for (int k = 0; k < 4; ++k) m.rotations[4 * i + k] = g(rng);
    m.opacity_logits[i] = 1.f + 2.f * g(rng);
    m.instance_opacity_logits[i] = m.opacity_logits[i];
    m.labels[i] = int32_t(i % 11);
  }
  m.has_labels = m.has_instance_opacity = true;
  return m;
}

// Flattened Gaussians on surfaces, as a trained model has them.
GaussianModel surface_scene(size_t n, int width, int height) {
  GaussianModel m = bench_scene(n, width, height);  // SH, labels, scale spread
  std::mt19937 rng(777);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<float> g;
  const Camera cam = bench_camera(width, height);
  struct Patch {
    Eigen::Vector3d center, t1, t2;
    double radius;
    bool sphere;
  };
  std::vector<Patch> patches;
  const double tx = cam.tan_half_fov_x(), ty = cam.tan_half_fov_y();
  patches.push_back({{0, 0, 9}, {1, 0, 0}, {0, 1, 0}, 10 * tx, false});  // back wall
  for (int k = 0; k < 16; ++k) {
    const double z = 2.5 + 5 * (0.5 + 0.5 * u(rng));
    Eigen::Vector3d c(u(rng) * z * tx, u(rng) * z * ty, z);
    const Eigen::Vector3d normal = Eigen::Vector3d(u(rng), u(rng), -1.5).normalized();
    const Eigen::Vector3d t1 = normal.cross(Eigen::Vector3d::UnitY()).normalized();
    patches.push_back({c, t1, normal.cross(t1), 0.3 + 0.5 * (0.5 + 0.5 * u(rng)), k % 3 == 0});
  }
  // Sampling spacing on each patch: sqrt(area / Gaussians on it).
  auto spacing = [&](size_t k) {
    const Patch& p = patches[k];
    const double area = p.sphere ? 4 * M_PI * p.radius * p.radius : 4 * p.radius * p.radius;
    const double count = k == 0 ? n / 5.0 : n * 0.8 / 16;
    return std::sqrt(area / count);
  };
  for (size_t i = 0; i < n; ++i) {
    const size_t patch = i % 5 == 0 ? 0 : 1 + i % 16;
    const Patch& p = patches[patch];
    Eigen::Vector3d pos, t1 = p.t1, t2 = p.t2;
    if (p.sphere) {
      const Eigen::Vector3d d = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      pos = p.center + p.radius * d;
      t1 = d.cross(Eigen::Vector3d::UnitY()).normalized();
      t2 = d.cross(t1);
    } else {
      pos = p.center + p.radius * (u(rng) * p.t1 + u(rng) * p.t2);
    }
    Eigen::Matrix3d R;
    R.col(0) = t1;
    R.col(1) = t2;
    R.col(2) = t1.cross(t2);
    const Eigen::Vector4d q = quaternion_from_rotation(R);
    for (int k = 0; k < 3; ++k) m.means[3 * i + k] = float(pos[k]);
    for (int k = 0; k < 4; ++k) m.rotations[4 * i + k] = float(q[k]);
    for (int k = 0; k < 2; ++k)
      m.log_scales[3 * i + k] = float(std::log(spacing(patch))) + 0.5f * g(rng);
    m.log_scales[3 * i + 2] =
        std::min(m.log_scales[3 * i], m.log_scales[3 * i + 1]) - std::log(10.f);
    m.opacity_logits[i] = 2.f + 1.5f * g(rng);
    m.instance_opacity_logits[i] = m.opacity_logits[i];
  }
  return m;
}

}  // namespace bench
