#include "splat/train/adam.h"

#include <gtest/gtest.h>

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
                       /*read_culled_gradients=*/false);
    }
    for (int gi = 0; gi < kParamGroups; ++gi)
      EXPECT_EQ(group_values(read, ParamGroup(gi)), group_values(unread, ParamGroup(gi)))
          << group_name(ParamGroup(gi)) << ", degree " << degree;
    EXPECT_EQ(adam_read, adam_unread);
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
