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
//
// What only the backward pass reads (pose gradients, vote protection, culled
// Gaussians left unwritten) is in BackwardSettings, not RenderSettings.

#include <memory>

#include "splat/camera.h"
#include "splat/gaussians.h"
#include "splat/render/render_types.h"

namespace splat {

class RenderState {
 public:
  virtual ~RenderState() = default;
  // Memory held for the backward pass, in bytes.
  virtual size_t bytes() const = 0;
  // Memory the backward pass allocates on top of it, in bytes.
  virtual size_t backward_bytes() const = 0;
};

class Renderer {
 public:
  virtual ~Renderer() = default;

  // Renders one view into out. When state is given, it receives what
  // backward needs; a state (and an out) from an earlier call is reused, so a
  // training loop allocates nothing after its first iteration.
  // Throws std::invalid_argument for bad settings (SH degree, repeated labels).
  virtual void render(const GaussianModel& model, const Camera& camera,
                      const RenderSettings& settings, RenderOutput& out,
                      std::unique_ptr<RenderState>* state = nullptr) const = 0;

  // Gradients of the loss w.r.t. every Gaussian parameter, given the
  // gradients w.r.t. the outputs of the render (with `settings`) that
  // produced state. out's buffers are reused.
  // Throws std::invalid_argument for bad backward settings.
  virtual void backward(const GaussianModel& model, const Camera& camera,
                        const RenderSettings& settings, const BackwardSettings& backward_settings,
                        RenderState& state, const RenderOutputGradients& grads,
                        GaussianGradients& out) const = 0;

  // Conveniences that return fresh outputs.
  RenderOutput render(const GaussianModel& model, const Camera& camera,
                      const RenderSettings& settings,
                      std::unique_ptr<RenderState>* state = nullptr) const {
    RenderOutput out;
    render(model, camera, settings, out, state);
    return out;
  }
  GaussianGradients backward(const GaussianModel& model, const Camera& camera,
                             const RenderSettings& settings,
                             const BackwardSettings& backward_settings, RenderState& state,
                             const RenderOutputGradients& grads) const {
    GaussianGradients out;
    backward(model, camera, settings, backward_settings, state, grads, out);
    return out;
  }
  // With the default backward settings.
  void backward(const GaussianModel& model, const Camera& camera, const RenderSettings& settings,
                RenderState& state, const RenderOutputGradients& grads,
                GaussianGradients& out) const {
    backward(model, camera, settings, BackwardSettings{}, state, grads, out);
  }
  GaussianGradients backward(const GaussianModel& model, const Camera& camera,
                             const RenderSettings& settings, RenderState& state,
                             const RenderOutputGradients& grads) const {
    return backward(model, camera, settings, BackwardSettings{}, state, grads);
  }
};

class CpuRenderer : public Renderer {
 public:
  using Renderer::backward;
  using Renderer::render;
  void render(const GaussianModel& model, const Camera& camera, const RenderSettings& settings,
              RenderOutput& out, std::unique_ptr<RenderState>* state = nullptr) const override;
  void backward(const GaussianModel& model, const Camera& camera, const RenderSettings& settings,
                const BackwardSettings& backward_settings, RenderState& state,
                const RenderOutputGradients& grads, GaussianGradients& out) const override;
};

}  // namespace splat
