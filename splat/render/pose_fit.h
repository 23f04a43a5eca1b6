#pragma once
// Camera pose refinement through the renderer: learned corrections of the
// views' poses (stage one's --refine-poses, as BARF and gsplat's pose
// optimisation do) and the fit of one camera to its photo with the model
// held fixed (the test views' poses, which training never sees).
//
// A correction moves the camera in its own frame (moved_in_camera_frame):
// x_cam' = exp([omega]x) x_cam + rho. Its gradient is the renderer's
// GaussianGradients::camera at the corrected camera, and Adam steps in that
// tangent space, each step composed onto the correction.

#include <array>
#include <cstdint>
#include <iosfwd>
#include <vector>

#include "splat/camera.h"
#include "splat/gaussians.h"
#include "splat/image.h"
#include "splat/render/renderer.h"

namespace splat {

// Step sizes: radians for the rotation, scene units for the translation.
struct PoseStep {
  float rotation = 0;
  float translation = 0;
};

class ViewPoseCorrections {
 public:
  ViewPoseCorrections() = default;
  explicit ViewPoseCorrections(size_t views);  // all zero
  size_t size() const { return rho_.size(); }

  Camera apply(size_t view, const Camera& camera) const;
  // One Adam step on the view's correction, given dLoss/d(rho, omega) at the
  // corrected camera.
  void step(size_t view, const std::array<double, 6>& gradient, PoseStep lr);

  // The correction's size: rotation angle (radians) and translation length.
  double angle(size_t view) const;
  double distance(size_t view) const;

  void save(std::ostream& out) const;
  void load(std::istream& in);  // throws std::runtime_error on a malformed stream

 private:
  std::vector<std::array<double, 3>> rho_, omega_;
  std::vector<std::array<double, 6>> m_, v_;
  std::vector<uint32_t> steps_;
};

struct PoseFitOptions {
  int iterations = 0;            // 0: no fit
  float lr_rotation = 1e-3f;     // radians, decaying tenfold over the fit
  float lr_translation = 1e-3f;  // times the scene extent, likewise

  void Check() const;  // throws std::invalid_argument with a one-line message
};

// The camera moved so that the model's render matches the photo best (L1 of
// the colours), starting from `camera`. settings are those of the render
// (background, SH degree); the instance branch is not rendered.
Camera fit_camera_to_photo(const Renderer& renderer, const GaussianModel& model,
                           const Camera& camera, const ImageRGB& photo, RenderSettings settings,
                           double scene_extent, const PoseFitOptions& options);

}  // namespace splat
