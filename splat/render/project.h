#pragma once
// Step 1 of rendering: project every Gaussian into the image (EWA splatting).
// Produces, per Gaussian, the 2D mean, the conic (inverse 2D covariance), the
// camera depth, the screen radius and tile rectangle, the view-dependent
// colour and the activated opacities. Culled Gaussians get radius 0.

#include <cstdint>
#include <vector>

#include "splat/camera.h"
#include "splat/gaussians.h"
#include "splat/render/render_types.h"

namespace splat {

struct ProjectedGaussians {
  std::vector<float> mean2d;    // 2N, pixel coordinates (pixel centres at +0.5)
  std::vector<float> conic;     // 3N, A B C: power = -0.5 (A dx^2 + 2 B dx dy + C dy^2)
  std::vector<float> depth;     // N, camera z
  std::vector<int32_t> radius;  // N, ceil(3 sqrt(largest eigenvalue)); 0 = culled
  // Tiles [x0, x1) x [y0, y1): the reference's radius rectangle, narrowed to
  // the tiles where alpha can reach 1/255 (which changes no pixel).
  std::vector<int32_t> tile_rect;  // 4N
  // Half-extents (pixels) of the ellipse outside which sigma G < 1/255, with
  // a small margin: no pixel outside it is touched.
  std::vector<float> reach;             // 2N
  std::vector<float> color;             // 3N, empty when settings.color is false
  std::vector<uint8_t> color_clamped;   // 3N, 1 where the colour was clamped at 0
  std::vector<float> opacity;           // N, sigma
  std::vector<float> instance_opacity;  // N, sigma* (sigma when the model has none)
  int tiles_x = 0, tiles_y = 0;

  size_t size() const { return depth.size(); }
  bool visible(size_t i) const { return radius[i] > 0; }
};

void project_gaussians(const GaussianModel& model, const Camera& camera,
                       const RenderSettings& settings, ProjectedGaussians& out);

// dLoss/d(projected quantities), accumulated by the rasterizer's backward
// pass for the visible Gaussians; the culled ones' values are left as they
// were, not cleared (36 bytes of every Gaussian a view, when late in
// training more than half of them are culled in any one view).
struct ProjectedGradients {
  std::vector<float> mean2d;            // 2N, per pixel unit
  std::vector<float> conic;             // 3N
  std::vector<float> depth;             // N
  std::vector<float> color;             // 3N
  std::vector<float> opacity;           // N, w.r.t. sigma
  std::vector<float> instance_opacity;  // N, w.r.t. sigma*
  void resize(size_t n);                // new values 0, the others kept
};

// Chains the projected gradients back to the model parameters. Writes every
// field of `grads` (resized to the model).
void project_gaussians_backward(const GaussianModel& model, const Camera& camera,
                                const RenderSettings& settings,
                                const BackwardSettings& backward_settings,
                                const ProjectedGaussians& proj, const ProjectedGradients& pgrads,
                                GaussianGradients& grads);

}  // namespace splat
