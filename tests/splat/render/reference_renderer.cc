#include "tests/splat/render/reference_renderer.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <set>

namespace splat::reference {

Params Params::from(const GaussianModel& m) {
  Params p;
  auto cp = [](const std::vector<float>& v) { return std::vector<double>(v.begin(), v.end()); };
  p.means = cp(m.means);
  p.sh_dc = cp(m.sh_dc);
  p.sh_rest = cp(m.sh_rest);
  p.opacity_logits = cp(m.opacity_logits);
  p.log_scales = cp(m.log_scales);
  p.rotations = cp(m.rotations);
  p.instance_opacity_logits = cp(m.instance_opacity_logits);
  p.labels.assign(m.labels.begin(), m.labels.end());
  if (!m.has_labels) std::fill(p.labels.begin(), p.labels.end(), 0);
  p.has_instance_opacity = m.has_instance_opacity;
  return p;
}

std::vector<std::vector<double>*> Params::arrays() {
  return {
      &means, &sh_dc, &sh_rest, &opacity_logits, &log_scales, &rotations, &instance_opacity_logits};
}

namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

double sigmoid(double x) { return 1 / (1 + std::exp(-x)); }

struct Projected {
  bool visible = false;
  double u, v, A, B, C, depth, opacity, instance_opacity, color[3];
  int x0, y0, x1, y1;  // tile rectangle
  int label;
};

double sh_color(const Params& p, size_t i, const Vec3& d, int degree, int c) {
  const double x = d.x(), y = d.y(), z = d.z();
  auto rest = [&](int k) { return p.sh_rest[45 * i + 3 * (k - 1) + c]; };
  double v = 0.28209479177387814 * p.sh_dc[3 * i + c];
  if (degree >= 1)
    v += -0.4886025119029199 * y * rest(1) + 0.4886025119029199 * z * rest(2) -
         0.4886025119029199 * x * rest(3);
  if (degree >= 2) {
    const double xx = x * x, yy = y * y, zz = z * z;
    v += 1.0925484305920792 * x * y * rest(4) - 1.0925484305920792 * y * z * rest(5) +
         0.31539156525252005 * (2 * zz - xx - yy) * rest(6) - 1.0925484305920792 * x * z * rest(7) +
         0.5462742152960396 * (xx - yy) * rest(8);
    if (degree >= 3)
      v += -0.5900435899266435 * y * (3 * xx - yy) * rest(9) +
           2.890611442640554 * x * y * z * rest(10) -
           0.4570457994644658 * y * (4 * zz - xx - yy) * rest(11) +
           0.3731763325901154 * z * (2 * zz - 3 * xx - 3 * yy) * rest(12) -
           0.4570457994644658 * x * (4 * zz - xx - yy) * rest(13) +
           1.445305721320277 * z * (xx - yy) * rest(14) -
           0.5900435899266435 * x * (xx - 3 * yy) * rest(15);
  }
  return std::max(v + 0.5, 0.0);
}

Projected project(const Params& p, size_t i, const Camera& cam, const RenderSettings& s) {
  Projected g;
  const Vec3 mean(p.means[3 * i], p.means[3 * i + 1], p.means[3 * i + 2]);
  const Vec3 pv = cam.R * mean + cam.t;
  if (pv.z() <= 0.2) return g;
  Eigen::Quaterniond q(p.rotations[4 * i], p.rotations[4 * i + 1], p.rotations[4 * i + 2],
                       p.rotations[4 * i + 3]);
  const Mat3 R = q.normalized().toRotationMatrix();
  const Mat3 S = Vec3(std::exp(p.log_scales[3 * i]), std::exp(p.log_scales[3 * i + 1]),
                      std::exp(p.log_scales[3 * i + 2]))
                     .asDiagonal();
  const Mat3 Sigma = R * S * S.transpose() * R.transpose();
  const double lim_x = 1.3 * cam.tan_half_fov_x(), lim_y = 1.3 * cam.tan_half_fov_y();
  const double uc = std::clamp(pv.x() / pv.z(), -lim_x, lim_x),
               wc = std::clamp(pv.y() / pv.z(), -lim_y, lim_y);
  Eigen::Matrix<double, 2, 3> J;
  J << cam.fx / pv.z(), 0, -cam.fx * uc / pv.z(), 0, cam.fy / pv.z(), -cam.fy * wc / pv.z();
  const Eigen::Matrix2d cov = J * cam.R * Sigma * cam.R.transpose() * J.transpose();
  const double a = cov(0, 0) + 0.3, b = cov(0, 1), c = cov(1, 1) + 0.3, det = a * c - b * b;
  if (det <= 0) return g;
  const double mid = 0.5 * (a + c);
  const int radius = int(std::ceil(3 * std::sqrt(mid + std::sqrt(std::max(0.1, mid * mid - det)))));
  g.u = cam.fx * pv.x() / pv.z() + cam.cx;
  g.v = cam.fy * pv.y() / pv.z() + cam.cy;
  if (!p.mean2d_offset.empty()) g.u += p.mean2d_offset[2 * i], g.v += p.mean2d_offset[2 * i + 1];
  const int tx = (cam.width + 15) / 16, ty = (cam.height + 15) / 16;
  g.x0 = std::clamp(int((g.u - 0.5 - radius) / 16), 0, tx);
  g.x1 = std::clamp(int((g.u - 0.5 + radius + 15) / 16), 0, tx);
  g.y0 = std::clamp(int((g.v - 0.5 - radius) / 16), 0, ty);
  g.y1 = std::clamp(int((g.v - 0.5 + radius + 15) / 16), 0, ty);
  if ((g.x1 - g.x0) * (g.y1 - g.y0) == 0) return g;
  g.visible = true;
  g.A = c / det;
  g.B = -b / det;
  g.C = a / det;
  g.depth = pv.z();
  g.opacity = sigmoid(p.opacity_logits[i]);
  g.instance_opacity = p.has_instance_opacity ? sigmoid(p.instance_opacity_logits[i]) : g.opacity;
  g.label = p.labels[i];
  const Vec3 dir = (mean - cam.center()).normalized();
  for (int ch = 0; ch < 3; ++ch) g.color[ch] = s.color ? sh_color(p, i, dir, s.sh_degree, ch) : 0;
  return g;
}

}  // namespace

Output render(const Params& p, const Camera& cam, const RenderSettings& s) {
  const int W = cam.width, H = cam.height;
  const size_t pixels = size_t(W) * H;
  std::vector<Projected> proj(p.size());
  std::set<int32_t> labels;
  for (size_t i = 0; i < p.size(); ++i) {
    proj[i] = project(p, i, cam, s);
    if (p.labels[i] > 0) labels.insert(p.labels[i]);
  }
  Output o;
  if (s.all_instance_labels)
    o.map_labels.assign(labels.begin(), labels.end());
  else
    o.map_labels.assign(s.instance_labels.begin(), s.instance_labels.end());
  o.color.assign(3 * pixels, 0);
  o.alpha.assign(pixels, 0);
  o.depth.assign(pixels, 0);
  o.contributors.assign(pixels, 0);
  o.instance_maps.assign(o.map_labels.size() * pixels, 0);
  o.instance_label.assign(pixels, 0);
  o.baseline_label.assign(pixels, 0);

  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const size_t pix = size_t(y) * W + x;
      std::vector<size_t> list;
      for (size_t i = 0; i < p.size(); ++i) {
        const Projected& g = proj[i];
        if (g.visible && x / 16 >= g.x0 && x / 16 < g.x1 && y / 16 >= g.y0 && y / 16 < g.y1)
          list.push_back(i);
      }
      // The tile renderer sorts by float depth; sort by the same key.
      std::stable_sort(list.begin(), list.end(), [&](size_t a, size_t b) {
        return float(proj[a].depth) < float(proj[b].depth);
      });
      double T = 1, best_star = 0, best_w = 0;
      for (size_t k = 0; k < list.size(); ++k) {
        const Projected& g = proj[list[k]];
        const double dx = g.u - (x + 0.5), dy = g.v - (y + 0.5);
        const double power = -0.5 * (g.A * dx * dx + g.C * dy * dy) - g.B * dx * dy;
        if (power > 0) continue;
        const double G = std::exp(power);
        const double alpha = std::min(0.99, g.opacity * G);
        if (alpha < 1.0 / 255) continue;
        if (T * (1 - alpha) < 1e-4) break;
        const double w = alpha * T;
        for (int c = 0; c < 3; ++c) o.color[3 * pix + c] += w * g.color[c];
        o.depth[pix] += w * g.depth;
        const double alpha_star = std::min(0.99, g.instance_opacity * G);
        for (size_t m = 0; m < o.map_labels.size(); ++m)
          if (o.map_labels[m] == g.label) o.instance_maps[m * pixels + pix] += alpha_star * T;
        if (alpha_star >= 1.0 / 255 && alpha_star > best_star)
          best_star = alpha_star, o.instance_label[pix] = g.label;
        if (w > best_w) best_w = w, o.baseline_label[pix] = g.label;
        ++o.contributors[pix];
        T *= 1 - alpha;
      }
      for (int c = 0; c < 3; ++c) o.color[3 * pix + c] += T * s.background[c];
      o.alpha[pix] = 1 - T;
    }
  }
  return o;
}

std::vector<double> instance_maps_frozen_T(const Params& frozen, const Params& p, const Camera& cam,
                                           const RenderSettings& s) {
  const int W = cam.width, H = cam.height;
  const size_t pixels = size_t(W) * H;
  std::vector<Projected> base(p.size()), moved(p.size());
  for (size_t i = 0; i < p.size(); ++i) {
    base[i] = project(frozen, i, cam, s);
    moved[i] = project(p, i, cam, s);
  }
  const std::vector<int32_t>& labels = s.instance_labels;
  std::vector<double> maps(labels.size() * pixels, 0);
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      std::vector<size_t> list;
      for (size_t i = 0; i < p.size(); ++i) {
        const Projected& g = base[i];
        if (g.visible && x / 16 >= g.x0 && x / 16 < g.x1 && y / 16 >= g.y0 && y / 16 < g.y1)
          list.push_back(i);
      }
      std::stable_sort(list.begin(), list.end(), [&](size_t a, size_t b) {
        return float(base[a].depth) < float(base[b].depth);
      });
      double T = 1;
      for (size_t i : list) {
        auto G_of = [&](const Projected& g) {
          const double dx = g.u - (x + 0.5), dy = g.v - (y + 0.5);
          return -0.5 * (g.A * dx * dx + g.C * dy * dy) - g.B * dx * dy;
        };
        const double power = G_of(base[i]);
        if (power > 0) continue;
        const double alpha = std::min(0.99, base[i].opacity * std::exp(power));
        if (alpha < 1.0 / 255) continue;
        if (T * (1 - alpha) < 1e-4) break;
        const double alpha_star =
            std::min(0.99, moved[i].instance_opacity * std::exp(G_of(moved[i])));
        for (size_t m = 0; m < labels.size(); ++m)
          if (labels[m] == base[i].label) maps[m * pixels + size_t(y) * W + x] += alpha_star * T;
        T *= 1 - alpha;
      }
    }
  }
  return maps;
}

}  // namespace splat::reference
