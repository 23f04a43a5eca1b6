#pragma once
// The backward pass of the projection one Gaussian at a time, in plain
// scalar algebra (Eigen's 3x3 matrices), as gsplat keeps its reference
// apart from its kernels. It is the reference that the batched pass
// (project_backward.cc) is tested against, and the pass that also sums the
// gradient of the camera's pose (BackwardSettings::camera_gradient, for pose
// refinement), which the batches do not. Internal to splat/render/.

#include "splat/camera.h"
#include "splat/gaussians.h"
#include "splat/render/project.h"
#include "splat/render/render_types.h"

namespace splat {

// As project_gaussians_backward, with `grads` resized and grads.camera
// zeroed by the caller; adds the camera's gradient to grads.camera.
void project_gaussians_backward_one_by_one(const GaussianModel& model, const Camera& camera,
                                           const RenderSettings& settings,
                                           const ProjectedGaussians& proj,
                                           const ProjectedGradients& pgrads,
                                           GaussianGradients& grads);

}  // namespace splat
