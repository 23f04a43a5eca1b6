#include "splat/camera_distortion.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace splat {
namespace {

// COLMAP's model IDs (splat/colmap_model.cc).
enum Model {
  kSimplePinhole = 0,
  kPinhole = 1,
  kSimpleRadial = 2,
  kRadial = 3,
  kOpenCv = 4,
  kOpenCvFisheye = 5,
  kFullOpenCv = 6,
  kSimpleRadialFisheye = 8,
  kRadialFisheye = 9,
};

// Models with one focal length list f, cx, cy first; the others fx, fy, cx, cy.
bool has_single_focal(int model) {
  return model == kSimplePinhole || model == kSimpleRadial || model == kRadial ||
         model == kSimpleRadialFisheye || model == kRadialFisheye;
}

struct Intrinsics {
  double fx, fy, cx, cy;
  const double* k;  // the distortion parameters after them
};

Intrinsics intrinsics_of(const ColmapCamera& c) {
  const auto info = camera_model_by_id(c.model_id);
  if (!info || c.params.size() != size_t(info->num_params))
    throw std::invalid_argument(fmt::format("camera {} has model {} with {} parameters",
                                            c.camera_id, c.model_id, c.params.size()));
  const double* p = c.params.data();
  if (has_single_focal(c.model_id)) return {p[0], p[0], p[1], p[2], p + 3};
  return {p[0], p[1], p[2], p[3], p + 4};
}

// Undistorted normalised (u, v) to distorted normalised coordinates.
Eigen::Vector2d distort(int model, const double* k, double u, double v) {
  const double u2 = u * u, v2 = v * v, uv = u * v, r2 = u2 + v2;
  switch (model) {
    case kSimplePinhole:
    case kPinhole:
      return {u, v};
    case kSimpleRadial: {
      const double s = 1 + k[0] * r2;
      return {u * s, v * s};
    }
    case kRadial: {
      const double s = 1 + k[0] * r2 + k[1] * r2 * r2;
      return {u * s, v * s};
    }
    case kOpenCv: {
      const double s = 1 + k[0] * r2 + k[1] * r2 * r2;
      return {u * s + 2 * k[2] * uv + k[3] * (r2 + 2 * u2),
              v * s + 2 * k[3] * uv + k[2] * (r2 + 2 * v2)};
    }
    case kFullOpenCv: {
      const double r4 = r2 * r2, r6 = r4 * r2;
      const double s =
          (1 + k[0] * r2 + k[1] * r4 + k[4] * r6) / (1 + k[5] * r2 + k[6] * r4 + k[7] * r6);
      return {u * s + 2 * k[2] * uv + k[3] * (r2 + 2 * u2),
              v * s + 2 * k[3] * uv + k[2] * (r2 + 2 * v2)};
    }
    case kOpenCvFisheye:
    case kSimpleRadialFisheye:
    case kRadialFisheye: {
      const double r = std::sqrt(r2);
      if (r < 1e-12) return {u, v};
      const double t = std::atan(r), t2 = t * t;
      double poly = 1;
      if (model == kOpenCvFisheye)
        poly += t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])));
      else if (model == kSimpleRadialFisheye)
        poly += k[0] * t2;
      else
        poly += t2 * (k[0] + t2 * k[1]);
      const double s = t * poly / r;
      return {u * s, v * s};
    }
    default:
      throw std::invalid_argument(fmt::format(
          "camera model {} has no closed-form distortion: undistort the ID maps yourself, or "
          "run SfM with --camera-model OPENCV",
          camera_model_by_id(model) ? camera_model_by_id(model)->name : std::to_string(model)));
  }
}

// Pixel positions of the undistorted pinhole view to the distorted view, with
// both cameras' parameters looked up once rather than for every pixel.
class PinholeToDistorted {
 public:
  PinholeToDistorted(const ColmapCamera& distorted, const ColmapCamera& pinhole)
      : model_(distorted.model_id), p_(intrinsics_of(pinhole)), d_(intrinsics_of(distorted)) {
    (*this)(0, 0);  // throws here for a model without a closed-form distortion
  }

  Eigen::Vector2d operator()(double x, double y) const {
    const Eigen::Vector2d n = distort(model_, d_.k, (x - p_.cx) / p_.fx, (y - p_.cy) / p_.fy);
    return {d_.fx * n.x() + d_.cx, d_.fy * n.y() + d_.cy};
  }

  // The inverse: the pinhole position that maps to the distorted position
  // (x, y), by Newton's method with a numerical Jacobian, as COLMAP
  // undistorts points. NaN where it does not converge (outside the region in
  // which the distortion is invertible).
  Eigen::Vector2d inverse(double x, double y) const {
    const Eigen::Vector2d target(x, y);
    // The start: the same normalised position in the pinhole camera.
    Eigen::Vector2d q(p_.fx * (x - d_.cx) / d_.fx + p_.cx, p_.fy * (y - d_.cy) / d_.fy + p_.cy);
    constexpr double kStep = 1e-3;  // pixels, for the Jacobian's differences
    for (int iteration = 0; iteration < 50; ++iteration) {
      const Eigen::Vector2d residual = (*this)(q.x(), q.y()) - target;
      if (residual.squaredNorm() < 1e-12) return q;
      Eigen::Matrix2d jacobian;
      jacobian.col(0) =
          ((*this)(q.x() + kStep, q.y()) - (*this)(q.x() - kStep, q.y())) / (2 * kStep);
      jacobian.col(1) =
          ((*this)(q.x(), q.y() + kStep) - (*this)(q.x(), q.y() - kStep)) / (2 * kStep);
      if (std::abs(jacobian.determinant()) < 1e-12) break;
      q -= jacobian.inverse() * residual;
      if (!q.allFinite()) break;
    }
    return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  }

 private:
  int model_;
  Intrinsics p_, d_;
};

}  // namespace

Eigen::Vector2d distorted_position(const ColmapCamera& distorted, const ColmapCamera& pinhole,
                                   double x, double y) {
  return PinholeToDistorted(distorted, pinhole)(x, y);
}

Eigen::Vector2d undistorted_position(const ColmapCamera& distorted, const ColmapCamera& pinhole,
                                     double x, double y) {
  return PinholeToDistorted(distorted, pinhole).inverse(x, y);
}

std::vector<int64_t> photo_pixel_sources(const ColmapCamera& distorted, const ColmapCamera& pinhole,
                                         int source_width, int source_height) {
  if (pinhole.model_id != kSimplePinhole && pinhole.model_id != kPinhole)
    throw std::invalid_argument("photo_pixel_sources: the source camera must be a pinhole");
  const PinholeToDistorted to_distorted(distorted, pinhole);
  const int W = int(distorted.width), H = int(distorted.height);
  const double sx = double(source_width) / double(pinhole.width);
  const double sy = double(source_height) / double(pinhole.height);
  std::vector<int64_t> sources(size_t(W) * H, -1);
  tbb::parallel_for(0, H, [&](int y) {
    for (int x = 0; x < W; ++x) {
      const Eigen::Vector2d q = to_distorted.inverse(x + 0.5, y + 0.5);
      const double mx = std::floor(q.x() * sx), my = std::floor(q.y() * sy);
      if (mx >= 0 && my >= 0 && mx < source_width && my < source_height)  // false for NaN
        sources[size_t(y) * W + x] = int64_t(my) * source_width + int64_t(mx);
    }
  });
  return sources;
}

IdMap undistort_id_map(const IdMap& map, const ColmapCamera& distorted,
                       const ColmapCamera& pinhole) {
  if (pinhole.model_id != kSimplePinhole && pinhole.model_id != kPinhole)
    throw std::invalid_argument("undistort_id_map: the target camera must be a pinhole");
  const PinholeToDistorted to_distorted(distorted, pinhole);
  const int W = int(pinhole.width), H = int(pinhole.height);
  // The map may be smaller or larger than the photos SAM2 ran on.
  const double sx = double(map.width) / double(distorted.width);
  const double sy = double(map.height) / double(distorted.height);
  IdMap out(W, H);
  tbb::parallel_for(0, H, [&](int y) {
    for (int x = 0; x < W; ++x) {
      const Eigen::Vector2d s = to_distorted(x + 0.5, y + 0.5);
      const double mx = std::floor(s.x() * sx), my = std::floor(s.y() * sy);
      if (mx >= 0 && my >= 0 && mx < map.width && my < map.height)
        out.ids[size_t(y) * W + x] = map.ids[size_t(my) * map.width + size_t(mx)];
    }
  });
  return out;
}

}  // namespace splat
