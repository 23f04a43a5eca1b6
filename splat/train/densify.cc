#include "splat/train/densify.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "splat/binary_io.h"

namespace splat {

namespace {

// Appends a copy of Gaussian i (every parameter, label included).
void append_copy(GaussianModel& m, size_t i) {
  const size_t n = m.size();
  m.resize(n + 1);
  for (int g = 0; g < kParamGroups; ++g) {
    std::vector<float>& v = group_values(m, ParamGroup(g));
    const size_t w = size_t(group_width(ParamGroup(g)));
    std::copy_n(v.begin() + long(w * i), w, v.begin() + long(w * n));
  }
  m.labels[n] = m.labels[i];
}

float max_scale(const GaussianModel& m, size_t i) {
  return std::exp(
      std::max({m.log_scales[3 * i], m.log_scales[3 * i + 1], m.log_scales[3 * i + 2]}));
}

}  // namespace

void DensificationStats::reset(size_t n) {
  grad_accum.assign(n, 0.f);
  count.assign(n, 0.f);
  max_radius.assign(n, 0.f);
}

void DensificationStats::add(const GaussianGradients& g, const std::vector<int32_t>& radii,
                             std::array<float, 2> ndc_scale) {
  // Every iteration until densification ends, over every Gaussian: in
  // parallel, so that it does not become the serial part on many cores.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count.size(), 16384), [&](const auto& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      if (!g.visible[i]) continue;
      grad_accum[i] +=
          std::hypot(ndc_scale[0] * g.mean2d_ndc[2 * i], ndc_scale[1] * g.mean2d_ndc[2 * i + 1]);
      count[i] += 1.f;
      max_radius[i] = std::max(max_radius[i], float(radii[i]));
    }
  });
}

void DensificationStats::save(std::ostream& out) const {
  write_vector(out, grad_accum);
  write_vector(out, count);
  write_vector(out, max_radius);
}

void DensificationStats::load(std::istream& in) {
  grad_accum = read_vector<float>(in);
  count = read_vector<float>(in);
  max_radius = read_vector<float>(in);
}

size_t prune(GaussianModel& model, GaussianAdam& adam, DensificationStats& stats,
             const std::vector<uint8_t>& remove) {
  std::vector<uint8_t> keep(remove.size());
  size_t removed = 0;
  for (size_t i = 0; i < remove.size(); ++i) {
    keep[i] = !remove[i];
    removed += remove[i] != 0;
  }
  keep_gaussians(model, keep);
  adam.keep(keep);
  keep_entries(stats.grad_accum, 1, keep);
  keep_entries(stats.count, 1, keep);
  keep_entries(stats.max_radius, 1, keep);
  return removed;
}

std::vector<uint8_t> densification_candidates(const std::vector<float>& grad,
                                              const std::vector<uint8_t>& large, size_t room,
                                              const DensifyOptions& o, size_t* held_back) {
  std::vector<uint8_t> grows(grad.size(), 0);
  std::vector<size_t> candidates;
  for (size_t i = 0; i < grad.size(); ++i)
    if (grad[i] >= o.grad_threshold) candidates.push_back(i);
  if (held_back) *held_back = 0;
  if (o.max_gaussians == 0) {
    for (size_t i : candidates) grows[i] = 1;
    return grows;
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [&](size_t a, size_t b) { return grad[a] > grad[b]; });
  size_t added = 0;
  for (size_t k = 0; k < candidates.size(); ++k) {
    const size_t i = candidates[k];
    const size_t adds = large[i] ? size_t(std::max(o.split_count - 1, 0)) : 1;
    if (added + adds > room) {
      if (held_back) *held_back = candidates.size() - k;
      break;
    }
    added += adds;
    grows[i] = 1;
  }
  return grows;
}

DensifyResult densify_and_prune(GaussianModel& m, GaussianAdam& adam, DensificationStats& stats,
                                double extent, bool prune_large, std::mt19937_64& rng,
                                const DensifyOptions& o) {
  DensifyResult result;
  const size_t n0 = m.size();
  std::vector<float> grad(n0);
  for (size_t i = 0; i < n0; ++i)
    grad[i] = stats.count[i] > 0 ? stats.grad_accum[i] / stats.count[i] : 0.f;
  // Screen radii seen before this step: the pruning test uses them.
  std::vector<float> radius = stats.max_radius;
  const float dense = float(o.percent_dense * extent);
  std::vector<uint8_t> large(n0);
  for (size_t i = 0; i < n0; ++i) large[i] = max_scale(m, i) > dense;
  const size_t room = o.max_gaussians > n0 ? o.max_gaussians - n0 : 0;
  const std::vector<uint8_t> grows =
      densification_candidates(grad, large, room, o, &result.held_back);

  // Clone: small Gaussians with large gradients get a copy.
  for (size_t i = 0; i < n0; ++i) {
    if (grows[i] && max_scale(m, i) <= dense) {
      append_copy(m, i);
      ++result.cloned;
    }
  }
  // Split: large ones are replaced by split_count samples from themselves.
  std::vector<uint8_t> remove(m.size(), 0);
  for (size_t i = 0; i < n0; ++i) {
    if (!(grows[i] && large[i])) continue;
    const Eigen::Quaternionf q(m.rotations[4 * i], m.rotations[4 * i + 1], m.rotations[4 * i + 2],
                               m.rotations[4 * i + 3]);
    const Eigen::Matrix3f R = q.normalized().toRotationMatrix();
    for (int s = 0; s < o.split_count; ++s) {
      Eigen::Vector3f offset;
      for (int k = 0; k < 3; ++k)
        offset[k] = std::normal_distribution<float>(0.f, std::exp(m.log_scales[3 * i + k]))(rng);
      const size_t j = m.size();
      append_copy(m, i);
      const Eigen::Vector3f mean =
          R * offset + Eigen::Vector3f(m.means[3 * i], m.means[3 * i + 1], m.means[3 * i + 2]);
      for (int k = 0; k < 3; ++k) {
        m.means[3 * j + k] = mean[k];
        m.log_scales[3 * j + k] = m.log_scales[3 * i + k] - std::log(o.split_scale_divisor);
      }
    }
    remove[i] = 1;
    ++result.split;
  }
  adam.append(m.size() - n0);
  remove.resize(m.size(), 0);
  radius.resize(m.size(), 0.f);

  // Prune: transparent, and (after the first reset) too large.
  for (size_t i = 0; i < m.size(); ++i) {
    if (remove[i]) continue;
    bool bad = sigmoid(m.opacity_logits[i]) < o.min_opacity;
    if (prune_large)
      bad = bad || (o.max_screen_radius > 0 && radius[i] > o.max_screen_radius) ||
            max_scale(m, i) > o.max_world_scale * extent;
    remove[i] = bad;
    result.pruned += bad;
  }
  stats.reset(m.size());
  prune(m, adam, stats, remove);
  return result;
}

void reset_opacity(GaussianModel& m, GaussianAdam& adam, float max_opacity) {
  const float cap = logit(max_opacity);
  for (float& l : m.opacity_logits) l = std::min(l, cap);
  adam.reset_moments(ParamGroup::kOpacity);
}

}  // namespace splat
