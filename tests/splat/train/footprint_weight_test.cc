// The footprint weight of --recipe robust-footprint against a slow
// reference, and its two limits: exact masks leave the paper's gradient as
// it is, and a one-pixel footprint gives the generalized cross-entropy's;
// and the sum of the weighted gradients.

#include "splat/train/footprint_weight.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "splat/train/object_loss.h"

namespace splat {
namespace {

constexpr double kQ = 0.7;

struct Maps {
  IdMap ids{7, 5};
  std::vector<int32_t> labels = {1, 3};
  std::vector<float> S;  // one plane per label

  explicit Maps(uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<int> id(0, 3);
    std::uniform_real_distribution<float> s(0.f, 1.f);
    for (uint16_t& v : ids.ids) v = uint16_t(id(rng));
    S.resize(labels.size() * ids.ids.size());
    for (float& v : S) v = s(rng);
    S[3] = 0.f, S[4] = 1.f;  // the ends, where no power is taken
  }
  // p^q of plane j at (x, y), the slow way.
  double agreement(size_t j, int x, int y) const {
    const size_t p = size_t(y) * size_t(ids.width) + size_t(x);
    const double s = S[j * ids.ids.size() + p];
    return std::pow(ids.ids[p] == labels[j] ? s : 1 - s, kQ);
  }
  double slow_box_mean(size_t j, int x0, int y0, int x1, int y1) const {
    double sum = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) sum += agreement(j, x, y);
    return sum / ((x1 - x0) * (y1 - y0));
  }
};

TEST(FootprintWeights, BoxMeanIsTheMeanOfTheGeneralizedLossWeight) {
  const Maps m(1);
  FootprintWeights w;
  w.compute(m.S, m.labels, m.ids, kQ);
  for (size_t j = 0; j < m.labels.size(); ++j)
    for (int y0 = 0; y0 < 5; ++y0)
      for (int y1 = y0 + 1; y1 <= 5; ++y1)
        for (int x0 = 0; x0 < 7; ++x0)
          for (int x1 = x0 + 1; x1 <= 7; ++x1)
            EXPECT_NEAR(w.box_mean(j, x0, y0, x1, y1), m.slow_box_mean(j, x0, y0, x1, y1), 1e-6)
                << j << " " << x0 << " " << y0 << " " << x1 << " " << y1;
}

TEST(FootprintWeights, TheFootprintIsOneSigmaAroundTheMeanCutToTheImage) {
  const Maps m(2);
  FootprintWeights w;
  w.compute(m.S, m.labels, m.ids, kQ);
  // Under 3 pixels of radius: the mean's pixel alone (centres at +0.5).
  EXPECT_NEAR(w.weight(0, 2.9f, 1.1f, 2), m.agreement(0, 2, 1), 1e-6);
  // Radius 6: one sigma is 2 pixels, a 5 x 5 square.
  EXPECT_NEAR(w.weight(1, 3.5f, 2.5f, 6), m.slow_box_mean(1, 1, 0, 6, 5), 1e-6);
  // Cut to the image at its corner.
  EXPECT_NEAR(w.weight(1, 0.2f, 4.7f, 3), m.slow_box_mean(1, 0, 3, 2, 5), 1e-6);
  // A mean off the image: the nearest pixel's footprint.
  EXPECT_NEAR(w.weight(0, -4.f, 9.f, 1), m.agreement(0, 0, 4), 1e-6);
}

TEST(FootprintWeights, EachVisibleGaussianOfAPlaneGetsItsFootprintsWeight) {
  const Maps m(3);
  FootprintWeights w;
  w.compute(m.S, m.labels, m.ids, kQ);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<float> x(-1.f, 8.f), y(-1.f, 6.f);
  std::uniform_int_distribution<int32_t> label(0, 3), radius(0, 9);
  const size_t n = 200;
  std::vector<float> mean2d(2 * n);
  std::vector<int32_t> labels(n), radii(n);
  std::vector<uint8_t> visible(n);
  for (size_t i = 0; i < n; ++i) {
    mean2d[2 * i] = x(rng), mean2d[2 * i + 1] = y(rng);
    labels[i] = label(rng), radii[i] = radius(rng), visible[i] = i % 5 != 0;
  }
  const std::vector<float> weights = w.per_gaussian(labels, visible, mean2d, radii);
  ASSERT_EQ(weights.size(), n);
  for (size_t i = 0; i < n; ++i) {
    const auto plane = std::find(m.labels.begin(), m.labels.end(), labels[i]);
    if (!visible[i] || radii[i] == 0 || plane == m.labels.end()) {
      EXPECT_EQ(weights[i], 1.f) << i;
      continue;
    }
    const size_t j = size_t(plane - m.labels.begin());
    const int cx = std::clamp(int(std::floor(mean2d[2 * i])), 0, 6);
    const int cy = std::clamp(int(std::floor(mean2d[2 * i + 1])), 0, 4);
    const int h = radii[i] / 3;
    EXPECT_NEAR(weights[i],
                m.slow_box_mean(j, std::max(cx - h, 0), std::max(cy - h, 0),
                                std::min(cx + h + 1, 7), std::min(cy + h + 1, 5)),
                1e-6)
        << i;
  }
}

// Where the model's maps are its masks, every weight is 1: the paper's
// gradient, bit for bit.
TEST(FootprintWeights, MasksTheModelAgreesWithWeighEveryGaussianOne) {
  Maps m(5);
  for (size_t j = 0; j < m.labels.size(); ++j)
    for (size_t p = 0; p < m.ids.ids.size(); ++p)
      m.S[j * m.ids.ids.size() + p] = m.ids.ids[p] == m.labels[j] ? 1.f : 0.f;
  FootprintWeights w;
  w.compute(m.S, m.labels, m.ids, kQ);
  EXPECT_EQ(w.per_gaussian(std::vector<int32_t>{1, 3, 1, 3}, std::vector<uint8_t>{1, 1, 1, 1},
                           std::vector<float>{0.5f, 0.5f, 3.2f, 2.2f, 6.9f, 4.9f, 1.f, 1.f},
                           std::vector<int32_t>{1, 9, 4, 30}),
            std::vector<float>(4, 1.f));
}

// add_weighted adds each visible Gaussian's gradient times its weight to
// every parameter's, and leaves the culled ones as they are.
TEST(FootprintWeights, AddWeightedAddsEachVisibleGaussiansShare) {
  const size_t n = 3;
  GaussianGradients into, from;
  into.resize(n), from.resize(n);
  into.visible = {1, 0, 1}, from.visible = into.visible;
  std::vector<std::vector<float>*> arrays[2];
  for (int k = 0; k < 2; ++k) {
    GaussianGradients& g = k ? from : into;
    arrays[k] = {&g.means,
                 &g.sh_dc,
                 &g.sh_rest,
                 &g.opacity_logits,
                 &g.log_scales,
                 &g.rotations,
                 &g.instance_opacity_logits,
                 &g.mean2d_ndc};
    for (std::vector<float>* a : arrays[k])
      for (size_t v = 0; v < a->size(); ++v) (*a)[v] = float(v + 1) * (k ? 0.5f : 1.f);
    g.camera = {1, 2, 3, 4, 5, 6};
  }
  const std::vector<float> weights = {0.25f, 3.f, 2.f};
  add_weighted(into, from, weights);
  for (const std::vector<float>* a : arrays[0]) {
    const size_t width = a->size() / n;
    for (size_t v = 0; v < a->size(); ++v) {
      const size_t i = v / width;
      const float before = float(v + 1), added = i == 1 ? 0.f : weights[i] * 0.5f * float(v + 1);
      EXPECT_EQ((*a)[v], before + added) << v;
    }
  }
  EXPECT_EQ(into.camera[5], 12.0);
  EXPECT_THROW(add_weighted(into, from, std::vector<float>(2)), std::invalid_argument);
}

// A footprint of one pixel: the cross-entropy's gradient times the weight is
// the generalized cross-entropy's (object_loss.h), which is what the weight
// averages over larger footprints.
TEST(FootprintWeights, OnOnePixelItGivesTheGeneralizedLossGradient) {
  for (const float s : {0.05f, 0.3f, 0.62f, 0.97f})
    for (const uint16_t id : {uint16_t(0), uint16_t(1)}) {
      IdMap ids(1, 1);
      ids.ids = {id};
      const std::vector<float> S = {s};
      std::vector<float> cross_entropy, generalized;
      object_loss(S, {1}, ids, 0.1f, &cross_entropy);
      PixelLoss gce;
      gce.kind = PixelLoss::Kind::kGeneralized;
      gce.q = kQ;
      object_loss(S, {1}, ids, 0.1f, &generalized, gce);
      FootprintWeights w;
      w.compute(S, {1}, ids, kQ);
      EXPECT_NEAR(cross_entropy[0] * w.weight(0, 0.5f, 0.5f, 1), generalized[0],
                  1e-5 * std::abs(generalized[0]))
          << s << " " << id;
    }
}

TEST(FootprintWeights, RejectsMapsOfAnotherSize) {
  const Maps m(6);
  FootprintWeights w;
  EXPECT_THROW(w.compute(std::vector<float>(3), m.labels, m.ids, kQ), std::invalid_argument);
  w.compute(m.S, m.labels, m.ids, kQ);
  EXPECT_THROW(w.per_gaussian(std::vector<int32_t>(2), std::vector<uint8_t>(2),
                              std::vector<float>(3), std::vector<int32_t>(2)),
               std::invalid_argument);
}

}  // namespace
}  // namespace splat
