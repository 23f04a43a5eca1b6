#include "splat/render/project_backward_one.h"

// The projection's backward pass one Gaussian at a time (the header says
// why it is kept). The algebra follows the forward of project.cc.

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "splat/render/project_backward_parts.h"
#include "splat/render/projection_view.h"
#include "splat/render/sh.h"

namespace splat {

using Mat3 = Eigen::Matrix3f;
using Vec3 = Eigen::Vector3f;
using Mat23 = Eigen::Matrix<float, 2, 3>;

namespace {

using project_backward_parts::backward_opacities;
using project_backward_parts::mark_visible;
using project_backward_parts::zero_gradients;

// Rotation matrix of the normalised quaternion w x y z.
Mat3 quaternion_matrix(float w, float x, float y, float z) {
  Mat3 R;
  R << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y), 2 * (x * y + w * z),
      1 - 2 * (x * x + z * z), 2 * (y * z - w * x), 2 * (x * z - w * y), 2 * (y * z + w * x),
      1 - 2 * (x * x + y * y);
  return R;
}

// The projection Jacobian at camera-space point pv, with the reference's
// clamp of the projected direction at 1.3 tan(fov/2).
Mat23 projection_jacobian(const ProjectionView& v, const Vec3& pv) {
  const float z = pv.z();
  const float uc = std::clamp(pv.x() / z, -v.lim_x, v.lim_x);
  const float wc = std::clamp(pv.y() / z, -v.lim_y, v.lim_y);
  Mat23 J;
  J << v.fx / z, 0, -v.fx * uc / z, 0, v.fy / z, -v.fy * wc / z;
  return J;
}

// M = R diag(s) of Gaussian i (its covariance is M M^T), with R and s.
Mat3 scaled_rotation(const GaussianModel& m, size_t i, Mat3& R, Vec3& s) {
  const float* q = &m.rotations[4 * i];
  const float qn = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  R = quaternion_matrix(q[0] / qn, q[1] / qn, q[2] / qn, q[3] / qn);
  s = Vec3(std::exp(m.log_scales[3 * i]), std::exp(m.log_scales[3 * i + 1]),
           std::exp(m.log_scales[3 * i + 2]));
  return R * s.asDiagonal();
}

// d R(q) / d q for the normalised quaternion, contracted with dL/dR.
Eigen::Vector4f quaternion_matrix_backward(const Eigen::Vector4f& q, const Mat3& gR) {
  const float w = q[0], x = q[1], y = q[2], z = q[3];
  Eigen::Vector4f g;
  g[0] = 2 *
         (-z * gR(0, 1) + y * gR(0, 2) + z * gR(1, 0) - x * gR(1, 2) - y * gR(2, 0) + x * gR(2, 1));
  g[1] = 2 * (y * gR(0, 1) + z * gR(0, 2) + y * gR(1, 0) - 2 * x * gR(1, 1) - w * gR(1, 2) +
              z * gR(2, 0) + w * gR(2, 1) - 2 * x * gR(2, 2));
  g[2] = 2 * (-2 * y * gR(0, 0) + x * gR(0, 1) + w * gR(0, 2) + x * gR(1, 0) + z * gR(1, 2) -
              w * gR(2, 0) + z * gR(2, 1) - 2 * y * gR(2, 2));
  g[3] = 2 * (-2 * z * gR(0, 0) - w * gR(0, 1) + x * gR(0, 2) + w * gR(1, 0) - 2 * z * gR(1, 1) +
              y * gR(1, 2) + x * gR(2, 0) + y * gR(2, 1));
  return g;
}

// Adds to cam (rho, omega) the gradient of a camera-frame pose perturbation
// x_cam' = exp([omega]x) x_cam + rho through Gaussian i: through its
// camera-space centre pv (all of g_pv), through the rotation in T = J R
// (gR_direct = dL/dR, holding J), and through the camera centre that the
// view direction of its colour starts from (centre' = centre - R^T rho).
void add_camera_gradient(const ProjectionView& v, const Vec3& pv, const Vec3& g_pv,
                         const Mat3& gR_direct, const Vec3& g_mean_color, double* cam) {
  const Vec3 g_rho = g_pv + v.R * g_mean_color;
  const Vec3 g_omega_center = pv.cross(g_pv);
  const Mat3 H = gR_direct * v.R.transpose();
  const Vec3 g_omega(H(2, 1) - H(1, 2), H(0, 2) - H(2, 0), H(1, 0) - H(0, 1));
  for (int k = 0; k < 3; ++k) {
    cam[k] += g_rho[k];
    cam[3 + k] += g_omega_center[k] + g_omega[k];
  }
}

// The colour's gradients: the SH coefficients' (written to g) and, through
// the view direction, the mean's (returned).
Vec3 backward_color(const GaussianModel& m, const ProjectionView& v, const RenderSettings& s,
                    const ProjectedGaussians& p, const ProjectedGradients& pg, size_t i,
                    const Vec3& mean, GaussianGradients& g) {
  const Vec3 d = mean - v.center;
  const float dlen = d.norm();
  const Vec3 dir = d / dlen;
  float gc[3];
  for (int c = 0; c < 3; ++c) gc[c] = p.color_clamped[3 * i + c] ? 0.f : pg.color[3 * i + c];
  // Coefficient by coefficient, in memory order; each one's colour weighted
  // by its gradient (summed over the channels) moves the view direction.
  float* g_rest = &g.sh_rest[kShRestFloats * i];
  const float* rest = &m.sh_rest[kShRestFloats * i];
  Vec3 g_dir = Vec3::Zero();
  for_each_sh_basis(s.sh_degree, dir.x(), dir.y(), dir.z(),
                    [&](int k, float b, float db_dx, float db_dy, float db_dz) {
                      if (k == 0) {
                        for (int c = 0; c < 3; ++c) g.sh_dc[3 * i + c] = b * gc[c];
                        return;
                      }
                      float weighted = 0.f;
                      for (int c = 0; c < 3; ++c) {
                        g_rest[3 * (k - 1) + c] = b * gc[c];
                        weighted += rest[3 * (k - 1) + c] * gc[c];
                      }
                      g_dir[0] += db_dx * weighted;
                      g_dir[1] += db_dy * weighted;
                      g_dir[2] += db_dz * weighted;
                    });
  const int n = (s.sh_degree + 1) * (s.sh_degree + 1);
  // The bands above the active degree get no gradient.
  std::fill(g_rest + 3 * (n - 1), g_rest + kShRestFloats, 0.f);
  return (g_dir - dir * dir.dot(g_dir)) / dlen;
}

void backward_one(const GaussianModel& m, const ProjectionView& v, const RenderSettings& s,
                  const ProjectedGaussians& p, const ProjectedGradients& pg, size_t i,
                  GaussianGradients& g, double* cam) {
  // cam: the camera's gradient (6 values) that this Gaussian adds to.
  const Vec3 mean(m.means[3 * i], m.means[3 * i + 1], m.means[3 * i + 2]);
  const Vec3 pv = v.R * mean + v.t;
  const float x = pv.x(), y = pv.y(), z = pv.z();
  Vec3 g_pv(0, 0, pg.depth[i]);

  // 2D mean: u = fx x / z + cx, v = fy y / z + cy.
  const float gu = pg.mean2d[2 * i], gw = pg.mean2d[2 * i + 1];
  g_pv.x() += gu * v.fx / z;
  g_pv.y() += gw * v.fy / z;
  g_pv.z() += -gu * v.fx * x / (z * z) - gw * v.fy * y / (z * z);

  // Conic (inverse of the low-passed 2D covariance) -> 2D covariance.
  const float A = p.conic[3 * i], B = p.conic[3 * i + 1], C = p.conic[3 * i + 2];
  Eigen::Matrix2f Q, gQ;
  Q << A, B, B, C;
  gQ << pg.conic[3 * i], 0.5f * pg.conic[3 * i + 1], 0.5f * pg.conic[3 * i + 1],
      pg.conic[3 * i + 2];
  const Eigen::Matrix2f gCov = -Q * gQ * Q;  // symmetric

  // 2D covariance = T Sigma T^T with T = J W.
  Mat3 Rq;
  Vec3 s_vec;
  const Mat3 M = scaled_rotation(m, i, Rq, s_vec);
  const Mat3 Sigma = M * M.transpose();
  const Mat23 J = projection_jacobian(v, pv);
  const Mat23 T = J * v.R;
  const Mat3 gSigma = T.transpose() * gCov * T;
  const Mat23 gT = 2.f * gCov * T * Sigma;
  const Mat23 gJ = gT * v.R.transpose();

  // Jacobian entries -> camera-space point, exact through the clamp.
  const float u_raw = x / z, w_raw = y / z;
  const float uc = std::clamp(u_raw, -v.lim_x, v.lim_x);
  const float wc = std::clamp(w_raw, -v.lim_y, v.lim_y);
  const float g_uc = -gJ(0, 2) * v.fx / z;
  const float g_wc = -gJ(1, 2) * v.fy / z;
  g_pv.z() += -gJ(0, 0) * v.fx / (z * z) + gJ(0, 2) * v.fx * uc / (z * z) -
              gJ(1, 1) * v.fy / (z * z) + gJ(1, 2) * v.fy * wc / (z * z);
  if (u_raw > -v.lim_x && u_raw < v.lim_x) {
    g_pv.x() += g_uc / z;
    g_pv.z() += -g_uc * x / (z * z);
  }
  if (w_raw > -v.lim_y && w_raw < v.lim_y) {
    g_pv.y() += g_wc / z;
    g_pv.z() += -g_wc * y / (z * z);
  }
  Vec3 g_mean = v.R.transpose() * g_pv;

  // Sigma = M M^T, M = R diag(s).
  const Mat3 gM = (gSigma + gSigma.transpose()) * M;
  for (int k = 0; k < 3; ++k) g.log_scales[3 * i + k] = gM.col(k).dot(Rq.col(k)) * s_vec[k];
  const Mat3 gR = gM * s_vec.asDiagonal();
  const Eigen::Map<const Eigen::Vector4f> q(&m.rotations[4 * i]);
  const float qlen = q.norm();
  const Eigen::Vector4f qn = q / qlen;
  const Eigen::Vector4f gqn = quaternion_matrix_backward(qn, gR);
  const Eigen::Vector4f gq = (gqn - qn * qn.dot(gqn)) / qlen;
  for (int k = 0; k < 4; ++k) g.rotations[4 * i + k] = gq[k];

  const Vec3 g_mean_color = s.color ? backward_color(m, v, s, p, pg, i, mean, g) : Vec3::Zero();
  g_mean += g_mean_color;
  for (int k = 0; k < 3; ++k) g.means[3 * i + k] = g_mean[k];
  add_camera_gradient(v, pv, g_pv, J.transpose() * gT, g_mean_color, cam);
  backward_opacities(p, pg, i, g);
}

}  // namespace

void project_gaussians_backward_one_by_one(const GaussianModel& m, const Camera& cam,
                                           const RenderSettings& s, const ProjectedGaussians& p,
                                           const ProjectedGradients& pg, GaussianGradients& g) {
  const size_t n = m.size();
  const ProjectionView v(cam);
  const float half_w = 0.5f * cam.width, half_h = 0.5f * cam.height;
  // The camera's sum per fixed chunk, then over the chunks in order, so
  // that it does not depend on the thread schedule.
  constexpr size_t kChunk = 4096;
  const size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::array<double, 6>> cam_partial(chunks);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, chunks, 1),
      [&](const auto& range) {
        for (size_t c = range.begin(); c < range.end(); ++c) {
          double* cam_sum = cam_partial[c].data();
          for (size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
            zero_gradients(g, i);
            if (!p.visible(i)) continue;
            mark_visible(pg, i, half_w, half_h, g);
            backward_one(m, v, s, p, pg, i, g, cam_sum);
          }
        }
      },
      tbb::simple_partitioner());
  for (const auto& partial : cam_partial)
    for (int k = 0; k < 6; ++k) g.camera[k] += partial[k];
}

}  // namespace splat
