#include "splat/train/adam.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <istream>
#include <ostream>
#include <stdexcept>

#include "splat/binary_io.h"

namespace splat {

const std::vector<float>& group_gradients(const GaussianGradients& g, ParamGroup group) {
  switch (group) {
    case ParamGroup::kMeans:
      return g.means;
    case ParamGroup::kShDc:
      return g.sh_dc;
    case ParamGroup::kShRest:
      return g.sh_rest;
    case ParamGroup::kOpacity:
      return g.opacity_logits;
    case ParamGroup::kScales:
      return g.log_scales;
    case ParamGroup::kRotations:
      return g.rotations;
    case ParamGroup::kInstanceOpacity:
      return g.instance_opacity_logits;
  }
  throw std::logic_error("bad group");
}

namespace {

using AdamStep = GaussianAdam::StepConstants;

// torch.optim.Adam's update of n values. Plain pointers that do not alias, so
// that the compiler vectorises it (the file is built with -fno-math-errno,
// which lets sqrt vectorise too). kZeroGradient: the same formulas with a
// gradient of +0, not read (the same results as with zeros read).
template <bool kZeroGradient = false>
void adam_update(float* __restrict p, const float* __restrict grad, float* __restrict m,
                 float* __restrict v, size_t n, const AdamStep& a) {
  for (size_t i = 0; i < n; ++i) {
    const float g = kZeroGradient ? 0.f : grad[i];
    const float mi = a.b1 * m[i] + (1 - a.b1) * g;
    const float vi = a.b2 * v[i] + (1 - a.b2) * g * g;
    m[i] = mi;
    v[i] = vi;
    p[i] -= a.step_size * mi / (std::sqrt(vi) * a.inv_bc2_sqrt + a.eps);
  }
}

// adam_update over n Gaussians of kWidth values each (its formulas written
// again: through a shared inline helper GCC no longer vectorises this loop),
// with the gradient of those out of view (visible[i] == 0) taken as +0,
// whatever it holds: the same results as adam_update<true> gives them; or,
// with kKeepCulled, those left unchanged. For groups of a few values
// a Gaussian: the Gaussians in view come in no order by index, about one in
// two late in training, and a branch or a call per run of them cost more
// than the step itself; reading the few unused gradients costs less.
template <int kWidth, bool kKeepCulled>
void adam_update_selected(float* __restrict p, const float* __restrict grad, float* __restrict m,
                          float* __restrict v, const uint8_t* __restrict visible, size_t n,
                          const AdamStep& a) {
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < kWidth; ++k) {
      const size_t j = kWidth * i + k;
      const float read = grad[j];  // loaded in any case, so that the loop vectorises
      const float g = visible[i] ? read : 0.f;
      const float mi = a.b1 * m[j] + (1 - a.b1) * g;
      const float vi = a.b2 * v[j] + (1 - a.b2) * g * g;
      const float pi = p[j] - a.step_size * mi / (std::sqrt(vi) * a.inv_bc2_sqrt + a.eps);
      const bool moves = !kKeepCulled || visible[i];
      m[j] = moves ? mi : m[j];
      v[j] = moves ? vi : v[j];
      p[j] = moves ? pi : p[j];
    }
  }
}

// Adam over Gaussians [begin, end) of a group whose Gaussians have `width`
// values, of which the first `active` move; the Gaussians out of view
// (visible[i] == 0; null: none) step with zero gradients, or not at all
// with keep_culled. Narrow groups go through adam_update_selected; the
// others by runs of Gaussians in view and out of view, the runs in view
// reading their gradients.
void adam_over_gaussians(float* p, const float* grad, float* m, float* v, size_t width,
                         size_t active, const uint8_t* visible, bool keep_culled, size_t begin,
                         size_t end, const AdamStep& a) {
  if (visible && active == width && width <= 4) {
    const size_t at = width * begin, n = end - begin;
    auto selected = [&]<int kWidth>() {
      const auto update =
          keep_culled ? adam_update_selected<kWidth, true> : adam_update_selected<kWidth, false>;
      update(&p[at], &grad[at], &m[at], &v[at], &visible[begin], n, a);
    };
    switch (width) {
      case 1:
        return selected.template operator()<1>();
      case 3:
        return selected.template operator()<3>();
      case 4:
        return selected.template operator()<4>();
      default:
        break;
    }
  }
  for (size_t i = begin; i < end;) {
    const bool in_view = !visible || visible[i];
    size_t run_end = visible ? i + 1 : end;
    while (run_end < end && bool(visible[run_end]) == in_view) ++run_end;
    if (!in_view && keep_culled) {
      i = run_end;
      continue;
    }
    const auto update = in_view ? adam_update<false> : adam_update<true>;
    if (active == width) {
      const size_t at = width * i;
      update(&p[at], &grad[at], &m[at], &v[at], width * (run_end - i), a);
    } else {
      for (size_t k = i; k < run_end; ++k) {
        const size_t at = width * k;
        update(&p[at], &grad[at], &m[at], &v[at], active, a);
      }
    }
    i = run_end;
  }
}

// The SH rest's values of a Gaussian that can move at this SH degree.
size_t sh_rest_active(int active_sh_degree) {
  return size_t(3 * ((active_sh_degree + 1) * (active_sh_degree + 1) - 1));
}

}  // namespace

GaussianAdam::StepConstants GaussianAdam::count_step(ParamGroup g, float lr) {
  State& s = state_[int(g)];
  ++s.step;
  const double bc1 = 1 - std::pow(double(options_.beta1), double(s.step));
  const double bc2_sqrt = std::sqrt(1 - std::pow(double(options_.beta2), double(s.step)));
  return {options_.beta1, options_.beta2, float(lr / bc1), float(1 / bc2_sqrt), options_.eps};
}

GaussianAdam::ShRestStep GaussianAdam::begin_sh_rest_step(GaussianModel& model, float lr,
                                                          int active_sh_degree, Culled culled) {
  State& s = state_[int(ParamGroup::kShRest)];
  if (model.sh_rest.size() != s.m.size())
    throw std::logic_error("Adam: size mismatch in group sh_rest");
  return ShRestStep(model.sh_rest.data(), s.m.data(), s.v.data(), sh_rest_active(active_sh_degree),
                    culled == Culled::kKeep, count_step(ParamGroup::kShRest, lr));
}

// A Gaussian out of view steps with a zero gradient unless kept: with
// kReadGradients its gradient would be the renderer's zeros, the same bits.
void GaussianAdam::ShRestStep::take(size_t first, size_t count, const float* rows,
                                    uint32_t visible) {
  for (size_t l = 0; l < count; ++l) {
    const size_t at = size_t(kShRestFloats) * (first + l);
    if (visible >> l & 1)
      adam_update<false>(values_ + at, rows + size_t(kShRestFloats) * l, m_ + at, v_ + at, active_,
                         constants_);
    else if (!keep_culled_)
      adam_update<true>(values_ + at, nullptr, m_ + at, v_ + at, active_, constants_);
  }
}

GaussianAdam::GaussianAdam(size_t n, AdamOptions options) : options_(options) {
  size_ = 0;
  append(n);
}

void GaussianAdam::step(GaussianModel& model, const GaussianGradients& grads,
                        const std::array<float, kParamGroups>& lr,
                        const std::array<bool, kParamGroups>& skip, int active_sh_degree,
                        Culled culled) {
  const uint8_t* visible = culled == Culled::kReadGradients ? nullptr : grads.visible.data();
  const bool keep_culled = culled == Culled::kKeep;
  for (int gi = 0; gi < kParamGroups; ++gi) {
    if (skip[gi] || lr[gi] <= 0) continue;
    const ParamGroup g = ParamGroup(gi);
    State& s = state_[gi];
    std::vector<float>& p = group_values(model, g);
    const std::vector<float>& grad = group_gradients(grads, g);
    if (p.size() != s.m.size() || grad.size() != p.size() ||
        (visible && grads.visible.size() != size_))
      throw std::logic_error(std::string("Adam: size mismatch in group ") + group_name(g));
    const AdamStep a = count_step(g, lr[gi]);
    const size_t width = size_t(group_width(g));
    // Values of each Gaussian that can move: all, or the active SH bands.
    const size_t active = g == ParamGroup::kShRest ? sh_rest_active(active_sh_degree) : width;
    // About 64k values a task, whatever the group's width.
    const size_t grain = std::max<size_t>(1, (size_t(1) << 16) / width);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, size_, grain), [&](const auto& r) {
      adam_over_gaussians(p.data(), grad.data(), s.m.data(), s.v.data(), width, active, visible,
                          keep_culled, r.begin(), r.end(), a);
    });
  }
}

void GaussianAdam::append(size_t count) {
  size_ += count;
  for (int gi = 0; gi < kParamGroups; ++gi) {
    const size_t w = size_t(group_width(ParamGroup(gi)));
    state_[gi].m.resize(w * size_, 0.f);
    state_[gi].v.resize(w * size_, 0.f);
  }
}

void GaussianAdam::keep(const std::vector<uint8_t>& keep) {
  if (keep.size() != size_) throw std::logic_error("Adam::keep: size mismatch");
  for (int gi = 0; gi < kParamGroups; ++gi) {
    const size_t w = size_t(group_width(ParamGroup(gi)));
    State& s = state_[gi];
    size_t out = 0;
    for (size_t i = 0; i < size_; ++i) {
      if (!keep[i]) continue;
      for (size_t k = 0; k < w; ++k) {
        s.m[w * out + k] = s.m[w * i + k];
        s.v[w * out + k] = s.v[w * i + k];
      }
      ++out;
    }
    s.m.resize(w * out);
    s.v.resize(w * out);
  }
  size_t kept = 0;
  for (uint8_t k : keep) kept += k != 0;
  size_ = kept;
}

void GaussianAdam::reset_moments(ParamGroup g) {
  State& s = state_[int(g)];
  std::fill(s.m.begin(), s.m.end(), 0.f);
  std::fill(s.v.begin(), s.v.end(), 0.f);
}

void GaussianAdam::save(std::ostream& out) const {
  write_pod(out, uint64_t(size_));
  for (const State& s : state_) {
    write_pod(out, s.step);
    write_vector(out, s.m);
    write_vector(out, s.v);
  }
}

void GaussianAdam::load(std::istream& in) {
  size_ = size_t(read_pod<uint64_t>(in));
  for (State& s : state_) {
    s.step = read_pod<int64_t>(in);
    s.m = read_vector<float>(in);
    s.v = read_vector<float>(in);
  }
}

}  // namespace splat
