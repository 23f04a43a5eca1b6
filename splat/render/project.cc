#include "splat/render/project.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "splat/parallel_fill.h"
#include "splat/render/fast_exp.h"
#include "splat/render/projection_view.h"
#include "splat/render/sh.h"

namespace splat {

using Mat3 = Eigen::Matrix3f;
using Vec3 = Eigen::Vector3f;
namespace {

void evaluate_color(const GaussianModel& m, size_t i, const Vec3& dir, int degree, float rgb[3],
                    uint8_t clamped[3]) {
  const float* dc = &m.sh_dc[3 * i];
  const float* rest = &m.sh_rest[kShRestFloats * i];
  float v[3];
  for_each_sh_basis(degree, dir.x(), dir.y(), dir.z(), [&](int k, float b, float, float, float) {
    for (int c = 0; c < 3; ++c) v[c] = k == 0 ? b * dc[c] : v[c] + b * rest[3 * (k - 1) + c];
  });
  for (int c = 0; c < 3; ++c) {
    v[c] += 0.5f;
    clamped[c] = v[c] < 0;
    rgb[c] = std::max(v[c], 0.f);
  }
}

// The geometry of up to kBatch consecutive Gaussians, computed with the
// Gaussians as vector lanes (the algebra written out, so that GCC
// vectorises it; project_backward.cc's backward_geometry is its backward):
// camera-space centre, 2D mean, and the low-passed 2D covariance.
constexpr int kBatch = kProjectionBatch;
struct GeometryBatch {
  alignas(64) float u[kBatch], w[kBatch], z[kBatch];
  alignas(64) float a[kBatch], b[kBatch], c[kBatch];  // 2D covariance + low-pass
};

// means, rotations and log_scales point at the batch's first Gaussian; the
// batch holds kBatch Gaussians.
void project_geometry(const float* means, const float* rotations, const float* log_scales,
                      const ProjectionView& v, GeometryBatch& out) {
  const Mat3& W = v.R;
  const float W00 = W(0, 0), W01 = W(0, 1), W02 = W(0, 2), W10 = W(1, 0), W11 = W(1, 1),
              W12 = W(1, 2), W20 = W(2, 0), W21 = W(2, 1), W22 = W(2, 2);
  const float t0 = v.t.x(), t1 = v.t.y(), t2 = v.t.z();
#pragma GCC ivdep
  for (int i = 0; i < kBatch; ++i) {
    const float mx = means[3 * i], my = means[3 * i + 1], mz = means[3 * i + 2];
    const float x = W00 * mx + W01 * my + W02 * mz + t0;
    const float y = W10 * mx + W11 * my + W12 * mz + t1;
    const float z = W20 * mx + W21 * my + W22 * mz + t2;
    // Rotation of the normalised quaternion, scaled columns M = R diag(s).
    const float qw0 = rotations[4 * i], qx0 = rotations[4 * i + 1], qy0 = rotations[4 * i + 2],
                qz0 = rotations[4 * i + 3];
    const float inv_qn = 1.f / std::sqrt(qw0 * qw0 + qx0 * qx0 + qy0 * qy0 + qz0 * qz0);
    const float qw = qw0 * inv_qn, qx = qx0 * inv_qn, qy = qy0 * inv_qn, qz = qz0 * inv_qn;
    const float s0 = fast_exp(std::min(log_scales[3 * i], 80.f));
    const float s1 = fast_exp(std::min(log_scales[3 * i + 1], 80.f));
    const float s2 = fast_exp(std::min(log_scales[3 * i + 2], 80.f));
    const float M00 = (1 - 2 * (qy * qy + qz * qz)) * s0, M01 = 2 * (qx * qy - qw * qz) * s1,
                M02 = 2 * (qx * qz + qw * qy) * s2;
    const float M10 = 2 * (qx * qy + qw * qz) * s0, M11 = (1 - 2 * (qx * qx + qz * qz)) * s1,
                M12 = 2 * (qy * qz - qw * qx) * s2;
    const float M20 = 2 * (qx * qz - qw * qy) * s0, M21 = 2 * (qy * qz + qw * qx) * s1,
                M22 = (1 - 2 * (qx * qx + qy * qy)) * s2;
    // Sigma = M M^T (symmetric).
    const float S00 = M00 * M00 + M01 * M01 + M02 * M02;
    const float S01 = M00 * M10 + M01 * M11 + M02 * M12;
    const float S02 = M00 * M20 + M01 * M21 + M02 * M22;
    const float S11 = M10 * M10 + M11 * M11 + M12 * M12;
    const float S12 = M10 * M20 + M11 * M21 + M12 * M22;
    const float S22 = M20 * M20 + M21 * M21 + M22 * M22;
    // The projection Jacobian with the reference's clamp, then T = J W.
    const float inv_z = 1.f / z;
    const float uc = std::clamp(x * inv_z, -v.lim_x, v.lim_x);
    const float wc = std::clamp(y * inv_z, -v.lim_y, v.lim_y);
    const float J00 = v.fx * inv_z, J02 = -v.fx * uc * inv_z;
    const float J11 = v.fy * inv_z, J12 = -v.fy * wc * inv_z;
    const float T00 = J00 * W00 + J02 * W20, T01 = J00 * W01 + J02 * W21,
                T02 = J00 * W02 + J02 * W22;
    const float T10 = J11 * W10 + J12 * W20, T11 = J11 * W11 + J12 * W21,
                T12 = J11 * W12 + J12 * W22;
    // cov = T Sigma T^T.
    const float P0 = T00 * S00 + T01 * S01 + T02 * S02;
    const float P1 = T00 * S01 + T01 * S11 + T02 * S12;
    const float P2 = T00 * S02 + T01 * S12 + T02 * S22;
    const float Q0 = T10 * S00 + T11 * S01 + T12 * S02;
    const float Q1 = T10 * S01 + T11 * S11 + T12 * S12;
    const float Q2 = T10 * S02 + T11 * S12 + T12 * S22;
    out.a[i] = P0 * T00 + P1 * T01 + P2 * T02 + kLowPass;
    out.b[i] = P0 * T10 + P1 * T11 + P2 * T12;
    out.c[i] = Q0 * T10 + Q1 * T11 + Q2 * T12 + kLowPass;
    out.u[i] = v.fx * x * inv_z + v.cx;
    out.w[i] = v.fy * y * inv_z + v.cy;
    out.z[i] = z;
  }
}

// Culling, radius and tile rectangle of a batch, with the Gaussians as
// vector lanes, from their geometry and opacity. visible[l] is 0 for a
// culled Gaussian; its other fields are then meaningless.
struct ExtentBatch {
  alignas(64) float sigma[kBatch];  // filled by the caller
  alignas(64) float det[kBatch];    // of the 2D covariance, for the conic
  alignas(64) float ext_x[kBatch], ext_y[kBatch];
  alignas(64) int32_t radius[kBatch], x0[kBatch], y0[kBatch], x1[kBatch], y1[kBatch];
  alignas(64) int32_t visible[kBatch];
};

// Tile arithmetic on v held to [-1, tiles + 1] first: far outside the image
// the result is clamped to the grid anyway, and the conversions stay
// defined. Written with int conversions, as std::floor and std::ceil keep
// GCC from vectorising the loop.
inline float hold_to_grid(float v, int tiles) {
  return std::min(std::max(v, -1.f), float(tiles + 1));
}
inline int32_t tile_index(float v, int tiles) { return int32_t(hold_to_grid(v, tiles)); }
inline int32_t tile_floor(float v, int tiles) {
  v = hold_to_grid(v, tiles);
  const int32_t t = int32_t(v);
  return t - (float(t) > v ? 1 : 0);
}
// ceil(v) for 0 <= v < 2^31.
inline int32_t ceil_positive(float v) {
  const int32_t t = int32_t(v);
  return t + (float(t) < v ? 1 : 0);
}

void project_extents(const GeometryBatch& g, int tiles_x, int tiles_y, ExtentBatch& e) {
  // In front of the near plane, alpha can reach 1/255 somewhere, and the
  // covariance is positive definite (all false for NaN). Culled lanes go on
  // with harmless values, and the covariance is held under 1e12 px^2 (a
  // radius of 3e6 px, far past any image) so that the radius fits an int.
  // (A loop of its own: merged with the next, GCC turns the selects into
  // branches and vectorises neither.)
  alignas(64) float sa[kBatch], sc[kBatch], ssigma[kBatch], su[kBatch], sw[kBatch];
  alignas(64) int32_t ok[kBatch];
#pragma GCC ivdep
  for (int l = 0; l < kBatch; ++l) {
    const float a = g.a[l], b = g.b[l], c = g.c[l], sigma = e.sigma[l];
    const float det = a * c - b * b;
    const bool keep = (g.z[l] > kNearPlane) & (sigma >= kMinAlpha) & (det > 0);
    ok[l] = keep ? 1 : 0;
    sa[l] = keep ? std::min(a, 1e12f) : 1.f;
    sc[l] = keep ? std::min(c, 1e12f) : 1.f;
    e.det[l] = keep ? det : 1.f;
    ssigma[l] = keep ? sigma : 1.f;
    su[l] = keep ? g.u[l] : 0.f;
    sw[l] = keep ? g.w[l] : 0.f;
  }
#pragma GCC ivdep
  for (int l = 0; l < kBatch; ++l) {
    const float a = sa[l], c = sc[l];
    const float mid = 0.5f * (a + c);
    const float lambda = mid + std::sqrt(std::max(0.1f, mid * mid - e.det[l]));
    const int32_t radius = ceil_positive(3.f * std::sqrt(lambda));
    // The reference's tile rectangle, in its pixel coordinates (centres at integers).
    const float cu = su[l] - 0.5f, cw = sw[l] - 0.5f;
    int32_t x0 = std::clamp(tile_index((cu - radius) / kTileSize, tiles_x), 0, tiles_x);
    int32_t x1 =
        std::clamp(tile_index((cu + radius + kTileSize - 1) / kTileSize, tiles_x), 0, tiles_x);
    int32_t y0 = std::clamp(tile_index((cw - radius) / kTileSize, tiles_y), 0, tiles_y);
    int32_t y1 =
        std::clamp(tile_index((cw + radius + kTileSize - 1) / kTileSize, tiles_y), 0, tiles_y);
    // Narrow to where sigma G >= 1/255: d^T Q d <= 2 ln(255 sigma), an ellipse
    // with half-extents sqrt(2 ln(255 sigma) cov_xx) and ..._yy; with a margin.
    const float level = 2.f * fast_log(255.f * ssigma[l]);
    const float ext_x = 1.001f * std::sqrt(level * a) + 0.01f;
    const float ext_y = 1.001f * std::sqrt(level * c) + 0.01f;
    x0 = std::max(x0, tile_floor((cu - ext_x) / kTileSize, tiles_x));
    x1 = std::min(x1, tile_floor((cu + ext_x) / kTileSize, tiles_x) + 1);
    y0 = std::max(y0, tile_floor((cw - ext_y) / kTileSize, tiles_y));
    y1 = std::min(y1, tile_floor((cw + ext_y) / kTileSize, tiles_y) + 1);
    e.ext_x[l] = ext_x;
    e.ext_y[l] = ext_y;
    e.radius[l] = radius;
    e.x0[l] = x0, e.y0[l] = y0, e.x1[l] = x1, e.y1[l] = y1;
    e.visible[l] = ok[l] & (x1 > x0) & (y1 > y0);
  }
}

// Stores Gaussian i from lane l of its batch, which is visible.
void store_projected(const GaussianModel& m, const GeometryBatch& g, const ExtentBatch& e, int l,
                     size_t i, ProjectedGaussians& p) {
  const float a = g.a[l], b = g.b[l], c = g.c[l], det = e.det[l];
  p.mean2d[2 * i] = g.u[l];
  p.mean2d[2 * i + 1] = g.w[l];
  p.conic[3 * i] = c / det;
  p.conic[3 * i + 1] = -b / det;
  p.conic[3 * i + 2] = a / det;
  p.depth[i] = g.z[l];
  p.radius[i] = e.radius[l];
  p.reach[2 * i] = e.ext_x[l];
  p.reach[2 * i + 1] = e.ext_y[l];
  int32_t* r = &p.tile_rect[4 * i];
  r[0] = e.x0[l], r[1] = e.y0[l], r[2] = e.x1[l], r[3] = e.y1[l];
  p.opacity[i] = e.sigma[l];
  p.instance_opacity[i] =
      m.has_instance_opacity ? sigmoid(m.instance_opacity_logits[i]) : e.sigma[l];
}

}  // namespace

void project_gaussians(const GaussianModel& m, const Camera& cam, const RenderSettings& s,
                       ProjectedGaussians& p) {
  const size_t n = m.size();
  p.tiles_x = (cam.width + kTileSize - 1) / kTileSize;
  p.tiles_y = (cam.height + kTileSize - 1) / kTileSize;
  // Only the radius marks a Gaussian visible; every other field is written
  // for visible Gaussians and read for them alone, so it is not cleared (for
  // 1M Gaussians that saves 60 MB of memset a view).
  parallel_assign(p.radius, n, 0);
  p.mean2d.resize(2 * n);
  p.conic.resize(3 * n);
  p.depth.resize(n);
  p.tile_rect.resize(4 * n);
  p.reach.resize(2 * n);
  p.opacity.resize(n);
  p.instance_opacity.resize(n);
  p.color.resize(s.color ? 3 * n : 0);
  p.color_clamped.resize(s.color ? 3 * n : 0);
  const ProjectionView v(cam);
  const size_t batches = (n + kBatch - 1) / kBatch;
  // Tasks of at least 512 Gaussians, so that the few thousand of early
  // training are split between threads too.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, batches, 32), [&](const auto& range) {
    GeometryBatch g;
    ExtentBatch e;
    for (size_t batch = range.begin(); batch < range.end(); ++batch) {
      const size_t first = batch * kBatch, count = std::min<size_t>(kBatch, n - first);
      if (count == kBatch) {
        project_geometry(&m.means[3 * first], &m.rotations[4 * first], &m.log_scales[3 * first], v,
                         g);
      } else {  // the last, partial batch: padded with copies of its last Gaussian
        float means[3 * kBatch], rotations[4 * kBatch], log_scales[3 * kBatch];
        for (int l = 0; l < kBatch; ++l) {
          const size_t i = first + std::min<size_t>(l, count - 1);
          std::copy_n(&m.means[3 * i], 3, &means[3 * l]);
          std::copy_n(&m.rotations[4 * i], 4, &rotations[4 * l]);
          std::copy_n(&m.log_scales[3 * i], 3, &log_scales[3 * l]);
        }
        project_geometry(means, rotations, log_scales, v, g);
      }
      for (int l = 0; l < kBatch; ++l)
        e.sigma[l] = sigmoid(m.opacity_logits[first + std::min<size_t>(l, count - 1)]);
      project_extents(g, p.tiles_x, p.tiles_y, e);
      for (int l = 0; l < int(count); ++l) {
        if (!e.visible[l]) continue;
        const size_t i = first + size_t(l);
        store_projected(m, g, e, l, i, p);
        if (s.color) {
          const Vec3 mean(m.means[3 * i], m.means[3 * i + 1], m.means[3 * i + 2]);
          evaluate_color(m, i, (mean - v.center).normalized(), s.sh_degree, &p.color[3 * i],
                         &p.color_clamped[3 * i]);
        }
      }
    }
  });
}

}  // namespace splat
