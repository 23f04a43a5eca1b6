#include "splat/render/fast_exp.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>

namespace splat {
namespace {

TEST(FastExp, MatchesStdExpOnTheRendererRange) {
  for (double x = -87.0; x <= 0.0; x += 1e-3) {
    const double want = std::exp(double(float(x)));
    ASSERT_NEAR(fast_exp(float(x)), want, 3e-7 * want + 1e-38) << x;
  }
  for (double x = 0.0; x <= 80.0; x += 1e-2) {  // log-scales (the projection takes their exp)
    const double want = std::exp(double(float(x)));
    ASSERT_NEAR(fast_exp(float(x)), want, 4e-7 * want) << x;
  }
  EXPECT_GT(fast_exp(-1000.f), 0.f);
  EXPECT_LT(fast_exp(-1000.f), 1e-37f);
}

#if defined(__AVX2__) && defined(__FMA__)
// The rasterizer's register loops take exp through fast_exp_lanes, which
// applies 2^n with V::times_two_to (a scale instruction with AVX-512): the
// same bits as fast_exp on the range they use (x <= 0, clamped at -87).
TEST(FastExp, RegisterLanesGiveTheScalarBits) {
  using V = RegisterLanes;
  alignas(64) float x[V::kWidth], got[V::kWidth];
  for (double start = -100.0; start <= 0.0; start += V::kWidth * 7.3e-4) {
    for (int l = 0; l < V::kWidth; ++l) x[l] = std::fmin(float(start + l * 7.3e-4), 0.f);
    V::store(got, fast_exp_lanes<V>(V::load(x)));
    for (int l = 0; l < V::kWidth; ++l)
      ASSERT_EQ(std::bit_cast<uint32_t>(got[l]), std::bit_cast<uint32_t>(fast_exp(x[l]))) << x[l];
  }
}
#endif

TEST(FastLog, MatchesStdLog) {
  // Densely where the renderer uses it (ln(255 sigma), 255 sigma in [1, 255]),
  // then across the float range.
  for (double x = 1.0; x <= 255.0; x += 1e-3) {
    const float xf = float(x);
    const double want = std::log(double(xf));
    ASSERT_NEAR(fast_log(xf), want, 1e-7 + 1e-7 * std::abs(want)) << x;
  }
  for (double x = 1e-30; x < 1e30; x *= 1.001) {
    const float xf = float(x);
    const double want = std::log(double(xf));
    ASSERT_NEAR(fast_log(xf), want, 1e-7 + 1e-7 * std::abs(want)) << x;
  }
}

}  // namespace
}  // namespace splat
