#pragma once
// Adam over the Gaussian parameter groups, as torch.optim.Adam computes it
// (the reference 3DGS optimiser): per group a step count and first and second
// moments per value, bias correction, eps = 1e-15. Groups can grow, shrink
// and be reset when densification changes the set of Gaussians.

#include <array>
#include <cstdint>
#include <iosfwd>
#include <vector>

#include "splat/gaussians.h"
#include "splat/render/render_types.h"

namespace splat {

// The gradients' array of a parameter group (the model's: group_values).
const std::vector<float>& group_gradients(const GaussianGradients& g, ParamGroup group);

struct AdamOptions {
  float beta1 = 0.9f;
  float beta2 = 0.999f;
  float eps = 1e-15f;
  bool operator==(const AdamOptions&) const = default;
};

class GaussianAdam {
 public:
  explicit GaussianAdam(size_t num_gaussians, AdamOptions options = {});

  // What a step does to the Gaussians out of view (grads.visible == 0).
  enum class Culled {
    // They step with the gradient as written (zeros, for the renderer's
    // BackwardSettings::zero_culled_gradients).
    kReadGradients,
    // They step with a zero gradient without it being read (the renderer
    // may leave it unwritten): the same step to the bit as kReadGradients
    // with zeros. The reference recipe: its moments decay and momentum
    // keeps moving them.
    kZeroGradients,
    // They do not step: values and moments stay as they are (sparse Adam, as
    // gsplat's and Taming 3DGS's selective Adam), so a step touches only the
    // Gaussians in view. Not the reference's results.
    kKeep,
  };

  // One Adam step of every group whose learning rate is given (> 0 or not
  // skipped); groups in `skip` keep their values and step count (as torch
  // skips parameters without a gradient).
  // With active_sh_degree < 3, the SH coefficients above it are left alone:
  // their gradients and moments are zero, so Adam would not move them anyway.
  void step(GaussianModel& model, const GaussianGradients& grads,
            const std::array<float, kParamGroups>& learning_rates,
            const std::array<bool, kParamGroups>& skip = {}, int active_sh_degree = kMaxShDegree,
            Culled culled = Culled::kReadGradients);

  // The SH rest's step taken inside the renderer's backward pass, a batch
  // of Gaussians at a time as their gradients are made
  // (BackwardSettings::sh_rest_sink): the same step to the bit as step()
  // gives the group, without its pass over memory. begin_sh_rest_step counts
  // the group's step; the caller then skips the group in step(). The model
  // must outlive it and not change size meanwhile.
  class ShRestStep;
  ShRestStep begin_sh_rest_step(GaussianModel& model, float learning_rate, int active_sh_degree,
                                Culled culled);

  // Densification: new Gaussians appended with zero moments; removal keeps
  // the Gaussians with keep[i] != 0 in order.
  void append(size_t count);
  void keep(const std::vector<uint8_t>& keep);
  // Zero a group's moments (opacity reset); its step count stays.
  void reset_moments(ParamGroup g);

  size_t size() const { return size_; }
  int64_t steps(ParamGroup g) const { return state_[int(g)].step; }

  void save(std::ostream& out) const;
  void load(std::istream& in);
  bool operator==(const GaussianAdam&) const = default;

  // The constants of one group's step.
  struct StepConstants {
    float b1, b2, step_size, inv_bc2_sqrt, eps;
  };

 private:
  struct State {
    std::vector<float> m, v;
    int64_t step = 0;
    bool operator==(const State&) const = default;
  };
  // Counts group g's step; its constants at learning rate lr.
  StepConstants count_step(ParamGroup g, float lr);

  AdamOptions options_;
  size_t size_ = 0;
  std::array<State, kParamGroups> state_;
};

class GaussianAdam::ShRestStep final : public ShRestGradientSink {
 public:
  void take(size_t first, size_t count, const float* rows, uint32_t visible) override;

 private:
  friend class GaussianAdam;
  ShRestStep(float* values, float* m, float* v, size_t active, bool keep_culled,
             StepConstants constants)
      : values_(values),
        m_(m),
        v_(v),
        active_(active),
        keep_culled_(keep_culled),
        constants_(constants) {}
  float *values_, *m_, *v_;
  size_t active_;  // values of a Gaussian that move: the active SH bands'
  bool keep_culled_;
  StepConstants constants_;
};

}  // namespace splat
