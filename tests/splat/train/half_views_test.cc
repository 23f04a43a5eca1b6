#include "splat/train/half_views.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "splat/render/renderer.h"
#include "splat/train/image_loss.h"
#include "tests/splat/render/scenes.h"

namespace splat {
namespace {

// Over two consecutive epochs a view shows both halves once: together they
// are the view, with no pixel twice.
TEST(HalfViews, TwoEpochsCoverEveryPixelOnce) {
  const size_t views = 7;
  for (const auto& [w, h] : {std::pair{986, 728}, std::pair{7, 5}, std::pair{5, 9}}) {
    for (size_t view : {size_t(0), size_t(3)}) {
      for (int epoch : {0, 1, 4}) {
        std::vector<int> seen(size_t(w) * h, 0);
        for (int e : {epoch, epoch + 1}) {
          const int iteration = 1 + e * int(views) + 2;  // somewhere in epoch e
          const PixelRect r = training_half(w, h, view, iteration, views);
          ASSERT_GE(r.x, 0);
          ASSERT_GE(r.y, 0);
          ASSERT_LE(r.x + r.width, w);
          ASSERT_LE(r.y + r.height, h);
          for (int y = r.y; y < r.y + r.height; ++y)
            for (int x = r.x; x < r.x + r.width; ++x) ++seen[size_t(y) * w + x];
        }
        for (int s : seen) ASSERT_EQ(s, 1) << w << "x" << h << " view " << view;
      }
    }
  }
}

TEST(HalfViews, SplitTheLongerSideAndStartHalfTheViewsOnEachSide) {
  const PixelRect landscape = training_half(986, 728, 0, 1, 10);
  EXPECT_EQ(landscape.width, 493);
  EXPECT_EQ(landscape.height, 728);
  const PixelRect portrait = training_half(360, 640, 0, 1, 10);
  EXPECT_EQ(portrait.width, 360);
  EXPECT_EQ(portrait.height, 320);
  // Views 0 and 1 in the same epoch show different halves.
  EXPECT_NE(training_half(986, 728, 0, 5, 10).x, training_half(986, 728, 1, 5, 10).x);
  // The epoch is counted from iteration 1: iterations 1-10 are epoch 0.
  EXPECT_EQ(training_half(986, 728, 0, 10, 10).x, 0);
  EXPECT_EQ(training_half(986, 728, 0, 11, 10).x, 493);
}

TEST(HalfViews, ShareIsThePixelFractionAndOffIsNever) {
  EXPECT_DOUBLE_EQ(half_share({0, 0, 3, 5}, 7, 5), 3.0 / 7.0);
  EXPECT_DOUBLE_EQ(half_share({3, 0, 4, 5}, 7, 5), 4.0 / 7.0);
  const HalfViewOptions off;
  EXPECT_FALSE(off.applies(1));
  EXPECT_FALSE(off.applies(30000));
  const HalfViewOptions late{7500};
  EXPECT_FALSE(late.applies(7499));
  EXPECT_TRUE(late.applies(7500));
  EXPECT_THROW(HalfViewOptions{-1}.Check(), std::invalid_argument);
  EXPECT_THROW(training_half(1, 5, 0, 1, 3), std::invalid_argument);
  EXPECT_THROW(training_half(8, 6, 0, 1, 0), std::invalid_argument);
}

// The render of a half is that rectangle of the whole view's render: the
// cropped camera moves the principal point and nothing else.
TEST(HalfViews, AHalfRendersAsThatRectangleOfTheView) {
  const GaussianModel m = testing_scenes::random_scene(400, 11);
  const Camera cam = testing_scenes::test_camera(64, 48);
  RenderSettings s;
  const RenderOutput full = CpuRenderer().render(m, cam, s);
  for (int epoch : {0, 1}) {
    const PixelRect r = training_half(cam.width, cam.height, 0, 1 + epoch * 5, 5);
    const RenderOutput half = CpuRenderer().render(m, cam.cropped(r.x, r.y, r.width, r.height), s);
    ASSERT_EQ(half.width, r.width);
    ASSERT_EQ(half.height, r.height);
    double worst = 0;
    for (int y = 0; y < r.height; ++y)
      for (int x = 0; x < r.width; ++x)
        for (int k = 0; k < 3; ++k)
          worst = std::max(
              worst, double(std::abs(half.color[3 * (size_t(y) * r.width + x) + k] -
                                     full.color[3 * (size_t(y + r.y) * cam.width + x + r.x) + k])));
    EXPECT_LT(worst, 1e-5) << "half at x " << r.x;
  }
}

// With the loss weighted by each half's share, the two halves' gradients add
// up to the whole view's (an L1 loss, which is a sum over pixels), so the
// Gaussians learn from a half what they learn from those pixels of the view;
// and the 2D means' gradients, scaled as DensificationStats::add scales
// them, are the view's.
TEST(HalfViews, TheHalvesGradientsWeightedByTheirShareAddUpToTheViews) {
  const GaussianModel m = testing_scenes::random_scene(400, 12);
  const Camera cam = testing_scenes::test_camera(64, 48);
  ImageRGB target(cam.width, cam.height);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0, 1);
  for (float& v : target.data) v = u(rng);
  const ImageLossOptions l1{0.f};
  RenderSettings s;
  BackwardSettings b;
  b.zero_culled_gradients = true;  // so that the sums below read zeros, not stale values

  auto gradients = [&](const Camera& c, const ImageRGB& t, float weight) {
    CpuRenderer r;
    std::unique_ptr<RenderState> state;
    const RenderOutput out = r.render(m, c, s, &state);
    RenderOutputGradients g;
    image_loss(out.color, t, l1, &g.color);
    for (float& v : g.color) v *= weight;
    return r.backward(m, c, s, b, *state, g);
  };
  const GaussianGradients whole = gradients(cam, target, 1.f);
  std::vector<float> means(whole.means.size(), 0.f), opacity(m.size(), 0.f),
      mean2d(whole.mean2d_ndc.size(), 0.f);
  for (int epoch : {0, 1}) {
    const PixelRect r = training_half(cam.width, cam.height, 0, 1 + epoch * 5, 5);
    const GaussianGradients g = gradients(cam.cropped(r.x, r.y, r.width, r.height), crop(target, r),
                                          float(half_share(r, cam.width, cam.height)));
    const float sx = float(cam.width) / r.width, sy = float(cam.height) / r.height;
    for (size_t i = 0; i < means.size(); ++i) means[i] += g.means[i];
    for (size_t i = 0; i < opacity.size(); ++i) {
      opacity[i] += g.opacity_logits[i];
      mean2d[2 * i] += sx * g.mean2d_ndc[2 * i];
      mean2d[2 * i + 1] += sy * g.mean2d_ndc[2 * i + 1];
    }
  }
  auto expect_close = [](const std::vector<float>& sum, const std::vector<float>& ref,
                         const char* what) {
    double scale = 0;
    for (float v : ref) scale = std::max(scale, double(std::abs(v)));
    ASSERT_GT(scale, 0) << what;
    for (size_t i = 0; i < ref.size(); ++i)
      ASSERT_NEAR(sum[i], ref[i], 1e-4 * scale) << what << " " << i;
  };
  expect_close(means, whole.means, "means");
  expect_close(opacity, whole.opacity_logits, "opacity");
  expect_close(mean2d, whole.mean2d_ndc, "2D means (NDC)");
}

}  // namespace
}  // namespace splat
