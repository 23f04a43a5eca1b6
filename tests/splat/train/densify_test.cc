#include "splat/train/densify.h"

#include <gtest/gtest.h>

#include <cmath>

#include "splat/train/initialize.h"

namespace splat {
namespace {

// Three Gaussians: 0 small with a large gradient (clone), 1 large with a
// large gradient (split), 2 transparent (prune).
struct Fixture {
  GaussianModel m;
  GaussianAdam adam{0};
  DensificationStats stats;
  Fixture() {
    m.resize(3);
    const float small = std::log(0.005f), large = std::log(0.5f);
    for (int k = 0; k < 3; ++k) {
      m.log_scales[k] = small;
      m.log_scales[3 + k] = large;
      m.log_scales[6 + k] = small;
      m.means[3 + k] = 1.f;
    }
    m.opacity_logits = {2.f, 2.f, std::log(0.001f / 0.999f)};
    m.labels = {7, 8, 9};
    adam = GaussianAdam(3);
    stats.reset(3);
    stats.grad_accum = {0.003f, 0.003f, 0.f};  // mean 0.0003 over 10 views
    stats.count = {10.f, 10.f, 10.f};
  }
};

TEST(Densify, ClonesSmallSplitsLargePrunesTransparent) {
  Fixture f;
  std::mt19937_64 rng(1);
  const DensifyResult r = densify_and_prune(f.m, f.adam, f.stats, /*extent=*/1.0, false, rng);
  EXPECT_EQ(r.cloned, 1u);
  EXPECT_EQ(r.split, 1u);
  EXPECT_EQ(r.pruned, 1u);
  // Kept: Gaussian 0, its clone, and the two halves of Gaussian 1.
  ASSERT_EQ(f.m.size(), 4u);
  EXPECT_EQ(f.m.labels, (std::vector<int32_t>{7, 7, 8, 8}));
  EXPECT_EQ(f.m.means[0], f.m.means[3]) << "a clone sits where its source is";
  for (int half : {2, 3}) {
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(std::exp(f.m.log_scales[3 * half + k]), 0.5 / 1.6, 1e-6) << "split scales / 1.6";
    EXPECT_GT(std::abs(f.m.means[3 * half] - 1.f), 0.f) << "split samples move";
  }
  EXPECT_EQ(f.adam.size(), 4u);
  EXPECT_EQ(f.stats.count.size(), 4u);
  EXPECT_EQ(f.stats.grad_accum[0], 0.f) << "statistics reset";
}

TEST(Densify, BelowThresholdNothingGrows) {
  Fixture f;
  f.stats.grad_accum = {0.0019f, 0.0019f, 0.f};
  std::mt19937_64 rng(1);
  const DensifyResult r = densify_and_prune(f.m, f.adam, f.stats, 1.0, false, rng);
  EXPECT_EQ(r.cloned + r.split, 0u);
  EXPECT_EQ(f.m.size(), 2u);
}

TEST(Densify, LargeOnScreenOrInWorldArePrunedAfterFirstReset) {
  Fixture f;
  f.stats.grad_accum = {0, 0, 0};
  f.stats.max_radius = {25.f, 1.f, 1.f};  // 0 is too large on screen
  std::mt19937_64 rng(1);
  // Gaussian 1 is 0.5 > 0.1 * extent (extent 1): too large in the world.
  DensifyOptions spec_rule;
  spec_rule.max_screen_radius = 20.f;
  const DensifyResult r =
      densify_and_prune(f.m, f.adam, f.stats, 1.0, /*prune_large=*/true, rng, spec_rule);
  EXPECT_EQ(r.pruned, 3u);
  EXPECT_EQ(f.m.size(), 0u);
}

TEST(Densify, ByDefaultNoScreenSizePruningAsTheReferenceDoes) {
  Fixture f;
  f.stats.grad_accum = {0, 0, 0};
  f.stats.max_radius = {25.f, 1.f, 1.f};
  std::mt19937_64 rng(1);
  const DensifyResult r = densify_and_prune(f.m, f.adam, f.stats, 1.0, true, rng);
  EXPECT_EQ(r.pruned, 2u) << "the transparent one and the one too large in the world";
  ASSERT_EQ(f.m.size(), 1u);
  EXPECT_EQ(f.m.labels[0], 7);
}

TEST(Densify, ABudgetGrowsTheLargestGradientsFirst) {
  Fixture f;
  f.stats.grad_accum = {0.003f, 0.004f, 0.f};  // the large one's gradient is larger
  DensifyOptions budget;
  budget.max_gaussians = 4;  // room for one more: the split of Gaussian 1
  std::mt19937_64 rng(1);
  const DensifyResult r = densify_and_prune(f.m, f.adam, f.stats, 1.0, false, rng, budget);
  EXPECT_EQ(r.split, 1u);
  EXPECT_EQ(r.cloned, 0u);
  EXPECT_EQ(r.held_back, 1u);
  EXPECT_EQ(f.m.labels, (std::vector<int32_t>{7, 8, 8})) << "the transparent one pruned";

  Fixture g;
  g.stats.grad_accum = {0.004f, 0.003f, 0.f};  // now the small one's is larger
  std::mt19937_64 rng2(1);
  const DensifyResult s = densify_and_prune(g.m, g.adam, g.stats, 1.0, false, rng2, budget);
  EXPECT_EQ(s.cloned, 1u);
  EXPECT_EQ(s.split, 0u);
  EXPECT_EQ(g.m.labels, (std::vector<int32_t>{7, 8, 7}));
}

TEST(Densify, ABudgetWithRoomChangesNothing) {
  Fixture f, g;
  DensifyOptions budget;
  budget.max_gaussians = 5;  // exactly the room the two candidates need
  std::mt19937_64 rng_f(3), rng_g(3);
  const DensifyResult r = densify_and_prune(f.m, f.adam, f.stats, 1.0, false, rng_f);
  const DensifyResult s = densify_and_prune(g.m, g.adam, g.stats, 1.0, false, rng_g, budget);
  EXPECT_EQ(s.held_back, 0u);
  EXPECT_EQ(r.cloned + r.split + r.pruned, s.cloned + s.split + s.pruned);
  EXPECT_EQ(f.m.means, g.m.means) << "the same split samples, drawn in the same order";
  EXPECT_EQ(f.m.log_scales, g.m.log_scales);
}

TEST(Densify, ABudgetAlreadyReachedGrowsNothing) {
  Fixture f;
  DensifyOptions budget;
  budget.max_gaussians = 2;  // below the 3 there are
  std::mt19937_64 rng(1);
  const DensifyResult r = densify_and_prune(f.m, f.adam, f.stats, 1.0, false, rng, budget);
  EXPECT_EQ(r.cloned + r.split, 0u);
  EXPECT_EQ(r.held_back, 2u);
  EXPECT_EQ(f.m.size(), 2u) << "pruning still frees room";
}

TEST(Densify, CandidatesWithinABudgetCountASplitsNewGaussians) {
  // Gradients 5, 4, 3, 2, 1 (times 1e-3), the first two large (a split of
  // three adds two), the threshold 1.5e-3; room 5: 2 + 2 + 1, then no room.
  const std::vector<float> grad = {5e-3f, 4e-3f, 3e-3f, 2e-3f, 1e-3f};
  const std::vector<uint8_t> large = {1, 1, 0, 0, 0};
  DensifyOptions o;
  o.grad_threshold = 1.5e-3f;
  o.split_count = 3;
  o.max_gaussians = 100;
  size_t held_back = 0;
  EXPECT_EQ(densification_candidates(grad, large, 5, o, &held_back),
            (std::vector<uint8_t>{1, 1, 1, 0, 0}));
  EXPECT_EQ(held_back, 1u);
  o.max_gaussians = 0;  // no budget: the threshold alone, whatever the room
  EXPECT_EQ(densification_candidates(grad, large, 0, o, &held_back),
            (std::vector<uint8_t>{1, 1, 1, 1, 0}));
  EXPECT_EQ(held_back, 0u);
}

TEST(Densify, ResetOpacityCapsAt001) {
  Fixture f;
  reset_opacity(f.m, f.adam);
  EXPECT_NEAR(1 / (1 + std::exp(-f.m.opacity_logits[0])), 0.01, 1e-6);
  EXPECT_LT(f.m.opacity_logits[2], std::log(0.01f / 0.99f)) << "lower opacities stay";
}

TEST(Initialize, FromPointsAsTheReference) {
  const std::vector<Eigen::Vector3d> pts = {
      {0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {0, 0, 3}, {10, 10, 10}};
  const std::vector<Eigen::Vector3f> cols(5, Eigen::Vector3f(1.f, 0.5f, 0.f));
  const std::vector<double> d2 = mean_squared_knn_distance(pts);
  EXPECT_NEAR(d2[0], (1 + 4 + 9) / 3.0, 1e-12);
  const GaussianModel m = initialize_from_points(pts, cols);
  EXPECT_NEAR(m.log_scales[0], std::log(std::sqrt(14.0 / 3)), 1e-6);
  EXPECT_NEAR(m.sh_dc[0], 0.5f / 0.28209479177387814f, 1e-5);
  EXPECT_NEAR(m.sh_dc[1], 0.f, 1e-7);
  EXPECT_NEAR(1 / (1 + std::exp(-m.opacity_logits[0])), 0.1, 1e-6);
  EXPECT_EQ(m.rotations[0], 1.f);
  EXPECT_EQ(m.sh_rest[5], 0.f);
}

}  // namespace
}  // namespace splat
