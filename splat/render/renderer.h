#pragma once
// The differentiable renderer's interface. The CPU backend is the reference
// every other backend (CUDA, later) is tested against; a backend keeps what
// its backward pass needs in a RenderState of its own.
//
//   CpuRenderer renderer;
//   std::unique_ptr<RenderState> state;
//   RenderOutput out = renderer.render(model, camera, settings, &state);
//   ... loss and its gradients w.r.t. out ...
//   GaussianGradients g = renderer.backward(model, camera, settings, *state, grads);

#include <memory>

#include "splat/camera.h"
#include "splat/gaussians.h"
#include "splat/render/render_types.h"

namespace splat {

class RenderState {
 public:
  virtual ~RenderState() = default;
};

class Renderer {
 public:
  virtual ~Renderer() = default;

  // Renders one view. When state is given, it receives what backward needs.
  // Throws std::invalid_argument for bad settings (SH degree, repeated labels).
  virtual RenderOutput render(const GaussianModel& model, const Camera& camera,
                              const RenderSettings& settings,
                              std::unique_ptr<RenderState>* state = nullptr) const = 0;

  // Gradients of the loss w.r.t. every Gaussian parameter, given the
  // gradients w.r.t. the outputs of the render that produced state.
  virtual GaussianGradients backward(const GaussianModel& model, const Camera& camera,
                                     const RenderSettings& settings, const RenderState& state,
                                     const RenderOutputGradients& grads) const = 0;
};

class CpuRenderer : public Renderer {
 public:
  RenderOutput render(const GaussianModel& model, const Camera& camera,
                      const RenderSettings& settings,
                      std::unique_ptr<RenderState>* state = nullptr) const override;
  GaussianGradients backward(const GaussianModel& model, const Camera& camera,
                             const RenderSettings& settings, const RenderState& state,
                             const RenderOutputGradients& grads) const override;
};

}  // namespace splat
