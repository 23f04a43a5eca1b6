#include "splat/train/adam.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace splat {
namespace {

TEST(Adam, MatchesTorchAdamByHand) {
  GaussianModel m;
  m.resize(1);
  m.means = {1.f, 2.f, 3.f};
  GaussianGradients g;
  g.resize(1);
  std::fill(g.means.begin(), g.means.end(), 0.f);
  GaussianAdam adam(1);
  std::array<float, kParamGroups> lr{};
  lr[int(ParamGroup::kMeans)] = 0.1f;
  double p = 1.0, mom = 0, vel = 0;
  for (int step = 1; step <= 5; ++step) {
    const float grad = 0.5f * step - 1.f;
    g.means = {grad, 0.f, 0.f};
    adam.step(m, g, lr);
    mom = 0.9 * mom + 0.1 * grad;
    vel = 0.999 * vel + 0.001 * grad * grad;
    const double mhat = mom / (1 - std::pow(0.9, step)), vhat = vel / (1 - std::pow(0.999, step));
    p -= 0.1 * mhat / (std::sqrt(vhat) + 1e-15);
    EXPECT_NEAR(m.means[0], p, 1e-5) << "step " << step;
  }
  EXPECT_EQ(m.means[1], 2.f) << "zero gradient, zero moments: no move";
  EXPECT_EQ(adam.steps(ParamGroup::kMeans), 5);
  EXPECT_EQ(adam.steps(ParamGroup::kOpacity), 0) << "groups without a learning rate do not step";
}

// The trainer's step: culled Gaussians' gradients are not read (the renderer
// leaves them unwritten) and they step as with zero gradients, to the bit.
TEST(Adam, CulledGaussiansStepAsWithZeroGradientsUnread) {
  const size_t n = 37;
  GaussianModel start;
  start.resize(n);
  std::vector<uint8_t> visible(n);
  for (size_t i = 0; i < n; ++i) visible[i] = (i % 7 < 3 || i > 30) ? 1 : 0;  // runs of both
  auto gradients = [&](int step, float culled) {
    GaussianGradients g;
    g.resize(n);
    g.visible = visible;
    int seed = 0;
    for (std::vector<float>* values : {&g.means, &g.sh_dc, &g.sh_rest, &g.opacity_logits,
                                       &g.log_scales, &g.rotations, &g.instance_opacity_logits}) {
      const size_t width = values->size() / n;
      for (size_t k = 0; k < values->size(); ++k)
        (*values)[k] = visible[k / width] ? std::sin(float(k + 13 * step + seed)) : culled;
      ++seed;
    }
    return g;
  };
  std::array<float, kParamGroups> lr;
  lr.fill(0.01f);
  for (int degree : {1, 3}) {
    GaussianModel read = start, unread = start;
    read.has_instance_opacity = unread.has_instance_opacity = true;
    GaussianAdam adam_read(n), adam_unread(n);
    for (int step = 1; step <= 4; ++step) {
      adam_read.step(read, gradients(step, 0.f), lr, {}, degree);
      adam_unread.step(unread, gradients(step, std::nanf("")), lr, {}, degree,
                       GaussianAdam::Culled::kZeroGradients);
    }
    for (int gi = 0; gi < kParamGroups; ++gi)
      EXPECT_EQ(group_values(read, ParamGroup(gi)), group_values(unread, ParamGroup(gi)))
          << group_name(ParamGroup(gi)) << ", degree " << degree;
    EXPECT_EQ(adam_read, adam_unread);
  }
}

// Sparse Adam: a Gaussian out of view keeps its values and moments, and the
// ones in view step as torch's Adam with the group's step count, checked
// value by value against a slow reference over steps whose views differ.
TEST(Adam, KeepCulledStepsOnlyTheGaussiansInView) {
  const size_t n = 23;
  GaussianModel model;
  model.resize(n);
  model.has_instance_opacity = true;
  for (int gi = 0; gi < kParamGroups; ++gi) {
    std::vector<float>& values = group_values(model, ParamGroup(gi));
    for (size_t k = 0; k < values.size(); ++k) values[k] = std::cos(float(k + 7 * gi));
  }
  struct Reference {
    std::vector<float> p;
    std::vector<double> m, v;
  };
  std::array<Reference, kParamGroups> ref;
  for (int gi = 0; gi < kParamGroups; ++gi) {
    ref[gi].p = group_values(model, ParamGroup(gi));
    ref[gi].m.assign(ref[gi].p.size(), 0.0);
    ref[gi].v.assign(ref[gi].p.size(), 0.0);
  }
  std::array<float, kParamGroups> lr;
  lr.fill(0.01f);
  GaussianAdam adam(n);
  for (int step = 1; step <= 5; ++step) {
    GaussianGradients g;
    g.resize(n);
    g.visible.resize(n);
    // Runs of both, shifting from step to step; a NaN where the renderer
    // leaves a culled Gaussian's gradient unwritten.
    for (size_t i = 0; i < n; ++i) g.visible[i] = ((i + size_t(step)) % 5 < 2) ? 1 : 0;
    for (int gi = 0; gi < kParamGroups; ++gi) {
      auto& values = const_cast<std::vector<float>&>(group_gradients(g, ParamGroup(gi)));
      const size_t width = values.size() / n;
      for (size_t k = 0; k < values.size(); ++k)
        values[k] = g.visible[k / width] ? std::sin(float(k + 11 * step + gi)) : std::nanf("");
    }
    adam.step(model, g, lr, {}, kMaxShDegree, GaussianAdam::Culled::kKeep);
    const double bc1 = 1 - std::pow(0.9, step), bc2 = 1 - std::pow(0.999, step);
    for (int gi = 0; gi < kParamGroups; ++gi) {
      const std::vector<float>& grad = group_gradients(g, ParamGroup(gi));
      Reference& r = ref[gi];
      const size_t width = grad.size() / n;
      for (size_t k = 0; k < grad.size(); ++k) {
        if (!g.visible[k / width]) continue;  // values and moments stay
        r.m[k] = 0.9 * r.m[k] + 0.1 * grad[k];
        r.v[k] = 0.999 * r.v[k] + 0.001 * double(grad[k]) * grad[k];
        r.p[k] -= float(0.01 * (r.m[k] / bc1) / (std::sqrt(r.v[k] / bc2) + 1e-15));
      }
      const std::vector<float>& got = group_values(model, ParamGroup(gi));
      for (size_t k = 0; k < got.size(); ++k)
        ASSERT_NEAR(got[k], r.p[k], 1e-5f * (1 + std::abs(r.p[k])))
            << group_name(ParamGroup(gi)) << " value " << k << ", step " << step
            << (g.visible[k / width] ? " (in view)" : " (culled)");
    }
  }
  EXPECT_EQ(adam.steps(ParamGroup::kMeans), 5);
}

// With every Gaussian in view, sparse Adam is the reference's step (to float
// rounding: GCC may contract the two loops' multiply-adds differently).
TEST(Adam, KeepCulledWithAllInViewIsTheReferenceStep) {
  const size_t n = 9;
  GaussianModel dense, sparse;
  dense.resize(n);
  dense.has_instance_opacity = true;
  for (int gi = 0; gi < kParamGroups; ++gi) {
    std::vector<float>& values = group_values(dense, ParamGroup(gi));
    for (size_t k = 0; k < values.size(); ++k) values[k] = std::cos(float(3 * k + gi));
  }
  sparse = dense;
  GaussianGradients g;
  g.resize(n);
  g.visible.assign(n, 1);
  for (int gi = 0; gi < kParamGroups; ++gi) {
    auto& values = const_cast<std::vector<float>&>(group_gradients(g, ParamGroup(gi)));
    for (size_t k = 0; k < values.size(); ++k) values[k] = std::sin(float(k + gi));
  }
  std::array<float, kParamGroups> lr;
  lr.fill(0.02f);
  GaussianAdam adam_dense(n), adam_sparse(n);
  for (int step = 0; step < 3; ++step) {
    adam_dense.step(dense, g, lr);
    adam_sparse.step(sparse, g, lr, {}, kMaxShDegree, GaussianAdam::Culled::kKeep);
  }
  for (int gi = 0; gi < kParamGroups; ++gi) {
    const auto& a = group_values(dense, ParamGroup(gi));
    const auto& b = group_values(sparse, ParamGroup(gi));
    for (size_t k = 0; k < a.size(); ++k)
      ASSERT_NEAR(a[k], b[k], 1e-6f * (1 + std::abs(a[k])))
          << group_name(ParamGroup(gi)) << " value " << k;
  }
  EXPECT_EQ(adam_dense.steps(ParamGroup::kMeans), adam_sparse.steps(ParamGroup::kMeans));
}

// The SH rest's step taken a batch at a time inside the backward pass (the
// trainer's) is step()'s for the group to the bit, whatever the batches'
// sizes, for Gaussians in view and out of view, at every culling rule and
// with SH bands above the active degree; it counts the group's step once.
TEST(Adam, ShRestStepInBatchesIsTheGroupsStep) {
  const size_t n = 41;
  GaussianModel start;
  start.resize(n);
  for (size_t k = 0; k < start.sh_rest.size(); ++k) start.sh_rest[k] = std::cos(float(k));
  std::array<float, kParamGroups> lr{};
  lr[int(ParamGroup::kShRest)] = 0.01f;
  for (const auto culled : {GaussianAdam::Culled::kZeroGradients, GaussianAdam::Culled::kKeep})
    for (int degree : {1, 3}) {
      GaussianModel whole = start, batched = start;
      GaussianAdam adam_whole(n), adam_batched(n);
      for (int step = 1; step <= 4; ++step) {
        GaussianGradients g;
        g.resize(n);
        g.visible.resize(n);
        for (size_t i = 0; i < n; ++i) g.visible[i] = (i * 7 + size_t(step)) % 5 < 3 ? 1 : 0;
        for (size_t k = 0; k < g.sh_rest.size(); ++k)
          g.sh_rest[k] =
              g.visible[k / kShRestFloats] ? std::sin(float(k + 17 * step)) : std::nanf("");
        adam_whole.step(whole, g, lr, {}, degree, culled);
        GaussianAdam::ShRestStep rest =
            adam_batched.begin_sh_rest_step(batched, 0.01f, degree, culled);
        // Batches of 16 and a short last one, as the backward pass makes them;
        // the rows of Gaussians out of view hold NaN (unwritten).
        for (size_t first = 0; first < n; first += 16) {
          const size_t count = std::min<size_t>(16, n - first);
          uint32_t visible = 0;
          for (size_t l = 0; l < count; ++l) visible |= uint32_t(g.visible[first + l]) << l;
          rest.take(first, count, &g.sh_rest[kShRestFloats * first], visible);
        }
      }
      EXPECT_EQ(whole.sh_rest, batched.sh_rest)
          << (culled == GaussianAdam::Culled::kKeep ? "kept" : "zero gradients") << ", degree "
          << degree;
      EXPECT_EQ(adam_whole, adam_batched);
      EXPECT_EQ(adam_batched.steps(ParamGroup::kShRest), 4);
    }
}

TEST(Adam, SkippedGroupsKeepValuesAndStepCount) {
  GaussianModel m;
  m.resize(2);
  GaussianGradients g;
  g.resize(2);
  std::fill(g.opacity_logits.begin(), g.opacity_logits.end(), 1.f);
  GaussianAdam adam(2);
  std::array<float, kParamGroups> lr;
  lr.fill(0.01f);
  std::array<bool, kParamGroups> skip{};
  skip[int(ParamGroup::kOpacity)] = true;
  adam.step(m, g, lr, skip);
  EXPECT_EQ(m.opacity_logits[0], 0.f);
  EXPECT_EQ(adam.steps(ParamGroup::kOpacity), 0);
  EXPECT_EQ(adam.steps(ParamGroup::kScales), 1);
}

TEST(Adam, AppendKeepResetAndSaveLoad) {
  GaussianModel m;
  m.resize(3);
  GaussianGradients g;
  g.resize(3);
  std::fill(g.log_scales.begin(), g.log_scales.end(), 1.f);
  GaussianAdam adam(3);
  std::array<float, kParamGroups> lr;
  lr.fill(0.01f);
  adam.step(m, g, lr);
  adam.append(2);
  EXPECT_EQ(adam.size(), 5u);
  adam.keep({1, 0, 1, 1, 0});
  EXPECT_EQ(adam.size(), 3u);
  adam.reset_moments(ParamGroup::kOpacity);
  std::stringstream buffer;
  adam.save(buffer);
  GaussianAdam loaded(0);
  loaded.load(buffer);
  EXPECT_TRUE(loaded == adam);
}

}  // namespace
}  // namespace splat
