#include "splat/gaussians.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace splat {
namespace {

GaussianModel random_model(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-5.f, 5.f);
  GaussianModel m;
  m.resize(n);
  for (float* v : {m.means.data(), m.sh_dc.data(), m.log_scales.data()})
    for (size_t i = 0; i < 3 * n; ++i) v[i] = u(rng);
  for (float& v : m.sh_rest) v = u(rng);
  for (float& v : m.rotations) v = u(rng);
  for (size_t i = 0; i < n; ++i) {
    m.opacity_logits[i] = u(rng);
    m.instance_opacity_logits[i] = u(rng);
    m.labels[i] = int32_t(i % 7);
  }
  return m;
}

TEST(Gaussians, ReorderMovesEveryArrayAndTheInverseRestoresTheModel) {
  const GaussianModel original = random_model(1000, 3);
  std::vector<uint32_t> order(1000);
  for (uint32_t k = 0; k < 1000; ++k) order[k] = (k * 389) % 1000;  // a permutation
  GaussianModel m = original;
  reorder_gaussians(m, order);
  for (size_t k : {0, 1, 517, 999}) {
    const size_t i = order[k];
    EXPECT_EQ(m.means[3 * k + 2], original.means[3 * i + 2]);
    EXPECT_EQ(m.sh_rest[kShRestFloats * k + 44], original.sh_rest[kShRestFloats * i + 44]);
    EXPECT_EQ(m.rotations[4 * k + 3], original.rotations[4 * i + 3]);
    EXPECT_EQ(m.opacity_logits[k], original.opacity_logits[i]);
    EXPECT_EQ(m.instance_opacity_logits[k], original.instance_opacity_logits[i]);
    EXPECT_EQ(m.labels[k], original.labels[i]);
  }
  reorder_gaussians(m, inverse_order(order));
  EXPECT_EQ(m, original);
  EXPECT_THROW(reorder_gaussians(m, std::vector<uint32_t>(5)), std::invalid_argument);
}

TEST(Gaussians, SpatialOrderIsAPermutationThatKeepsNeighboursClose) {
  GaussianModel m = random_model(20000, 4);
  m.means[0] = std::numeric_limits<float>::quiet_NaN();  // a broken centre still gets a place
  m.means[3] = 1e30f;                                    // and so does a far floater
  const std::vector<uint32_t> order = spatial_order(m);
  std::vector<uint32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (uint32_t k = 0; k < sorted.size(); ++k) ASSERT_EQ(sorted[k], k);
  // Consecutive Gaussians lie far closer together in the new order than in
  // the random one.
  auto mean_step = [&](auto index) {
    double sum = 0;
    int count = 0;
    for (size_t k = 10; k + 1 < order.size() - 10; ++k) {
      const float* a = &m.means[3 * index(k)];
      const float* b = &m.means[3 * index(k + 1)];
      const double d = std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
      if (std::isfinite(d) && d < 100) sum += d, ++count;
    }
    return sum / count;
  };
  const double spatial = mean_step([&](size_t k) { return order[k]; });
  const double original = mean_step([](size_t k) { return k; });
  EXPECT_LT(spatial, 0.2 * original);
}

}  // namespace
}  // namespace splat
