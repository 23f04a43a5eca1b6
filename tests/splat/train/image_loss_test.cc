#include "splat/train/image_loss.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <random>

#include "splat/image_quality.h"

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

// The loss as splat/image_quality.h's slow reference computes it, plane by
// plane: L1, ssim_plane, and their gradients.
ImageLoss reference_loss(const ImageRGB& rendered, const ImageRGB& target, float lambda,
                         std::vector<float>& grad) {
  const size_t n = target.data.size();
  ImageLoss l;
  grad.assign(n, 0.f);
  for (size_t i = 0; i < n; ++i) {
    const float d = rendered.data[i] - target.data[i];
    l.l1 += std::abs(double(rendered.data[i]) - target.data[i]);
    grad[i] = d > 0 ? (1 - lambda) / float(n) : (d < 0 ? -(1 - lambda) / float(n) : 0.f);
  }
  l.l1 /= n;
  for (int c = 0; c < 3; ++c) {
    std::vector<float> dx(n / 3, 0.f);
    l.ssim += ssim_plane(rgb_channel(rendered.data, c), rgb_channel(target.data, c), target.width,
                         target.height, &dx);
    for (size_t i = 0; i < dx.size(); ++i) grad[3 * i + c] += -lambda / float(n) * dx[i];
  }
  l.ssim /= n;
  l.total = (1 - lambda) * l.l1 + lambda * (1 - l.ssim);
  return l;
}

TEST(ImageLoss, MatchesTheSlowReferenceAtEverySize) {
  ImageLossBuffers buffers;  // reused across sizes, as the trainer reuses it
  // 100 wide: the blurs' chunks of four vectors, single vectors and scalar tails.
  for (auto [w, h] : {std::pair{64, 48}, {100, 20}, {23, 17}, {7, 5}, {11, 30}, {40, 3}, {1, 1}}) {
    const ImageRGB target = random_image(w, h, 5);
    ImageRGB rendered = random_image(w, h, 6);
    rendered.data[0] = target.data[0];  // an L1 kink: sign(0) = 0
    std::vector<float> expected_grad, grad;
    const ImageLoss expected = reference_loss(rendered, target, 0.2f, expected_grad);
    const ImageLoss l = image_loss(rendered.data, target, {}, &grad, &buffers);
    // The blurs may round differently (the order of multiply-adds the
    // compiler vectorises), so the figures agree to float precision.
    EXPECT_NEAR(l.l1, expected.l1, 1e-12) << w << "x" << h;
    EXPECT_NEAR(10 * std::log10(1 / l.mse), psnr(rendered.data, target.data), 1e-9);
    EXPECT_NEAR(l.ssim, expected.ssim, 1e-6) << w << "x" << h;
    EXPECT_NEAR(l.total, expected.total, 1e-6) << w << "x" << h;
    ASSERT_EQ(grad.size(), expected_grad.size());
    float largest = 0;
    for (float g : expected_grad) largest = std::max(largest, std::abs(g));
    for (size_t i = 0; i < grad.size(); ++i)
      ASSERT_NEAR(grad[i], expected_grad[i], 1e-5f * largest) << w << "x" << h << " element " << i;
  }
}

// The buffers keep the zeros around the rows the horizontal blur reads from
// call to call; after a call at another size they are written anew, so a
// reused buffer gives the bits of a fresh one.
TEST(ImageLoss, ReusedBuffersGiveTheBitsOfFreshOnes) {
  ImageLossBuffers reused;
  for (auto [w, h] : {std::pair{37, 29}, {100, 20}, {37, 29}, {16, 16}, {37, 29}}) {
    const ImageRGB target = random_image(w, h, 9);
    const ImageRGB rendered = random_image(w, h, 10);
    std::vector<float> grad_reused, grad_fresh;
    const ImageLoss with_reused = image_loss(rendered.data, target, {}, &grad_reused, &reused);
    const ImageLoss with_fresh = image_loss(rendered.data, target, {}, &grad_fresh);
    EXPECT_EQ(with_reused.total, with_fresh.total) << w << "x" << h;
    EXPECT_EQ(with_reused.ssim, with_fresh.ssim) << w << "x" << h;
    EXPECT_EQ(grad_reused, grad_fresh) << w << "x" << h;
    // A call without the gradient between, as the trainer's test views make.
    image_loss(rendered.data, target, {}, nullptr, &reused);
  }
}

TEST(ImageLoss, IndependentOfTheThreadCount) {
  const ImageRGB target = random_image(300, 200, 7);
  const ImageRGB rendered = random_image(300, 200, 8);
  std::vector<float> grad_many, grad_one;
  const ImageLoss many = image_loss(rendered.data, target, {}, &grad_many);
  ImageLoss one;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = image_loss(rendered.data, target, {}, &grad_one);
  }
  EXPECT_EQ(many.total, one.total);
  EXPECT_EQ(grad_many, grad_one);
}

}  // namespace
}  // namespace splat
