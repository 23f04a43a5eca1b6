#include "splat/train/image_loss.h"

#include <gtest/gtest.h>

#include <random>

namespace splat {
namespace {

ImageRGB random_image(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  ImageRGB im(w, h);
  for (float& v : im.data) v = u(rng);
  return im;
}

TEST(ImageLoss, IdenticalImagesHaveZeroLossAndUnitSsim) {
  const ImageRGB a = random_image(20, 14, 1);
  const ImageLoss l = image_loss(a.data, a, {}, nullptr);
  EXPECT_NEAR(l.l1, 0.0, 1e-12);
  EXPECT_NEAR(l.ssim, 1.0, 1e-5);
  EXPECT_NEAR(l.total, 0.0, 1e-5);
}

TEST(ImageLoss, GradientMatchesFiniteDifferences) {
  const ImageRGB target = random_image(23, 17, 2);
  ImageRGB rendered = random_image(23, 17, 3);
  std::vector<float> grad;
  image_loss(rendered.data, target, {}, &grad);
  std::mt19937 rng(4);
  int checked = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const size_t i = rng() % rendered.data.size();
    const float keep = rendered.data[i], h = 1e-3f;
    rendered.data[i] = keep + h;
    const double up = image_loss(rendered.data, target, {}, nullptr).total;
    rendered.data[i] = keep - h;
    const double down = image_loss(rendered.data, target, {}, nullptr).total;
    rendered.data[i] = keep;
    if (std::abs(keep - target.data[i]) < 2 * h) continue;  // L1 kink
    EXPECT_NEAR(grad[i], (up - down) / (2 * h), 2e-3 * std::abs(grad[i]) + 2e-7) << i;
    ++checked;
  }
  EXPECT_GT(checked, 40);
}

}  // namespace
}  // namespace splat
