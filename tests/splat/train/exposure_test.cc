#include "splat/train/exposure.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include "splat/image_quality.h"

namespace splat {
namespace {

std::vector<float> random_colors(size_t pixels, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.05f, 0.9f);
  std::vector<float> c(3 * pixels);
  for (float& v : c) v = u(rng);
  return c;
}

TEST(Exposure, StartsAsTheIdentity) {
  const ViewColorTransforms t(3);
  const std::vector<float> in = random_colors(10, 1);
  std::vector<float> out(in.size());
  t.apply(2, in, out);
  EXPECT_EQ(out, in);
}

TEST(Exposure, GradientsMatchFiniteDifferences) {
  // Loss = sum w . out; after a few steps the transform is no identity.
  ViewColorTransforms t(1);
  const std::vector<float> in = random_colors(50, 2), w = random_colors(50, 3);
  for (int k = 0; k < 5; ++k) {
    std::vector<float> g = w;
    t.backward_and_step(0, in, g, 0.05f, 0);
  }
  std::vector<float> grad_in = w;
  ViewColorTransforms frozen = t;
  frozen.backward_and_step(0, in, grad_in, 0, 0);  // lr 0: gradient only
  const auto loss = [&](const std::vector<float>& x) {
    std::vector<float> out(x.size());
    t.apply(0, x, out);
    double l = 0;
    for (size_t i = 0; i < out.size(); ++i) l += double(w[i]) * out[i];
    return l;
  };
  for (size_t i : {0u, 7u, 20u, 149u}) {
    std::vector<float> a = in, b = in;
    a[i] += 1e-3f, b[i] -= 1e-3f;
    EXPECT_NEAR((loss(a) - loss(b)) / 2e-3, grad_in[i], 2e-3) << i;
  }
}

TEST(Exposure, LearnsAViewsGainAndOffset) {
  // The photo is the render with 1.3x exposure, a warmer balance and an
  // offset; minimising the squared error recovers them.
  const std::vector<float> render = random_colors(400, 4);
  std::vector<float> photo(render.size());
  const float gain[3] = {1.3f * 1.05f, 1.3f, 1.3f * 0.92f};
  for (size_t i = 0; i < render.size(); ++i) photo[i] = gain[i % 3] * render[i] + 0.02f;
  ViewColorTransforms t(1);
  for (int step = 0; step < 3000; ++step) {
    std::vector<float> out(render.size()), g(render.size());
    t.apply(0, render, out);
    for (size_t i = 0; i < out.size(); ++i) g[i] = 2 * (out[i] - photo[i]) / float(out.size());
    t.backward_and_step(0, render, g, 0.003f, 0);
  }
  const auto& p = t.params(0);
  EXPECT_NEAR(p[0], gain[0], 0.02);
  EXPECT_NEAR(p[4], gain[1], 0.02);
  EXPECT_NEAR(p[8], gain[2], 0.02);
  EXPECT_NEAR(p[1], 0, 0.02);
  EXPECT_NEAR(p[9], 0.02, 0.01);
}

TEST(Exposure, RegularisationPullsTowardsTheIdentity) {
  ViewColorTransforms t(1);
  const std::vector<float> in = random_colors(10, 5);
  for (int k = 0; k < 50; ++k) {
    std::vector<float> g(in.size(), 1.f);  // pushes every output down
    t.backward_and_step(0, in, g, 0.01f, 0);
  }
  const float pushed = t.params(0)[9];
  ASSERT_LT(pushed, -0.1f);
  for (int k = 0; k < 300; ++k) {
    std::vector<float> g(in.size(), 0.f);  // nothing but the pull
    t.backward_and_step(0, in, g, 0.01f, 1.f);
  }
  EXPECT_GT(t.params(0)[9], pushed / 2);  // well on its way back
}

TEST(Exposure, SavesAndLoadsExactly) {
  ViewColorTransforms t(4);
  const std::vector<float> in = random_colors(20, 6);
  std::vector<float> g = random_colors(20, 7);
  t.backward_and_step(1, in, g, 0.01f, 1e-3f);
  std::stringstream s;
  t.save(s);
  ViewColorTransforms u;
  u.load(s);
  ASSERT_EQ(u.size(), 4u);
  for (size_t v = 0; v < 4; ++v) EXPECT_EQ(u.params(v), t.params(v));
  // The optimiser's state came along: the next step is the same.
  std::vector<float> g1 = g, g2 = g;
  t.backward_and_step(1, in, g1, 0.01f, 1e-3f);
  u.backward_and_step(1, in, g2, 0.01f, 1e-3f);
  EXPECT_EQ(u.params(1), t.params(1));
}

TEST(Exposure, FittedPsnrUndoesAGlobalColourChange) {
  const int w = 32, h = 16;
  const std::vector<float> render = random_colors(size_t(w) * h, 8);
  std::vector<float> photo(render.size());
  for (size_t i = 0; i < render.size(); ++i) photo[i] = 0.8f * render[i] + 0.05f;
  EXPECT_LT(psnr(render, photo), 30);
  EXPECT_GT(psnr_after_fit(render, photo, w, h, w / 2), 60);
}

}  // namespace
}  // namespace splat
