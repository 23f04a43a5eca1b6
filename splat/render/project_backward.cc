#include "splat/render/project.h"

// The backward pass of step 1 (project.h): from the projected quantities'
// gradients to the Gaussians' parameters, a batch of Gaussians at a time in
// vector lanes. With the camera's gradient, one Gaussian at a time instead
// (project_backward_one.h, the batches' reference).

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "splat/render/fast_exp.h"
#include "splat/render/project_backward_one.h"
#include "splat/render/project_backward_parts.h"
#include "splat/render/projection_view.h"
#include "splat/render/sh.h"
#include "splat/render/sh_lanes.h"

namespace splat {

using Mat3 = Eigen::Matrix3f;
using Vec3 = Eigen::Vector3f;
using Mat23 = Eigen::Matrix<float, 2, 3>;

void GaussianGradients::resize(size_t n) {
  means.resize(3 * n);
  sh_dc.resize(3 * n);
  sh_rest.resize(kShRestFloats * n);
  opacity_logits.resize(n);
  log_scales.resize(3 * n);
  rotations.resize(4 * n);
  instance_opacity_logits.resize(n);
  mean2d_ndc.resize(2 * n);
  visible.resize(n);
}

void ProjectedGradients::resize(size_t n) {
  mean2d.resize(2 * n);
  conic.resize(3 * n);
  depth.resize(n);
  color.resize(3 * n);
  opacity.resize(n);
  instance_opacity.resize(n);
}

namespace {

using project_backward_parts::backward_opacities;
using project_backward_parts::mark_visible;
using project_backward_parts::zero_gradients;

constexpr int kBatch = kProjectionBatch;

// The geometry part of backward_one (project_backward_one.cc) for kBatch
// consecutive Gaussians, with the Gaussians as vector lanes (the same
// algebra written out, as project_geometry writes out the forward's): from
// the gradients of the 2D mean, the conic and the depth to those of the
// mean, the log-scales and the rotation. Lanes of culled Gaussians compute
// meaningless values that the caller does not store.
struct GeometryGradientBatch {
  alignas(64) float mean[3][kBatch];
  alignas(64) float log_scale[3][kBatch];
  alignas(64) float rotation[4][kBatch];
};

struct GeometryBatchInput {
  const float *means, *rotations, *log_scales;  // the model's, at the batch's first Gaussian
  const float *conic, *depth_grad, *mean2d_grad, *conic_grad;  // projected, likewise
};

void backward_geometry(const GeometryBatchInput& in, const ProjectionView& v,
                       GeometryGradientBatch& out) {
  const Mat3& W = v.R;
  const float W00 = W(0, 0), W01 = W(0, 1), W02 = W(0, 2), W10 = W(1, 0), W11 = W(1, 1),
              W12 = W(1, 2), W20 = W(2, 0), W21 = W(2, 1), W22 = W(2, 2);
  const float t0 = v.t.x(), t1 = v.t.y(), t2 = v.t.z(), fx = v.fx, fy = v.fy;
#pragma GCC ivdep
  for (int i = 0; i < kBatch; ++i) {
    const float mx = in.means[3 * i], my = in.means[3 * i + 1], mz = in.means[3 * i + 2];
    const float x = W00 * mx + W01 * my + W02 * mz + t0;
    const float y = W10 * mx + W11 * my + W12 * mz + t1;
    const float z = W20 * mx + W21 * my + W22 * mz + t2;
    const float iz = 1.f / z, iz2 = iz * iz;

    // 2D mean u = fx x / z + cx, w = fy y / z + cy, and the depth.
    const float gu = in.mean2d_grad[2 * i], gw = in.mean2d_grad[2 * i + 1];
    float gpx = gu * fx * iz, gpy = gw * fy * iz;
    float gpz = in.depth_grad[i] - gu * fx * x * iz2 - gw * fy * y * iz2;

    // Conic Q (inverse of the 2D covariance): dL/dcov = -Q dL/dQ Q.
    const float A = in.conic[3 * i], B = in.conic[3 * i + 1], C = in.conic[3 * i + 2];
    const float gA = in.conic_grad[3 * i], hB = 0.5f * in.conic_grad[3 * i + 1],
                gC = in.conic_grad[3 * i + 2];
    const float P00 = A * gA + B * hB, P01 = A * hB + B * gC;
    const float P10 = B * gA + C * hB, P11 = B * hB + C * gC;
    const float G00 = -(P00 * A + P01 * B), G01 = -(P00 * B + P01 * C);
    const float G10 = -(P10 * A + P11 * B), G11 = -(P10 * B + P11 * C);

    // Rotation of the normalised quaternion, scales, M = R diag(s), Sigma = M M^T.
    const float qw0 = in.rotations[4 * i], qx0 = in.rotations[4 * i + 1],
                qy0 = in.rotations[4 * i + 2], qz0 = in.rotations[4 * i + 3];
    const float inv_qn = 1.f / std::sqrt(qw0 * qw0 + qx0 * qx0 + qy0 * qy0 + qz0 * qz0);
    const float qw = qw0 * inv_qn, qx = qx0 * inv_qn, qy = qy0 * inv_qn, qz = qz0 * inv_qn;
    const float R00 = 1 - 2 * (qy * qy + qz * qz), R01 = 2 * (qx * qy - qw * qz),
                R02 = 2 * (qx * qz + qw * qy);
    const float R10 = 2 * (qx * qy + qw * qz), R11 = 1 - 2 * (qx * qx + qz * qz),
                R12 = 2 * (qy * qz - qw * qx);
    const float R20 = 2 * (qx * qz - qw * qy), R21 = 2 * (qy * qz + qw * qx),
                R22 = 1 - 2 * (qx * qx + qy * qy);
    const float s0 = fast_exp(std::min(in.log_scales[3 * i], 80.f));
    const float s1 = fast_exp(std::min(in.log_scales[3 * i + 1], 80.f));
    const float s2 = fast_exp(std::min(in.log_scales[3 * i + 2], 80.f));
    const float M00 = R00 * s0, M01 = R01 * s1, M02 = R02 * s2;
    const float M10 = R10 * s0, M11 = R11 * s1, M12 = R12 * s2;
    const float M20 = R20 * s0, M21 = R21 * s1, M22 = R22 * s2;
    const float S00 = M00 * M00 + M01 * M01 + M02 * M02;
    const float S01 = M00 * M10 + M01 * M11 + M02 * M12;
    const float S02 = M00 * M20 + M01 * M21 + M02 * M22;
    const float S11 = M10 * M10 + M11 * M11 + M12 * M12;
    const float S12 = M10 * M20 + M11 * M21 + M12 * M22;
    const float S22 = M20 * M20 + M21 * M21 + M22 * M22;

    // The Jacobian with the reference's clamp, T = J W.
    const float u_raw = x * iz, w_raw = y * iz;
    const float uc = std::clamp(u_raw, -v.lim_x, v.lim_x);
    const float wc = std::clamp(w_raw, -v.lim_y, v.lim_y);
    const float J00 = fx * iz, J02 = -fx * uc * iz, J11 = fy * iz, J12 = -fy * wc * iz;
    const float T00 = J00 * W00 + J02 * W20, T01 = J00 * W01 + J02 * W21,
                T02 = J00 * W02 + J02 * W22;
    const float T10 = J11 * W10 + J12 * W20, T11 = J11 * W11 + J12 * W21,
                T12 = J11 * W12 + J12 * W22;

    // cov = T Sigma T^T: dL/dSigma = T^T G T, dL/dT = 2 G T Sigma, with U = G T.
    const float U00 = G00 * T00 + G01 * T10, U01 = G00 * T01 + G01 * T11,
                U02 = G00 * T02 + G01 * T12;
    const float U10 = G10 * T00 + G11 * T10, U11 = G10 * T01 + G11 * T11,
                U12 = G10 * T02 + G11 * T12;
    const float gS00 = T00 * U00 + T10 * U10, gS01 = T00 * U01 + T10 * U11,
                gS02 = T00 * U02 + T10 * U12;
    const float gS10 = T01 * U00 + T11 * U10, gS11 = T01 * U01 + T11 * U11,
                gS12 = T01 * U02 + T11 * U12;
    const float gS20 = T02 * U00 + T12 * U10, gS21 = T02 * U01 + T12 * U11,
                gS22 = T02 * U02 + T12 * U12;
    const float gT00 = 2 * (U00 * S00 + U01 * S01 + U02 * S02);
    const float gT01 = 2 * (U00 * S01 + U01 * S11 + U02 * S12);
    const float gT02 = 2 * (U00 * S02 + U01 * S12 + U02 * S22);
    const float gT10 = 2 * (U10 * S00 + U11 * S01 + U12 * S02);
    const float gT11 = 2 * (U10 * S01 + U11 * S11 + U12 * S12);
    const float gT12 = 2 * (U10 * S02 + U11 * S12 + U12 * S22);
    // dL/dJ = dL/dT W^T (the entries J has).
    const float gJ00 = gT00 * W00 + gT01 * W01 + gT02 * W02;
    const float gJ02 = gT00 * W20 + gT01 * W21 + gT02 * W22;
    const float gJ11 = gT10 * W10 + gT11 * W11 + gT12 * W12;
    const float gJ12 = gT10 * W20 + gT11 * W21 + gT12 * W22;

    // The Jacobian's entries -> camera-space point, exact through the clamp.
    gpz += (-gJ00 * fx + gJ02 * fx * uc - gJ11 * fy + gJ12 * fy * wc) * iz2;
    const float in_x = (u_raw > -v.lim_x ? 1.f : 0.f) * (u_raw < v.lim_x ? 1.f : 0.f);
    const float in_y = (w_raw > -v.lim_y ? 1.f : 0.f) * (w_raw < v.lim_y ? 1.f : 0.f);
    const float g_uc = -gJ02 * fx * iz * in_x, g_wc = -gJ12 * fy * iz * in_y;
    gpx += g_uc * iz;
    gpz -= g_uc * x * iz2;
    gpy += g_wc * iz;
    gpz -= g_wc * y * iz2;
    out.mean[0][i] = W00 * gpx + W10 * gpy + W20 * gpz;
    out.mean[1][i] = W01 * gpx + W11 * gpy + W21 * gpz;
    out.mean[2][i] = W02 * gpx + W12 * gpy + W22 * gpz;

    // Sigma = M M^T: dL/dM = (gS + gS^T) M; log-scales and dL/dR = dL/dM diag(s).
    const float H00 = 2 * gS00, H01 = gS01 + gS10, H02 = gS02 + gS20;
    const float H11 = 2 * gS11, H12 = gS12 + gS21, H22 = 2 * gS22;
    const float gM00 = H00 * M00 + H01 * M10 + H02 * M20;
    const float gM01 = H00 * M01 + H01 * M11 + H02 * M21;
    const float gM02 = H00 * M02 + H01 * M12 + H02 * M22;
    const float gM10 = H01 * M00 + H11 * M10 + H12 * M20;
    const float gM11 = H01 * M01 + H11 * M11 + H12 * M21;
    const float gM12 = H01 * M02 + H11 * M12 + H12 * M22;
    const float gM20 = H02 * M00 + H12 * M10 + H22 * M20;
    const float gM21 = H02 * M01 + H12 * M11 + H22 * M21;
    const float gM22 = H02 * M02 + H12 * M12 + H22 * M22;
    out.log_scale[0][i] = (gM00 * R00 + gM10 * R10 + gM20 * R20) * s0;
    out.log_scale[1][i] = (gM01 * R01 + gM11 * R11 + gM21 * R21) * s1;
    out.log_scale[2][i] = (gM02 * R02 + gM12 * R12 + gM22 * R22) * s2;
    const float gR00 = gM00 * s0, gR01 = gM01 * s1, gR02 = gM02 * s2;
    const float gR10 = gM10 * s0, gR11 = gM11 * s1, gR12 = gM12 * s2;
    const float gR20 = gM20 * s0, gR21 = gM21 * s1, gR22 = gM22 * s2;
    // d R(q) / d q (quaternion_matrix_backward), then through the normalisation.
    const float gqw = 2 * (-qz * gR01 + qy * gR02 + qz * gR10 - qx * gR12 - qy * gR20 + qx * gR21);
    const float gqx = 2 * (qy * gR01 + qz * gR02 + qy * gR10 - 2 * qx * gR11 - qw * gR12 +
                           qz * gR20 + qw * gR21 - 2 * qx * gR22);
    const float gqy = 2 * (-2 * qy * gR00 + qx * gR01 + qw * gR02 + qx * gR10 + qz * gR12 -
                           qw * gR20 + qz * gR21 - 2 * qy * gR22);
    const float gqz = 2 * (-2 * qz * gR00 - qw * gR01 + qx * gR02 + qw * gR10 - 2 * qz * gR11 +
                           qy * gR12 + qx * gR20 + qy * gR21);
    const float dot = qw * gqw + qx * gqx + qy * gqy + qz * gqz;
    out.rotation[0][i] = (gqw - qw * dot) * inv_qn;
    out.rotation[1][i] = (gqx - qx * dot) * inv_qn;
    out.rotation[2][i] = (gqy - qy * dot) * inv_qn;
    out.rotation[3][i] = (gqz - qz * dot) * inv_qn;
  }
}

// backward_color for a batch, with the Gaussians as vector lanes (the same
// algebra; kDegree: the active SH degree). One Gaussian at a time it was
// scalar code that spent most of the projection's backward pass; in lanes,
// the coefficients are turned by sh_lanes.h.
struct ColorGradientBatch {
  alignas(64) float mean[3][kBatch];  // through the view direction
  alignas(64) float sh_dc[3][kBatch];
  ShRestLanes sh_rest;  // the bands above kDegree: 0
};

// The SH rows of the batch after the one at `rows` (kShRestFloats floats a
// Gaussian), fetched while this one computes: the hardware's prefetchers,
// following some twenty streams here, fell behind on these two, the largest
// (BM_ProjectBackward at 1M Gaussians: 90 ms without, 77 ms with both).
inline void prefetch_next_batch(const float* rows, bool for_writing) {
  const char* next = reinterpret_cast<const char*>(rows + kShRestFloats * kBatch);
  for (size_t k = 0; k < kShRestFloats * kBatch * sizeof(float); k += 64) {
    if (for_writing)
      __builtin_prefetch(next + k, 1);
    else
      __builtin_prefetch(next + k, 0);
  }
}

struct ColorBatchInput {
  const float* means;       // the model's, at the batch's first Gaussian
  const float* color_grad;  // projected, likewise
  const int32_t* clamped;   // likewise, widened (GCC does not vectorise the bytes)
};

template <int kDegree>
void backward_color_lanes(const ColorBatchInput& in, const ShRestLanes& rest, const Vec3& center,
                          ColorGradientBatch& out) {
  const float cx = center.x(), cy = center.y(), cz = center.z();
#pragma GCC ivdep
  for (int l = 0; l < kBatch; ++l) {
    const float dx = in.means[3 * l] - cx, dy = in.means[3 * l + 1] - cy,
                dz = in.means[3 * l + 2] - cz;
    const float dlen = std::sqrt(dx * dx + dy * dy + dz * dz);
    const float x = dx / dlen, y = dy / dlen, z = dz / dlen;
    float gc[3];
    for (int c = 0; c < 3; ++c) {
      const float g = in.color_grad[3 * l + c];
      gc[c] = in.clamped[3 * l + c] ? 0.f : g;
    }
    float gx = 0.f, gy = 0.f, gz = 0.f;
    for_each_sh_basis(kDegree, x, y, z, [&](int k, float b, float db_dx, float db_dy, float db_dz) {
      if (k == 0) {
        for (int c = 0; c < 3; ++c) out.sh_dc[c][l] = b * gc[c];
        return;
      }
      float weighted = 0.f;
      for (int c = 0; c < 3; ++c) {
        out.sh_rest.rows[3 * (k - 1) + c][l] = b * gc[c];
        weighted += rest.rows[3 * (k - 1) + c][l] * gc[c];
      }
      gx += db_dx * weighted;
      gy += db_dy * weighted;
      gz += db_dz * weighted;
    });
    const float dot = x * gx + y * gy + z * gz;
    out.mean[0][l] = (gx - x * dot) / dlen;
    out.mean[1][l] = (gy - y * dot) / dlen;
    out.mean[2][l] = (gz - z * dot) / dlen;
  }
  constexpr int kActive = 3 * ((kDegree + 1) * (kDegree + 1) - 1);
  for (int j = kActive; j < kShRestFloats; ++j) std::fill_n(out.sh_rest.rows[j], kBatch, 0.f);
}

// The colour gradients of the batch of `count` Gaussians from `first`; a
// partial batch is padded with copies of its last Gaussian.
void backward_color_batch(const GaussianModel& m, const ProjectionView& v, const RenderSettings& s,
                          const ProjectedGaussians& p, const ProjectedGradients& pg, size_t first,
                          size_t count, ColorGradientBatch& out) {
  const float* rows[kBatch];
  for (size_t l = 0; l < kBatch; ++l)
    rows[l] = &m.sh_rest[kShRestFloats * (first + std::min(l, count - 1))];
  if (first + 2 * kBatch <= m.size()) prefetch_next_batch(&m.sh_rest[kShRestFloats * first], false);
  ShRestLanes rest;
  load_sh_rest_lanes(rows, rest);
  alignas(64) int32_t clamped[3 * kBatch];
  ColorBatchInput in{&m.means[3 * first], &pg.color[3 * first], clamped};
  float means[3 * kBatch], color_grad[3 * kBatch];
  if (count < kBatch) {
    for (size_t l = 0; l < kBatch; ++l) {
      const size_t i = first + std::min(l, count - 1);
      std::copy_n(&m.means[3 * i], 3, &means[3 * l]);
      std::copy_n(&pg.color[3 * i], 3, &color_grad[3 * l]);
      std::copy_n(&p.color_clamped[3 * i], 3, &clamped[3 * l]);
    }
    in.means = means, in.color_grad = color_grad;
  } else {
    std::copy_n(&p.color_clamped[3 * first], 3 * kBatch, clamped);
  }
  switch (s.sh_degree) {
    case 0:
      return backward_color_lanes<0>(in, rest, v.center, out);
    case 1:
      return backward_color_lanes<1>(in, rest, v.center, out);
    case 2:
      return backward_color_lanes<2>(in, rest, v.center, out);
    default:
      return backward_color_lanes<3>(in, rest, v.center, out);
  }
}

// Zeroes the gradients of a batch's culled Gaussians and writes its visible
// ones': the geometry a batch at a time, the colour and opacities one by one;
// the SH rest's to the sink instead, when there is one.
void backward_batch(const GaussianModel& m, const ProjectionView& v, const RenderSettings& s,
                    const BackwardSettings& backward_settings, const ProjectedGaussians& p,
                    const ProjectedGradients& pg, size_t first, size_t count, float half_w,
                    float half_h, GaussianGradients& g) {
  bool any_visible = false;
  for (size_t i = first; i < first + count; ++i) {
    if (p.visible(i)) {  // every field written below
      any_visible = true;
    } else if (backward_settings.zero_culled_gradients) {
      zero_gradients(g, i);
    } else {
      g.visible[i] = 0;
    }
  }
  ShRestGradientSink* const sink = backward_settings.sh_rest_sink;
  if (!any_visible) {
    if (sink) sink->take(first, count, nullptr, 0);
    return;
  }
  GeometryGradientBatch geometry;
  if (count == kBatch) {
    backward_geometry(
        {&m.means[3 * first], &m.rotations[4 * first], &m.log_scales[3 * first],
         &p.conic[3 * first], &pg.depth[first], &pg.mean2d[2 * first], &pg.conic[3 * first]},
        v, geometry);
  } else {  // the last, partial batch: padded with copies of its last Gaussian
    float means[3 * kBatch], rotations[4 * kBatch], log_scales[3 * kBatch], conic[3 * kBatch],
        depth_grad[kBatch], mean2d_grad[2 * kBatch], conic_grad[3 * kBatch];
    for (size_t l = 0; l < kBatch; ++l) {
      const size_t i = first + std::min(l, count - 1);
      std::copy_n(&m.means[3 * i], 3, &means[3 * l]);
      std::copy_n(&m.rotations[4 * i], 4, &rotations[4 * l]);
      std::copy_n(&m.log_scales[3 * i], 3, &log_scales[3 * l]);
      std::copy_n(&p.conic[3 * i], 3, &conic[3 * l]);
      depth_grad[l] = pg.depth[i];
      std::copy_n(&pg.mean2d[2 * i], 2, &mean2d_grad[2 * l]);
      std::copy_n(&pg.conic[3 * i], 3, &conic_grad[3 * l]);
    }
    backward_geometry({means, rotations, log_scales, conic, depth_grad, mean2d_grad, conic_grad}, v,
                      geometry);
  }
  ColorGradientBatch color;
  if (s.color) backward_color_batch(m, v, s, p, pg, first, count, color);
  alignas(64) float sunk_rows[kBatch][kShRestFloats];  // used with a sink only
  if (!sink && first + 2 * kBatch <= m.size())
    prefetch_next_batch(&g.sh_rest[kShRestFloats * first], true);
  float* rest_rows[kBatch];
  uint32_t visible_lanes = 0;
  for (size_t l = 0; l < count; ++l) {
    const size_t i = first + l;
    rest_rows[l] = sink ? sunk_rows[l] : &g.sh_rest[kShRestFloats * i];
    if (!p.visible(i)) continue;
    visible_lanes |= 1u << l;
    mark_visible(pg, i, half_w, half_h, g);
    for (int k = 0; k < 3; ++k) {
      g.means[3 * i + k] = geometry.mean[k][l] + (s.color ? color.mean[k][l] : 0.f);
      g.log_scales[3 * i + k] = geometry.log_scale[k][l];
      g.sh_dc[3 * i + k] = s.color ? color.sh_dc[k][l] : 0.f;
    }
    if (!s.color) std::fill_n(rest_rows[l], kShRestFloats, 0.f);
    for (int k = 0; k < 4; ++k) g.rotations[4 * i + k] = geometry.rotation[k][l];
    backward_opacities(p, pg, i, g);
  }
  if (s.color) store_sh_rest_rows(color.sh_rest, rest_rows, visible_lanes);
  if (sink) sink->take(first, count, &sunk_rows[0][0], visible_lanes);
}

}  // namespace

void project_gaussians_backward(const GaussianModel& m, const Camera& cam, const RenderSettings& s,
                                const BackwardSettings& backward_settings,
                                const ProjectedGaussians& p, const ProjectedGradients& pg,
                                GaussianGradients& g) {
  const size_t n = m.size();
  g.resize(n);
  const ProjectionView v(cam);
  const float half_w = 0.5f * cam.width, half_h = 0.5f * cam.height;
  g.camera.fill(0.0);
  if (!backward_settings.camera_gradient) {
    const size_t batches = (n + kBatch - 1) / kBatch;
    // At least 512 Gaussians a task, as project_gaussians.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, batches, 32), [&](const auto& range) {
      for (size_t b = range.begin(); b < range.end(); ++b)
        backward_batch(m, v, s, backward_settings, p, pg, b * kBatch,
                       std::min<size_t>(kBatch, n - b * kBatch), half_w, half_h, g);
    });
    return;
  }
  // With the camera's gradient: one Gaussian at a time.
  if (backward_settings.sh_rest_sink)
    throw std::invalid_argument("an SH-rest gradient sink needs camera_gradient off");
  project_gaussians_backward_one_by_one(m, cam, s, p, pg, g);
}

}  // namespace splat
