#pragma once
// What project.cc and project_backward.cc share: the camera's constants that
// every Gaussian's projection needs, and the size of their batches. (The
// covariance and Jacobian algebra is written out in each direction's batch
// loop: moved into shared inline functions returning structs, it kept GCC
// from vectorising the forward loop.)

#include <Eigen/Core>

#include "splat/camera.h"
#include "splat/render/render_types.h"

namespace splat {

// Gaussians are projected (and sent back) kProjectionBatch at a time, as the
// lanes of the vector loops.
inline constexpr int kProjectionBatch = 16;

// The per-camera constants every Gaussian needs.
struct ProjectionView {
  Eigen::Matrix3f R;
  Eigen::Vector3f t, center;
  float fx, fy, cx, cy, lim_x, lim_y;
  explicit ProjectionView(const Camera& c)
      : R(c.R.cast<float>()),
        t(c.t.cast<float>()),
        center(c.center().cast<float>()),
        fx(float(c.fx)),
        fy(float(c.fy)),
        cx(float(c.cx)),
        cy(float(c.cy)),
        lim_x(kFovClamp * float(c.tan_half_fov_x())),
        lim_y(kFovClamp * float(c.tan_half_fov_y())) {}
};

}  // namespace splat
