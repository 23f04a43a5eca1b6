#include "splat/image_quality.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "splat/image.h"

namespace splat {
namespace {

TEST(ImageQuality, SsimOfKnownCase) {
  // A constant image against itself plus a constant offset: the SSIM map is
  // (2 mu_x mu_y + C1) / (mu_x^2 + mu_y^2 + C1) away from the borders.
  ImageRGB a(40, 40), b(40, 40);
  std::fill(a.data.begin(), a.data.end(), 0.5f);
  std::fill(b.data.begin(), b.data.end(), 0.6f);
  const double inner = (2 * 0.5 * 0.6 + 1e-4) / (0.25 + 0.36 + 1e-4);
  const double s = ssim(a.data, b.data, 40, 40);
  EXPECT_LT(std::abs(s - inner), 0.02);  // the zero-padded borders pull it a little
  EXPECT_LT(s, 1.0);
}

TEST(ImageQuality, Psnr) {
  std::vector<float> a(300, 0.5f), b(300, 0.6f);
  EXPECT_NEAR(psnr(a, b), 20.0, 1e-4);  // MSE 0.01
}

TEST(ImageQuality, SsimOfIdenticalImagesIsOne) {
  ImageRGB a(17, 11);
  for (size_t i = 0; i < a.data.size(); ++i) a.data[i] = float(i % 13) / 13.f;
  EXPECT_NEAR(ssim(a.data, a.data, 17, 11), 1.0, 1e-6);
}

}  // namespace
}  // namespace splat
