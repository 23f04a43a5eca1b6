// The random object loss: its gradient, the sampling of objects, and the
// paper's claim on a hand-built case.

#include "splat/train/object_loss.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/image_quality.h"
#include "splat/npy.h"
#include "splat/render/renderer.h"
#include "splat/train/adam.h"
#include "splat/train/image_loss.h"

namespace splat {
namespace {

// The gradient object_loss returns against central differences of its loss.
void expect_gradient_matches_finite_differences(const PixelLoss& loss, double tolerance) {
  IdMap ids(3, 2);
  ids.ids = {1, 1, 2, 0, 2, 1};
  const std::vector<int32_t> labels = {1, 2};
  std::vector<float> maps = {0.9f,  0.2f, 0.5f, 0.1f, 0.7f,  0.3f,
                             0.05f, 0.4f, 0.8f, 0.6f, 0.35f, 0.01f};
  std::vector<float> grad;
  const float weight = 0.1f;
  object_loss(maps, labels, ids, weight, &grad, loss);
  for (size_t i = 0; i < maps.size(); ++i) {
    std::vector<float> plus = maps, minus = maps;
    const float h = 1e-3f;
    plus[i] += h, minus[i] -= h;
    const double fd = weight *
                      (object_loss(plus, labels, ids, 1, nullptr, loss) -
                       object_loss(minus, labels, ids, 1, nullptr, loss)) /
                      (2 * h);
    EXPECT_NEAR(grad[i], fd, tolerance * std::abs(fd) + 1e-6) << i;
  }
}

TEST(ObjectLoss, GradientMatchesFiniteDifferences) {
  expect_gradient_matches_finite_differences({}, 1e-3);
}

// The loss and its gradient as the papers write them, one pixel at a time:
// the binary cross-entropy, against which object_loss (which skips the
// logarithms of clamped values) must agree to the last bit of the gradient
// (the loss up to its sum's order), or the
// generalized cross-entropy (1 - p^q) / q with p = S where B, else 1 - S,
// and with an outline band the cross-entropy at the pixels whose square
// window of that radius holds both values of the model's mask S >= tau
// (searched here pixel by pixel).
bool near_outline_by_search(const float* S, int width, int height, float tau, size_t pixel,
                            int radius) {
  const int x0 = int(pixel % size_t(width)), y0 = int(pixel / size_t(width));
  const bool b = S[pixel] >= tau;
  for (int y = std::max(0, y0 - radius); y <= std::min(height - 1, y0 + radius); ++y)
    for (int x = std::max(0, x0 - radius); x <= std::min(width - 1, x0 + radius); ++x)
      if ((S[size_t(y) * width + x] >= tau) != b) return true;
  return false;
}

double reference_object_loss(const std::vector<float>& maps, const std::vector<int32_t>& labels,
                             const IdMap& ids, float weight, std::vector<float>& grad,
                             const PixelLoss& loss = {}) {
  const size_t pixels = ids.ids.size();
  const double eps = 1e-6, scale = 1.0 / (double(labels.size()) * double(pixels)), q = loss.q;
  grad.assign(maps.size(), 0.f);
  double total = 0;
  for (size_t j = 0; j < labels.size(); ++j) {
    double sum = 0;
    for (size_t p = 0; p < pixels; ++p) {
      const float S = maps[j * pixels + p];
      const double b = ids.ids[p] == labels[j] ? 1.0 : 0.0;
      const double s = std::clamp(double(S), eps, 1 - eps);
      const double prob = b ? s : 1 - s;
      const bool in_band = loss.kind == PixelLoss::Kind::kGeneralized && loss.outline_band > 0 &&
                           near_outline_by_search(&maps[j * pixels], ids.width, ids.height,
                                                  loss.mask_threshold, p, loss.outline_band);
      const double q_here = in_band ? loss.outline_q : q;
      const bool generalized =
          loss.kind == PixelLoss::Kind::kGeneralized && !(in_band && loss.outline_q == 0);
      if (generalized)
        sum += (1 - std::pow(prob, q_here)) / q_here;
      else
        sum -= b * std::log(s) + (1 - b) * std::log(1 - s);
      if (S > eps && S < 1 - eps)  // generalized: dL/dS = -prob^(q-1) dprob/dS
        grad[j * pixels + p] = float(
            weight * scale *
            (generalized ? -std::pow(prob, q_here - 1) * (b ? 1 : -1) : (s - b) / (s * (1 - s))));
    }
    total += sum;
  }
  return total * scale;
}

// Random masks of labels {1, 3, 2} over more pixels than one chunk of the
// gradient, and occupancies that are zeros, ones, values next to the
// clamp's bounds and values inside.
struct LossCase {
  IdMap ids{300, 250};
  std::vector<int32_t> labels = {1, 3, 2};
  std::vector<float> maps;
  explicit LossCase(unsigned seed) {
    std::mt19937 rng(seed);
    for (uint16_t& id : ids.ids) id = uint16_t(rng() % 4);
    const float specials[] = {0.f, 1.f, 1e-7f, 1e-6f, 2e-6f, 0.999999f, 0.9999995f, 0.5f};
    maps.resize(labels.size() * ids.ids.size());
    for (float& v : maps)
      v = rng() % 2 ? specials[rng() % 8] : std::uniform_real_distribution<float>(0, 1)(rng);
  }
};

// The gradient bit for bit; the loss up to the order of its sum (the fast
// one adds each plane in chunks of pixels).
TEST(ObjectLoss, EqualsThePerPixelFormula) {
  const LossCase c(7);
  const auto& [ids, labels, maps] = c;
  std::vector<float> grad, expected_grad;
  const double loss = object_loss(maps, labels, ids, 0.1f, &grad);
  const double expected = reference_object_loss(maps, labels, ids, 0.1f, expected_grad);
  EXPECT_NEAR(loss, expected, 1e-12 * expected);
  EXPECT_EQ(grad, expected_grad);
}

// The chunks are fixed, so one thread and all of them give the same double.
TEST(ObjectLoss, TheLossIsTheSameDoubleWhateverTheThreads) {
  const LossCase c(5);
  const auto& [ids, labels, maps] = c;
  for (const PixelLoss& pixel_loss :
       {PixelLoss{}, PixelLoss{PixelLoss::Kind::kGeneralized, 0.7, 3}}) {
    std::vector<float> grad_one, grad_all;
    double one = 0;
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
      one = object_loss(maps, labels, ids, 0.1f, &grad_one, pixel_loss);
    }
    const double all = object_loss(maps, labels, ids, 0.1f, &grad_all, pixel_loss);
    EXPECT_EQ(one, all);
    EXPECT_EQ(grad_one, grad_all);
  }
}

// near_outline of the model's mask S >= 0.5 of one plane.
std::vector<uint8_t> near_outline_by_model(const std::vector<float>& S, const IdMap& ids,
                                           int radius) {
  std::vector<uint8_t> inside(S.size());
  for (size_t p = 0; p < S.size(); ++p) inside[p] = S[p] >= 0.5f;
  return near_outline(inside, ids.width, ids.height, radius);
}

PixelLoss generalized(double q) { return {PixelLoss::Kind::kGeneralized, q}; }
PixelLoss generalized_off_outline(double q, int band) {
  return {PixelLoss::Kind::kGeneralized, q, band};
}
PixelLoss generalized_with_outline_q(double q, int band, double outline_q) {
  PixelLoss loss{PixelLoss::Kind::kGeneralized, q, band};
  loss.outline_q = outline_q;
  return loss;
}

TEST(ObjectLoss, GeneralizedLossesEqualTheirPerPixelFormula) {
  const LossCase c(11);
  const auto& [ids, labels, maps] = c;
  for (double q : {0.7, 0.3, 1.0})
    for (const PixelLoss& pixel_loss :
         {generalized(q), generalized_off_outline(q, 1), generalized_off_outline(q, 3),
          generalized_with_outline_q(q, 2, 0.35), generalized_with_outline_q(q, 3, 1.0)}) {
      const int kind = pixel_loss.outline_band;
      std::vector<float> grad, expected_grad;
      const double loss = object_loss(maps, labels, ids, 0.1f, &grad, pixel_loss);
      EXPECT_NEAR(loss, reference_object_loss(maps, labels, ids, 0.1f, expected_grad, pixel_loss),
                  1e-12)
          << q << " " << kind;
      ASSERT_EQ(grad.size(), expected_grad.size());
      for (size_t i = 0; i < grad.size(); ++i)
        ASSERT_NEAR(grad[i], expected_grad[i], 1e-6 * std::abs(expected_grad[i]))
            << q << " " << kind << " " << i;
    }
}

TEST(ObjectLoss, GeneralizedGradientsMatchFiniteDifferences) {
  expect_gradient_matches_finite_differences(generalized(0.7), 2e-3);
  expect_gradient_matches_finite_differences(generalized_off_outline(0.7, 2), 2e-3);
  expect_gradient_matches_finite_differences(generalized_with_outline_q(0.7, 2, 0.35), 2e-3);
}

// A square of an object in a 12 x 10 image: the pixels near its outline are
// those within the radius of both sides.
TEST(ObjectLoss, NearOutlineIsTheBandOnBothSidesOfTheOutline) {
  const int w = 12, h = 10;
  std::vector<uint8_t> inside(size_t(w * h), 0);
  std::vector<float> S(inside.size(), 0.f);
  for (int y = 3; y < 8; ++y)
    for (int x = 2; x < 9; ++x) inside[size_t(y * w + x)] = 1, S[size_t(y * w + x)] = 1.f;
  const std::vector<uint8_t> near = near_outline(inside, w, h, 1);
  for (size_t p = 0; p < near.size(); ++p)
    EXPECT_EQ(bool(near[p]), near_outline_by_search(S.data(), w, h, 0.5f, p, 1)) << p;
  EXPECT_TRUE(near[size_t(3 * w + 2)]);   // the square's corner
  EXPECT_TRUE(near[size_t(2 * w + 1)]);   // the pixel outside it, diagonally
  EXPECT_FALSE(near[size_t(5 * w + 5)]);  // its middle
  EXPECT_FALSE(near[size_t(0)]);          // far outside
  EXPECT_THROW(near_outline(inside, w, h - 1, 1), std::invalid_argument);
}

// In stripes of rows on several threads, the band is the whole image's:
// random pixels over more rows than four stripes hold, in an arena of four
// threads whatever the machine's cores.
TEST(ObjectLoss, NearOutlineInStripesIsTheWholeImages) {
  const int w = 37, h = 611;
  std::mt19937 rng(3);
  std::vector<uint8_t> inside(size_t(w * h));
  std::vector<float> S(inside.size());
  for (size_t p = 0; p < inside.size(); ++p) S[p] = inside[p] = rng() % 7 == 0;
  for (int radius : {1, 3}) {
    std::vector<uint8_t> near;
    tbb::task_arena(4).execute([&] { near = near_outline(inside, w, h, radius); });
    ASSERT_EQ(near.size(), inside.size());
    for (size_t p = 0; p < near.size(); ++p)
      ASSERT_EQ(bool(near[p]), near_outline_by_search(S.data(), w, h, 0.5f, p, radius))
          << radius << " " << p;
  }
}

// The band follows the model's mask (S >= tau), not the view's: here the
// model draws a square and the view's mask misses a blob inside it and
// leaks outside it. Near the square's outline the loss is the paper's to the
// last bit of the gradient; on the miss and the leak, away from it, the
// generalized one.
TEST(ObjectLoss, TheOutlineBandIsThePapersLossNearTheModelsOutline) {
  IdMap ids(16, 12);
  std::vector<float> maps(ids.ids.size());
  std::mt19937 rng(3);
  for (int y = 0; y < ids.height; ++y)
    for (int x = 0; x < ids.width; ++x) {
      const bool in_square = x >= 3 && x < 12 && y >= 2 && y < 10;
      maps[size_t(y * ids.width + x)] =
          std::uniform_real_distribution<float>(0.01f, 0.49f)(rng) + (in_square ? 0.5f : 0.f);
      const bool missed = x >= 6 && x < 9 && y >= 5 && y < 7, leaked = x >= 14 && y >= 4;
      if ((in_square && !missed) || leaked) ids.at(x, y) = 4;
    }
  const std::vector<uint8_t> near = near_outline_by_model(maps, ids, 1);
  std::vector<float> paper, banded, robust;
  object_loss(maps, {4}, ids, 0.1f, &paper);
  object_loss(maps, {4}, ids, 0.1f, &banded, generalized_off_outline(0.7, 1));
  object_loss(maps, {4}, ids, 0.1f, &robust, generalized(0.7));
  for (size_t p = 0; p < maps.size(); ++p)
    EXPECT_EQ(banded[p], near[p] ? paper[p] : robust[p]) << p;
  const auto at = [&](int x, int y) { return size_t(y * ids.width + x); };
  EXPECT_TRUE(near[at(3, 2)]);    // the square's corner
  EXPECT_FALSE(near[at(7, 5)]);   // the missed blob
  EXPECT_FALSE(near[at(15, 8)]);  // the leak
  EXPECT_NE(banded[at(7, 5)], paper[at(7, 5)]);
}

// The band's q between: q near the outline equal to q elsewhere is the
// generalized loss everywhere, to the last bit.
TEST(ObjectLoss, TheOutlinesQEqualToQIsTheGeneralizedLossEverywhere) {
  const LossCase c(5);
  const auto& [ids, labels, maps] = c;
  std::vector<float> everywhere, banded;
  EXPECT_EQ(object_loss(maps, labels, ids, 0.1f, &everywhere, generalized(0.5)),
            object_loss(maps, labels, ids, 0.1f, &banded, generalized_with_outline_q(0.5, 2, 0.5)));
  EXPECT_EQ(everywhere, banded);
}

TEST(ObjectLoss, AQNearTheOutlineNeedsTheBand) {
  ObjectLossOptions o;
  o.pixel_loss.outline_q = 0.35;
  EXPECT_THROW(o.Check(), std::invalid_argument);  // the paper's loss: no band
  o.pixel_loss = generalized_with_outline_q(0.7, 3, 0.35);
  EXPECT_NO_THROW(o.Check());
  o.pixel_loss.outline_q = 1.5;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

TEST(ObjectLoss, TheDefaultIsThePapersCrossEntropy) {
  IdMap ids(3, 1);
  ids.ids = {1, 0, 1};
  const std::vector<float> maps = {0.3f, 0.6f, 0.9f};
  std::vector<float> a, b;
  EXPECT_EQ(object_loss(maps, {1}, ids, 0.1f, &a), object_loss(maps, {1}, ids, 0.1f, &b, {}));
  EXPECT_EQ(a, b);
  EXPECT_EQ(ObjectLossOptions{}.pixel_loss.kind, PixelLoss::Kind::kCrossEntropy);
  // The generalized loss at q = 1 is the mean absolute error |S - B|.
  EXPECT_NEAR(object_loss(maps, {1}, ids, 1, nullptr, generalized(1.0)), (0.7 + 0.6 + 0.1) / 3,
              1e-6);
}

// One pixel seen in 8 views, whose mask says "inside" in 6 of them (a
// segmenter that missed it in 2): plain gradient descent on the summed loss
// over the views settles at the mean, 0.75, under the cross-entropy and near
// the majority, 1, under the generalized loss (object_loss.h). With exact
// masks (8 of 8) both go to 1.
double settle(const PixelLoss& loss, int inside_views) {
  IdMap ids(8, 1);
  for (int v = 0; v < 8; ++v) ids.ids[v] = v < inside_views ? 1 : 0;
  double logit = 0;  // S = sigmoid(logit), as sigma* is
  for (int step = 0; step < 20000; ++step) {
    const float S = float(1 / (1 + std::exp(-logit)));
    const std::vector<float> maps(8, S);  // the same pixel in every view
    std::vector<float> grad;
    object_loss(maps, {1}, ids, 1, &grad, loss);
    double g = 0;
    for (float v : grad) g += v;
    logit -= 2.0 * g * S * (1 - S);
  }
  return 1 / (1 + std::exp(-logit));
}

// Where the occupancy already is the mask (exact masks the model has
// learned: S = 1 inside, 0 outside, clamped), neither loss moves anything:
// the robust recipe changes nothing that the masks agree on.
TEST(ObjectLoss, NeitherLossMovesAnOccupancyThatIsItsMask) {
  IdMap ids(4, 2);
  ids.ids = {1, 1, 0, 2, 0, 1, 2, 2};
  std::vector<float> maps;
  for (int32_t label : {1, 2})
    for (uint16_t id : ids.ids) maps.push_back(id == label ? 1.f : 0.f);
  for (const PixelLoss& loss : {PixelLoss{}, generalized(0.7), generalized_off_outline(0.7, 1)}) {
    std::vector<float> grad;
    object_loss(maps, {1, 2}, ids, 0.1f, &grad, loss);
    EXPECT_EQ(grad, std::vector<float>(maps.size(), 0.f));
  }
}

TEST(ObjectLoss, TheGeneralizedLossSettlesAtTheMajorityOfNoisyMasks) {
  EXPECT_NEAR(settle({}, 6), 0.75, 0.01);
  const double r = 0.75, q = 0.7, odds = std::pow(r / (1 - r), 1 / (1 - q));
  EXPECT_NEAR(settle(generalized(q), 6), odds / (1 + odds), 0.01);
  EXPECT_GT(settle(generalized(q), 6), 0.95);
  EXPECT_GT(settle({}, 8), 0.99);
  EXPECT_GT(settle(generalized(q), 8), 0.99);
}

TEST(ObjectLoss, PerfectOccupancyHasNearZeroLoss) {
  IdMap ids(2, 1);
  ids.ids = {3, 0};
  const std::vector<float> maps = {0.999999f, 0.f};
  const double loss = object_loss(maps, {3}, ids, 1, nullptr);
  EXPECT_LT(loss, 1e-5);
}

TEST(ObjectLoss, SamplesDistinctPresentObjects) {
  IdMap ids(4, 1);
  ids.ids = {0, 5, 2, 5};
  EXPECT_EQ(objects_in_map(ids), (std::vector<int32_t>{2, 5}));
  std::mt19937_64 rng(1);
  const std::vector<int32_t> present = {1, 2, 3, 4, 5, 6};
  for (int t = 0; t < 20; ++t) {
    std::vector<int32_t> s = sample_objects(present, 3, rng);
    ASSERT_EQ(s.size(), 3u);
    std::sort(s.begin(), s.end());
    EXPECT_EQ(std::adjacent_find(s.begin(), s.end()), s.end());
  }
  EXPECT_EQ(sample_objects({7}, 3, rng), (std::vector<int32_t>{7}));
  EXPECT_TRUE(sample_objects({}, 3, rng).empty());
}

// Object 1 fills the left half of the view and object 2 the right half. A
// floater in front of object 2 was given label 1 by voting.
struct FloaterScene {
  GaussianModel m;
  Camera cam = Camera::look_at({0, 0, 0}, {0, 0, 4}, {0, -1, 0}, 48, 48, 40, 40);
  IdMap ids{48, 48};  // the exact mask
  ImageRGB target{48, 48};
  static constexpr size_t kFloater = 2;
  // The split labels the last object_settings(keep) rendered with.
  mutable std::vector<int32_t> split;

  FloaterScene() {
    add({-1.f, 0, 4}, {1.f, 2.f, 0.05f}, 0.99f, 1, {1, 0, 0});     // object 1
    add({1.f, 0, 4}, {1.f, 2.f, 0.05f}, 0.99f, 2, {0, 0, 1});      // object 2
    add({0.5f, 0, 2}, {0.15f, 0.15f, 0.15f}, 0.6f, 1, {0, 1, 0});  // the floater
    m.has_labels = true;
    m.instance_opacity_logits = m.opacity_logits;  // sigma* starts as sigma
    m.has_instance_opacity = true;
    const bool object_1_left = cam.project({-1, 0, 4}).x() < 24;
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 48; ++x) ids.at(x, y) = (x < 24) == object_1_left ? 1 : 2;
    // The colour is already right: only sigma* should move.
    const RenderOutput r = CpuRenderer().render(m, cam, colour_settings());
    target.data.assign(r.color.begin(), r.color.end());
  }
  void add(Eigen::Vector3f mean, Eigen::Vector3f scale, float opacity, int32_t label,
           Eigen::Vector3f dc) {
    const size_t i = m.size();
    m.resize(i + 1);
    for (int k = 0; k < 3; ++k) {
      m.means[3 * i + k] = mean[k];
      m.log_scales[3 * i + k] = std::log(scale[k]);
      m.sh_dc[3 * i + k] = dc[k];
    }
    m.opacity_logits[i] = std::log(opacity / (1 - opacity));
    m.labels[i] = label;
  }
  static RenderSettings colour_settings() {
    RenderSettings s;
    s.sh_degree = 0;
    return s;
  }
  // Both losses against the photo and `mask`; with `keep`, those Gaussians'
  // sigma* may not fall.
  // The render settings of training against a mask; with `keep`, labels 1
  // and 2, then their unprotected Gaussians as 4 and 5.
  RenderSettings object_settings(const std::vector<uint8_t>* keep) const {
    RenderSettings s = colour_settings();
    s.instance_labels = {1, 2};
    if (keep) {
      split = split_labels(m.labels, *keep, 3);  // s.labels views it: it must outlive s
      s.labels = split;
      s.instance_labels = {1, 2, 4, 5};
    }
    return s;
  }
  // With vote protection, the protected Gaussians' maps (the first two)
  // reach sigma* only.
  static BackwardSettings object_backward_settings(const std::vector<uint8_t>* keep) {
    BackwardSettings b;
    if (keep) b.maps_without_geometry_gradient = 2;
    return b;
  }
  // The gradients of the object loss alone against `mask`, from the model as it is.
  GaussianGradients object_loss_gradients(const IdMap& mask,
                                          const std::vector<uint8_t>* keep) const {
    const CpuRenderer renderer;
    const RenderSettings s = object_settings(keep);
    std::unique_ptr<RenderState> state;
    const RenderOutput r = renderer.render(m, cam, s, &state);
    RenderOutputGradients out_grads;
    object_loss_into(r, mask, keep, out_grads);
    return renderer.backward(m, cam, s, object_backward_settings(keep), *state, out_grads);
  }
  // The object loss's dLoss/dS of a render with object_settings(keep).
  static void object_loss_into(const RenderOutput& r, const IdMap& mask,
                               const std::vector<uint8_t>* keep, RenderOutputGradients& out) {
    if (keep)
      split_object_loss(r.instance_maps, {1, 2}, mask, 0.1f, &out.instance_maps);
    else
      object_loss(r.instance_maps, r.instance_map_labels, mask, 0.1f, &out.instance_maps);
  }
  void train(const IdMap& mask, int iterations, const std::vector<uint8_t>* keep = nullptr) {
    const CpuRenderer renderer;
    const RenderSettings s = object_settings(keep);
    GaussianAdam adam(m.size());
    RenderOutputGradients out_grads;
    for (int it = 0; it < iterations; ++it) {
      std::unique_ptr<RenderState> state;
      const RenderOutput r = renderer.render(m, cam, s, &state);
      image_loss(r.color, target, {}, &out_grads.color);
      object_loss_into(r, mask, keep, out_grads);
      const GaussianGradients g =
          renderer.backward(m, cam, s, object_backward_settings(keep), *state, out_grads);
      // The object loss alone gives sigma no gradient; the colour loss is at its minimum.
      adam.step(m, g, {1e-4f, 2.5e-3f, 1.25e-4f, 0.05f, 5e-3f, 1e-3f, 0.05f}, {}, 0);
      if (keep) keep_in_mask(m.instance_opacity_logits, m.opacity_logits, *keep);
    }
  }
  float sigma_star(size_t i) const { return 1 / (1 + std::exp(-m.instance_opacity_logits[i])); }
  float sigma(size_t i) const { return 1 / (1 + std::exp(-m.opacity_logits[i])); }
};

// Training both losses, the floater's sigma* falls towards zero while it
// keeps its opacity and its share of the colour.
TEST(ObjectLoss, MislabelledFloaterLosesInstanceOpacityButKeepsItsColour) {
  FloaterScene f;
  // The floater lies on object 2's side.
  ASSERT_EQ(f.ids.at(int(f.cam.project({0.5, 0, 2}).x()), 24), 2);
  const CpuRenderer renderer;
  const RenderOutput before = renderer.render(f.m, f.cam, f.colour_settings());
  const float sigma_before = f.sigma(f.kFloater);
  const Eigen::Vector2d floater_pixel = f.cam.project({0.5, 0, 2});
  const size_t fp = size_t(floater_pixel.y()) * 48 + size_t(floater_pixel.x());
  f.train(f.ids, 300);
  EXPECT_LT(f.sigma_star(f.kFloater), 0.05f);  // the floater leaves the mask
  EXPECT_GT(f.sigma_star(0), 0.9f);            // the objects stay
  EXPECT_GT(f.sigma_star(1), 0.9f);
  EXPECT_NEAR(f.sigma(f.kFloater), sigma_before, 0.02f);  // still visible
  // Its colour (0.5 + 0.28 dc) moves by at most 0.03.
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(f.m.sh_dc[6 + k], k == 1 ? 1.f : 0.f, 0.1f);
  // Geometry is shared by both losses, so the picture may shift a little,
  // but the floater still shows.
  const RenderOutput after = renderer.render(f.m, f.cam, f.colour_settings());
  EXPECT_GT(psnr(after.color, f.target.data), 30.0);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(after.color[3 * fp + k], before.color[3 * fp + k], 0.05f);
}

// A mask that missed object 1 (its half shows background) pulls object 1's
// sigma* down; protected by its votes, object 1 keeps its sigma* and its
// shape, while the floater, unprotected, still leaves the mask.
TEST(ObjectLoss, ProtectedGaussiansKeepTheirInstanceOpacityAgainstAMissedMask) {
  FloaterScene f;
  IdMap missed = f.ids;
  for (uint16_t& id : missed.ids)
    if (id == 1) id = 0;
  const float start = f.sigma_star(0);
  FloaterScene unprotected = f;
  unprotected.train(missed, 300);
  EXPECT_LT(unprotected.sigma_star(0), 0.5f);  // the hole the miss punches

  const std::vector<uint8_t> keep = {1, 1, 0};
  // The object loss does not reach a protected Gaussian's position or shape:
  // exactly no gradient, where the unprotected one gets some. (Over training
  // it still moves a little: Adam's normalised steps turn the colour loss's
  // rounding, whatever its size, into steps of the learning rate's size, so
  // how far it moves depends on the build's rounding, not on the loss.)
  const GaussianGradients plain = FloaterScene().object_loss_gradients(missed, nullptr);
  const GaussianGradients held = FloaterScene().object_loss_gradients(missed, &keep);
  double plain_geometry = 0;
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(held.means[k], 0.f);
    EXPECT_EQ(held.log_scales[k], 0.f);
    plain_geometry += std::abs(plain.means[k]) + std::abs(plain.log_scales[k]);
  }
  EXPECT_GT(plain_geometry, 0.0);
  f.train(missed, 300, &keep);
  EXPECT_GE(f.sigma_star(0), f.sigma(0));
  EXPECT_NEAR(f.sigma_star(0), start, 0.02f);
  EXPECT_GT(f.sigma_star(1), 0.9f);
  EXPECT_LT(f.sigma_star(f.kFloater), 0.05f);
}

// The unprotected labels must not meet any ID a map may show, even IDs no
// Gaussian carries (a map's object 9 in a model labelled up to 5).
TEST(ObjectLoss, SplitLabelOffsetPassesEveryMapId) {
  EXPECT_EQ(split_label_offset({0, 5, 3}), 65536);
  EXPECT_EQ(split_label_offset({70000}), 70001);
}

TEST(ObjectLoss, SplitLabelsMoveOnlyTheUnprotected) {
  EXPECT_EQ(split_labels({1, 2, 0, 2}, {1, 0, 0, 1}, 10), (std::vector<int32_t>{1, 12, 10, 2}));
  EXPECT_THROW(split_labels({1, 2}, {1}, 10), std::invalid_argument);
}

TEST(ObjectLoss, SplitLossIsThePlainLossOfTheSums) {
  IdMap ids(3, 2);
  ids.ids = {1, 1, 2, 0, 2, 1};
  // Planes P_1, P_2 (protected Gaussians), then U_1, U_2 (the others).
  const std::vector<float> split = {0.6f, 0.1f, 0.5f,  0.0f,  0.3f, 0.2f,  0.05f, 0.3f,
                                    0.1f, 0.4f, 0.2f,  0.01f, 0.2f, 0.1f,  0.3f,  0.3f,
                                    0.2f, 0.1f, 0.15f, 0.5f,  0.1f, 0.05f, 0.6f,  0.3f};
  std::vector<float> sums(12), g_split, g_plain;
  for (size_t k = 0; k < 12; ++k) sums[k] = split[k] + split[12 + k];
  EXPECT_EQ(split_object_loss(split, {1, 2}, ids, 0.1f, &g_split),
            object_loss(sums, {1, 2}, ids, 0.1f, &g_plain));
  ASSERT_EQ(g_split.size(), 24u);
  for (size_t k = 0; k < 12; ++k) {
    EXPECT_EQ(g_split[k], g_plain[k]);
    EXPECT_EQ(g_split[12 + k], g_plain[k]);
  }
  EXPECT_THROW(split_object_loss(sums, {1, 2}, ids, 0.1f, nullptr), std::invalid_argument);
}

TEST(ObjectLoss, KeepInMaskRaisesOnlyProtectedSigmaStarBelowSigma) {
  std::vector<float> star = {-2.f, 1.f, -2.f, 1.f};
  const std::vector<float> sigma = {0.f, 0.f, 0.f, 0.f};
  keep_in_mask(star, sigma, {1, 1, 0, 0});
  EXPECT_EQ(star, (std::vector<float>{0.f, 1.f, -2.f, 1.f}));
  EXPECT_THROW(keep_in_mask(star, sigma, {1}), std::invalid_argument);
}

TEST(ObjectLoss, ProtectedGaussiansAreReadFromTheVotesAgreement) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("op2gs-agreement-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  write_npy_f64(dir / "a.npy", {0.95, 0.5, 0.9, 0.0}, {4});
  EXPECT_EQ(read_protected_gaussians(dir / "a.npy", 0.9f, 4), (std::vector<uint8_t>{1, 0, 1, 0}));
  // Agreements of another model, or no agreement file at all, are named.
  EXPECT_THROW(read_protected_gaussians(dir / "a.npy", 0.9f, 5), InputError);
  EXPECT_THROW(read_protected_gaussians(dir / "none.npy", 0.9f, 4), InputError);
  ObjectLossOptions o;
  o.protected_agreement = 0.9f;
  EXPECT_THROW(o.Check(), std::invalid_argument);  // no file named
  o.label_agreement = dir / "a.npy";
  EXPECT_NO_THROW(o.Check());
  o.protected_agreement = 1.5f;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  std::filesystem::remove_all(dir);
}

TEST(ObjectLoss, TheVotesTrackCorrectionsAreRead) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("op2gs-corrections-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  write_text_atomically(dir / "summary.json", R"({"joined_ids": [{"kept": 2, "joined": [11, 14]}],
      "merged_segments": [{"view": "frame_00003.png", "id": 5, "covers": [8]}]})");
  ObjectLossOptions o;
  read_id_corrections(dir / "summary.json", o);
  EXPECT_EQ(o.id_remap, (std::map<int32_t, int32_t>{{11, 2}, {14, 2}}));
  EXPECT_EQ(o.ignored_ids.at("frame_00003.png"), std::vector<int32_t>{5});
  IdMap m(2, 1);
  m.ids = {11, 3};
  remap_ids(m, o.id_remap);
  EXPECT_EQ(m.ids, (std::vector<uint16_t>{2, 3}));
  // A summary without corrections changes nothing; a broken one is named.
  ObjectLossOptions plain;
  write_text_atomically(dir / "plain.json", R"({"gaussians": 3})");
  read_id_corrections(dir / "plain.json", plain);
  EXPECT_TRUE(plain.id_remap.empty() && plain.ignored_ids.empty());
  write_text_atomically(dir / "bad.json", R"({"joined_ids": [{"kept": "x"}]})");
  EXPECT_THROW(read_id_corrections(dir / "bad.json", plain), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace splat
