#include "splat/render/fast_exp.h"

#include <gtest/gtest.h>

#include <cmath>

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

}  // namespace
}  // namespace splat
