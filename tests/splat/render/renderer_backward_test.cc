// Finite-difference checks of every gradient of the CPU renderer, against
// the double-precision reference renderer.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <set>
#include <string>

#include "splat/render/renderer.h"
#include "tests/splat/render/reference_renderer.h"
#include "tests/splat/render/scenes.h"

namespace splat {
namespace {

using testing_scenes::random_scene;
using testing_scenes::test_camera;

// The analytic gradient arrays, in the order of reference::Params::arrays().
std::vector<const std::vector<float>*> gradient_arrays(const GaussianGradients& g) {
  return {&g.means,
          &g.sh_dc,
          &g.sh_rest,
          &g.opacity_logits,
          &g.log_scales,
          &g.rotations,
          &g.instance_opacity_logits};
}
const char* kArrayNames[] = {"means",      "sh_dc",     "sh_rest",         "opacity",
                             "log_scales", "rotations", "instance_opacity"};

// Central differences of loss(params) for every parameter, compared with the
// analytic gradient array by array.
// Arrays named in must_be_zero are checked to have exactly zero analytic
// gradient (the loss does not reach them); every other array must have some.
void check_gradients(const reference::Params& base, const GaussianGradients& analytic,
                     const std::function<double(const reference::Params&)>& loss,
                     const std::set<std::string>& must_be_zero = {}) {
  const auto grads = gradient_arrays(analytic);
  reference::Params p = base;
  const auto arrays = p.arrays();
  for (size_t a = 0; a < arrays.size(); ++a) {
    std::vector<double> fd(arrays[a]->size());
    double scale = 0;
    for (size_t k = 0; k < fd.size(); ++k) {
      const double h = 1e-5, keep = (*arrays[a])[k];
      (*arrays[a])[k] = keep + h;
      const double up = loss(p);
      (*arrays[a])[k] = keep - h;
      const double down = loss(p);
      (*arrays[a])[k] = keep;
      fd[k] = (up - down) / (2 * h);
      scale = std::max(scale, std::abs(fd[k]));
    }
    if (must_be_zero.count(kArrayNames[a])) {
      for (float v : *grads[a]) ASSERT_EQ(v, 0.f) << kArrayNames[a];
      EXPECT_LT(scale, 1e-6) << kArrayNames[a];
      continue;
    }
    // Every array must be exercised, or the comparison below proves nothing.
    EXPECT_GT(scale, 1e-6) << kArrayNames[a] << " has no gradient in this scene";
    size_t bad = 0;
    for (size_t k = 0; k < fd.size(); ++k) {
      const double an = (*grads[a])[k];
      if (std::abs(an - fd[k]) > 2e-3 * scale + 1e-2 * std::abs(fd[k]) + 1e-6) {
        if (++bad <= 5)
          ADD_FAILURE() << kArrayNames[a] << "[" << k << "]: analytic " << an
                        << " vs finite difference " << fd[k] << " (array scale " << scale << ")";
      }
    }
    EXPECT_EQ(bad, 0u) << kArrayNames[a];
  }
}

std::vector<float> random_weights(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<float> w(n);
  for (float& x : w) x = u(rng);
  return w;
}

// sum w_i v_i; no weights: 0.
double dot(const std::vector<float>& w, const std::vector<double>& v) {
  if (w.empty()) return 0;
  double s = 0;
  for (size_t i = 0; i < v.size(); ++i) s += w[i] * v[i];
  return s;
}

// Random weights on colour, alpha and depth (seeds seed, seed + 1, seed + 2),
// so that a scalar loss, weighted_sum, exercises all three outputs.
RenderOutputGradients colour_alpha_depth_weights(const Camera& cam, unsigned seed) {
  const size_t pixels = size_t(cam.width) * cam.height;
  RenderOutputGradients g;
  g.color = random_weights(3 * pixels, seed);
  g.alpha = random_weights(pixels, seed + 1);
  g.depth = random_weights(pixels, seed + 2);
  return g;
}

// A random scene of `gaussians` rendered in colour without depth, some of
// it culled, and random weights on its colour: what the tests of what the
// backward pass writes start from.
struct ColourRender {
  GaussianModel m;
  Camera cam;
  RenderSettings s;
  RenderOutputGradients g;
  std::unique_ptr<RenderState> state;
};
ColourRender colour_render(const CpuRenderer& renderer, size_t gaussians, unsigned scene_seed,
                           unsigned weight_seed) {
  ColourRender r{random_scene(gaussians, scene_seed), test_camera(32, 24), {}, {}, nullptr};
  r.s.depth = false;
  r.g.color = random_weights(3 * size_t(r.cam.width) * r.cam.height, weight_seed);
  renderer.render(r.m, r.cam, r.s, &r.state);
  return r;
}

double weighted_sum(const RenderOutputGradients& g, const reference::Output& o) {
  return dot(g.color, o.color) + dot(g.alpha, o.alpha) + dot(g.depth, o.depth);
}

// A small scene where no ray terminates, so every output is smooth in the
// parameters (termination is a step, which finite differences cannot see).
GaussianModel smooth_scene(unsigned seed) {
  GaussianModel m = random_scene(14, seed, 3, /*edge_cases=*/false);
  for (size_t i = 0; i < m.size(); ++i) m.opacity_logits[i] = std::min(m.opacity_logits[i], 0.5f);
  // One Gaussian bright enough to hit the 0.99 alpha clamp near its centre.
  m.opacity_logits[5] = 8.f;
  return m;
}

// The analytic gradient of weighted_sum(g, render) against finite
// differences through the reference renderer (no object loss: sigma* gets none).
void expect_weighted_sum_gradients(const GaussianModel& m, const Camera& cam,
                                   const RenderSettings& s, const RenderOutputGradients& g) {
  const CpuRenderer renderer;
  std::unique_ptr<RenderState> state;
  renderer.render(m, cam, s, &state);
  const GaussianGradients analytic = renderer.backward(m, cam, s, *state, g);
  check_gradients(
      reference::Params::from(m), analytic,
      [&](const reference::Params& p) { return weighted_sum(g, reference::render(p, cam, s)); },
      {"instance_opacity"});
}

class GradientsMatchFiniteDifferences : public ::testing::TestWithParam<unsigned> {};

TEST_P(GradientsMatchFiniteDifferences, ColourAlphaAndDepthLoss) {
  const Camera cam = test_camera(40, 30);
  RenderSettings s;
  s.background[0] = 0.3f, s.background[2] = 0.7f;
  expect_weighted_sum_gradients(smooth_scene(GetParam()), cam, s,
                                colour_alpha_depth_weights(cam, 1));
}

// Training's settings: colour alone, no depth output, a colour loss.
TEST_P(GradientsMatchFiniteDifferences, TrainingColourLoss) {
  const Camera cam = test_camera(40, 30);
  RenderSettings s;
  s.background[0] = 0.3f, s.background[2] = 0.7f;
  s.depth = false;
  RenderOutputGradients g;
  g.color = random_weights(3 * size_t(cam.width) * cam.height, GetParam());
  expect_weighted_sum_gradients(smooth_scene(GetParam()), cam, s, g);
}

TEST_P(GradientsMatchFiniteDifferences, ObjectLossWithTransmittanceHeld) {
  const GaussianModel m = smooth_scene(GetParam());
  const Camera cam = test_camera(40, 30);
  RenderSettings s;
  s.instance_labels = {1, 3, 2};
  const size_t pixels = size_t(cam.width) * cam.height;
  RenderOutputGradients g;
  g.instance_maps = random_weights(3 * pixels, 4);
  const CpuRenderer renderer;
  std::unique_ptr<RenderState> state;
  renderer.render(m, cam, s, &state);
  const GaussianGradients analytic = renderer.backward(m, cam, s, *state, g);
  const reference::Params base = reference::Params::from(m);
  check_gradients(base, analytic,
                  [&](const reference::Params& p) {
                    return dot(g.instance_maps, reference::instance_maps_frozen_T(base, p, cam, s));
                  },
                  {"sh_dc", "sh_rest", "opacity"});
}

INSTANTIATE_TEST_SUITE_P(Seeds, GradientsMatchFiniteDifferences, ::testing::Values(11u, 12u, 13u));

// The gradients of a random weighting of the occupancy maps s asks for.
GaussianGradients occupancy_gradients(const GaussianModel& m, const Camera& cam,
                                      const RenderSettings& s, unsigned seed,
                                      const BackwardSettings& b = {}) {
  RenderOutputGradients g;
  g.instance_maps = random_weights(s.instance_labels.size() * cam.width * cam.height, seed);
  const CpuRenderer renderer;
  std::unique_ptr<RenderState> state;
  renderer.render(m, cam, s, &state);
  return renderer.backward(m, cam, s, b, *state, g);
}

TEST(RendererBackward, ObjectLossNeverReachesOpacityOrColour) {
  const GaussianModel m = random_scene(400, 21);
  const Camera cam = test_camera(64, 48);
  RenderSettings s;
  s.instance_labels = {1, 2, 4};
  const GaussianGradients grads = occupancy_gradients(m, cam, s, 5);
  double star = 0, geometry = 0;
  for (size_t i = 0; i < m.size(); ++i) {
    ASSERT_EQ(grads.opacity_logits[i], 0.f);
    for (int c = 0; c < 3; ++c) ASSERT_EQ(grads.sh_dc[3 * i + c], 0.f);
    for (int k = 0; k < 45; ++k) ASSERT_EQ(grads.sh_rest[45 * i + k], 0.f);
    star += std::abs(grads.instance_opacity_logits[i]);
    for (int k = 0; k < 3; ++k)
      geometry += std::abs(grads.means[3 * i + k]) + std::abs(grads.log_scales[3 * i + k]);
    // Gaussians of unselected labels get no sigma* gradient.
    if (m.labels[i] == 0 || m.labels[i] == 3) {
      ASSERT_EQ(grads.instance_opacity_logits[i], 0.f);
    }
  }
  EXPECT_GT(star, 0.0);
  EXPECT_GT(geometry, 0.0);
}

// The first maps_without_geometry_gradient maps reach sigma* only: their
// Gaussians get no geometry gradient from them, and everything else is as
// without the setting.
TEST(RendererBackward, MapsWithoutGeometryGradientReachSigmaStarOnly) {
  const GaussianModel m = random_scene(400, 23);
  const Camera cam = test_camera(64, 48);
  RenderSettings s;
  s.color = false;
  s.instance_labels = {1, 2, 4};
  const GaussianGradients all = occupancy_gradients(m, cam, s, 6);
  BackwardSettings b;
  b.maps_without_geometry_gradient = 1;  // label 1's map
  const GaussianGradients cut = occupancy_gradients(m, cam, s, 6, b);
  double label_1_star = 0;
  for (size_t i = 0; i < m.size(); ++i) {
    EXPECT_EQ(cut.instance_opacity_logits[i], all.instance_opacity_logits[i]);
    for (int k = 0; k < 3; ++k) {
      if (m.labels[i] == 1) {
        EXPECT_EQ(cut.means[3 * i + k], 0.f);
        EXPECT_EQ(cut.log_scales[3 * i + k], 0.f);
      } else {
        EXPECT_FLOAT_EQ(cut.means[3 * i + k], all.means[3 * i + k]);
        EXPECT_FLOAT_EQ(cut.log_scales[3 * i + k], all.log_scales[3 * i + k]);
      }
    }
    if (m.labels[i] == 1) label_1_star += std::abs(cut.instance_opacity_logits[i]);
  }
  EXPECT_GT(label_1_star, 0.0);
}

TEST(RendererBackward, ColourLossNeverReachesInstanceOpacity) {
  const GaussianModel m = random_scene(400, 22);
  const Camera cam = test_camera(64, 48);
  RenderSettings s;
  s.instance_labels = {1, 2};
  RenderOutputGradients g;
  g.color = random_weights(3 * size_t(cam.width) * cam.height, 6);
  const CpuRenderer renderer;
  std::unique_ptr<RenderState> state;
  renderer.render(m, cam, s, &state);
  const GaussianGradients grads = renderer.backward(m, cam, s, *state, g);
  for (float v : grads.instance_opacity_logits) ASSERT_EQ(v, 0.f);
}

// The backward pass is linear in the output gradients: with the colour and
// the occupancy maps' gradients together (training's stage two, where only
// the Gaussians whose label has a map take the instance terms), each
// parameter's gradient is the sum of the two passes apart.
TEST(RendererBackward, ColourAndObjectLossTogetherAreTheSumOfEach) {
  const GaussianModel m = random_scene(400, 24);
  const Camera cam = test_camera(64, 48);
  const size_t pixels = size_t(cam.width) * cam.height;
  RenderSettings s;
  s.instance_labels = {1, 2};  // labels 0 and 3 have no map
  const std::vector<float> color = random_weights(3 * pixels, 8);
  const std::vector<float> maps = random_weights(2 * pixels, 9);
  auto backward = [&](bool with_color, bool with_maps) {
    RenderOutputGradients g;
    if (with_color) g.color = color;
    if (with_maps) g.instance_maps = maps;
    const CpuRenderer renderer;
    std::unique_ptr<RenderState> state;
    renderer.render(m, cam, s, &state);
    return renderer.backward(m, cam, s, *state, g);
  };
  const GaussianGradients both = backward(true, true), colour_only = backward(true, false),
                          maps_only = backward(false, true);
  auto expect_sum = [](const std::vector<float>& total, const std::vector<float>& a,
                       const std::vector<float>& b, const char* name) {
    ASSERT_EQ(total.size(), a.size());
    for (size_t i = 0; i < total.size(); ++i)
      ASSERT_NEAR(total[i], a[i] + b[i], 1e-4 * (std::abs(a[i]) + std::abs(b[i])) + 1e-7)
          << name << " " << i;
  };
  expect_sum(both.means, colour_only.means, maps_only.means, "means");
  expect_sum(both.log_scales, colour_only.log_scales, maps_only.log_scales, "log_scales");
  expect_sum(both.rotations, colour_only.rotations, maps_only.rotations, "rotations");
  expect_sum(both.opacity_logits, colour_only.opacity_logits, maps_only.opacity_logits, "opacity");
  expect_sum(both.sh_dc, colour_only.sh_dc, maps_only.sh_dc, "sh_dc");
  expect_sum(both.instance_opacity_logits, colour_only.instance_opacity_logits,
             maps_only.instance_opacity_logits, "instance_opacity");
  double star = 0;
  for (float v : both.instance_opacity_logits) star += std::abs(v);
  EXPECT_GT(star, 0.0);
}

// The gradient of a colour and object loss through the rasterizer's loop over
// lanes (taken when the loss also has alpha or depth terms, here zero) and,
// with AVX-512 or AVX2, through the loop that keeps its sums in registers (a
// block a register, or an 8-lane half; training's losses): the same values,
// to the bit but for the sign of zeros (which == does not tell apart).
TEST(RendererBackward, GradientIsTheSameThroughEitherLaneLoop) {
  const GaussianModel m = random_scene(400, 31);
  const Camera cam = test_camera(70, 45);  // lanes off the image in the last blocks
  const size_t pixels = size_t(cam.width) * cam.height;
  RenderSettings s;
  s.instance_labels = {1, 2};  // labels 0, 3 and 4 have no map
  RenderOutputGradients g;
  g.color = random_weights(3 * pixels, 5);
  g.instance_maps = random_weights(2 * pixels, 6);
  auto backward = [&](const RenderOutputGradients& grads) {
    const CpuRenderer renderer;
    std::unique_ptr<RenderState> state;
    renderer.render(m, cam, s, &state);
    return renderer.backward(m, cam, s, *state, grads);
  };
  RenderOutputGradients with_zero_terms = g;
  with_zero_terms.alpha.assign(pixels, 0.f);
  with_zero_terms.depth.assign(pixels, 0.f);
  const GaussianGradients in_halves = backward(g), in_lanes = backward(with_zero_terms);
  const auto a = gradient_arrays(in_halves), b = gradient_arrays(in_lanes);
  for (size_t j = 0; j < a.size(); ++j) EXPECT_EQ(*a[j], *b[j]) << kArrayNames[j];
  double star = 0;
  for (float v : in_halves.instance_opacity_logits) star += std::abs(v);
  EXPECT_GT(star, 0.0);
}

TEST(RendererBackward, Mean2dNdcIsPixelGradientTimesHalfImageSize) {
  // The densification statistic against finite differences w.r.t. the
  // projected 2D mean itself (in double, through the reference renderer).
  const GaussianModel m = smooth_scene(24);
  const Camera cam = test_camera(48, 40);
  RenderSettings s;
  RenderOutputGradients g;
  g.color = random_weights(3 * size_t(cam.width) * cam.height, 7);
  const CpuRenderer renderer;
  std::unique_ptr<RenderState> state;
  renderer.render(m, cam, s, &state);
  const GaussianGradients grads = renderer.backward(m, cam, s, *state, g);
  reference::Params p = reference::Params::from(m);
  p.mean2d_offset.assign(2 * m.size(), 0.0);
  int checked = 0;
  for (size_t i = 0; i < m.size(); ++i) {
    if (!grads.visible[i]) continue;
    for (int axis = 0; axis < 2; ++axis) {
      const double h = 1e-6;
      p.mean2d_offset[2 * i + axis] = h;
      const double up = dot(g.color, reference::render(p, cam, s).color);
      p.mean2d_offset[2 * i + axis] = -h;
      const double down = dot(g.color, reference::render(p, cam, s).color);
      p.mean2d_offset[2 * i + axis] = 0;
      const double expected = (up - down) / (2 * h) * 0.5 * (axis == 0 ? cam.width : cam.height);
      EXPECT_NEAR(grads.mean2d_ndc[2 * i + axis], expected, 1e-2 * std::abs(expected) + 1e-3)
          << "Gaussian " << i << " axis " << axis;
      ++checked;
    }
  }
  EXPECT_GE(checked, 16);
}

TEST(RendererBackward, CameraGradientMatchesFiniteDifferences) {
  // dLoss/d(rho, omega) of the camera's pose, through colour (with the view
  // direction of SH), alpha and depth. (The object loss holds T_i constant,
  // which a moved camera does not, so it has no finite-difference twin here.)
  const GaussianModel m = smooth_scene(25);
  const Camera cam = test_camera(40, 30);
  RenderSettings s;
  BackwardSettings b;
  b.camera_gradient = true;
  const RenderOutputGradients g = colour_alpha_depth_weights(cam, 8);
  const CpuRenderer renderer;
  std::unique_ptr<RenderState> state;
  renderer.render(m, cam, s, &state);
  const GaussianGradients grads = renderer.backward(m, cam, s, b, *state, g);
  const reference::Params base = reference::Params::from(m);
  auto loss = [&](const Camera& c) { return weighted_sum(g, reference::render(base, c, s)); };
  for (int k = 0; k < 6; ++k) {
    const double h = 1e-6;
    Eigen::Vector3d rho = Eigen::Vector3d::Zero(), omega = Eigen::Vector3d::Zero();
    (k < 3 ? rho[k] : omega[k - 3]) = h;
    const double up = loss(moved_in_camera_frame(cam, rho, omega));
    const double down = loss(moved_in_camera_frame(cam, -rho, -omega));
    const double expected = (up - down) / (2 * h);
    EXPECT_GT(std::abs(expected), 1e-3) << "component " << k << " has no gradient in this scene";
    EXPECT_NEAR(grads.camera[k], expected, 1e-2 * std::abs(expected) + 1e-3) << "component " << k;
  }
}

TEST(RendererBackward, NoCameraGradientUnlessAsked) {
  const GaussianModel m = random_scene(50, 26);
  const Camera cam = test_camera(32, 24);
  RenderSettings s;
  RenderOutputGradients g;
  g.color = random_weights(3 * size_t(cam.width) * cam.height, 12);
  const CpuRenderer renderer;
  std::unique_ptr<RenderState> state;
  renderer.render(m, cam, s, &state);
  const GaussianGradients grads = renderer.backward(m, cam, s, *state, g);
  for (double v : grads.camera) EXPECT_EQ(v, 0.0);
}

// Without the camera's gradient the Gaussians go back a batch of 16 at a
// time (project_backward.cc's backward_geometry and backward_color_lanes,
// the SH coefficients turned into lanes by sh_lanes.h); with it, one at a
// time (backward_one). The two write the same gradients up to float
// rounding, for every Gaussian of a scene with culled ones, clamped
// Jacobians and a partial last batch (50 Gaussians), at every SH degree.
class BatchedMatchesOneAtATime : public ::testing::TestWithParam<int> {};

TEST_P(BatchedMatchesOneAtATime, EveryGradient) {
  const GaussianModel m = random_scene(50, 27);
  const Camera cam = test_camera(32, 24);
  RenderOutputGradients g = colour_alpha_depth_weights(cam, 31);
  const CpuRenderer renderer;
  RenderSettings s;
  s.sh_degree = GetParam();
  BackwardSettings one_at_a_time;
  one_at_a_time.camera_gradient = true;
  std::unique_ptr<RenderState> state;
  renderer.render(m, cam, s, &state);
  const GaussianGradients a = renderer.backward(m, cam, s, *state, g);
  const GaussianGradients b = renderer.backward(m, cam, s, one_at_a_time, *state, g);
  EXPECT_EQ(a.visible, b.visible);
  size_t visible = 0, culled = 0;
  for (uint8_t v : a.visible) (v ? visible : culled)++;
  EXPECT_GT(visible, 10u);
  EXPECT_GT(culled, 0u);
  const auto arrays_a = gradient_arrays(a), arrays_b = gradient_arrays(b);
  for (size_t k = 0; k < arrays_a.size(); ++k) {
    const std::vector<float>&x = *arrays_a[k], &y = *arrays_b[k];
    ASSERT_EQ(x.size(), y.size());
    float scale = 0;
    for (float v : y) scale = std::max(scale, std::abs(v));
    for (size_t i = 0; i < x.size(); ++i)
      ASSERT_NEAR(x[i], y[i], 1e-4f * scale + 1e-4f * std::abs(y[i]))
          << kArrayNames[k] << "[" << i << "]";
  }
  EXPECT_EQ(a.mean2d_ndc, b.mean2d_ndc);
}
INSTANTIATE_TEST_SUITE_P(ShDegrees, BatchedMatchesOneAtATime, ::testing::Values(0, 1, 2, 3));

// The batches write every gradient of every Gaussian, culled or not, SH
// bands above the active degree included (the trainer reuses its gradient
// arrays from view to view): nothing of a NaN-filled output survives.
// zero_culled_gradients false (the trainer's): the visible Gaussians'
// gradients as before, the culled ones' left as they were and marked.
TEST(RendererBackward, CulledGradientsLeftUnwrittenWhenAsked) {
  const CpuRenderer renderer;
  // Some Gaussians behind the camera or off the image.
  const auto [m, cam, s, g, state] = colour_render(renderer, 60, 29, 5);
  const GaussianGradients zeroed = renderer.backward(m, cam, s, *state, g);
  BackwardSettings unwritten;
  unwritten.zero_culled_gradients = false;
  GaussianGradients out;
  out.resize(m.size());
  for (auto* a : gradient_arrays(out))
    const_cast<std::vector<float>*>(a)->assign(a->size(), std::nanf(""));
  renderer.backward(m, cam, s, unwritten, *state, g, out);
  EXPECT_EQ(out.visible, zeroed.visible);
  size_t culled = 0;
  const auto written = gradient_arrays(out), expected = gradient_arrays(zeroed);
  for (size_t k = 0; k < written.size(); ++k) {
    const size_t width = written[k]->size() / m.size();
    for (size_t i = 0; i < written[k]->size(); ++i) {
      if (zeroed.visible[i / width])
        ASSERT_EQ((*written[k])[i], (*expected[k])[i]) << kArrayNames[k] << "[" << i << "]";
      else
        ASSERT_TRUE(std::isnan((*written[k])[i])) << kArrayNames[k] << "[" << i << "]";
    }
  }
  for (uint8_t v : out.visible) culled += v == 0;
  EXPECT_GT(culled, 0u) << "the scene must have culled Gaussians";
}

// A sink of the SH-rest gradients (the trainer's Adam step) takes every
// Gaussian once, in view where `visible` says so, with the rows the gradient
// array gets without it; the array is then left unwritten.
TEST(RendererBackward, ShRestSinkTakesTheRowsTheArrayWouldGet) {
  struct Collect final : ShRestGradientSink {
    std::vector<float> rows;
    std::vector<int> taken;
    std::vector<uint8_t> visible;
    void take(size_t first, size_t count, const float* batch, uint32_t in_view) override {
      for (size_t l = 0; l < count; ++l) {
        ++taken[first + l];
        visible[first + l] = in_view >> l & 1;
        if (in_view >> l & 1)
          std::copy_n(batch + kShRestFloats * l, kShRestFloats, &rows[kShRestFloats * (first + l)]);
      }
    }
  };
  const CpuRenderer renderer;
  const auto [m, cam, s, g, state] = colour_render(renderer, 70, 31, 6);  // batches, some culled
  const GaussianGradients plain = renderer.backward(m, cam, s, *state, g);
  Collect sink;
  sink.rows.assign(plain.sh_rest.size(), std::nanf(""));
  sink.taken.assign(m.size(), 0);
  sink.visible.assign(m.size(), 0);
  BackwardSettings with_sink;
  with_sink.zero_culled_gradients = false;
  with_sink.sh_rest_sink = &sink;
  GaussianGradients out;
  out.resize(m.size());
  out.sh_rest.assign(out.sh_rest.size(), std::nanf(""));
  renderer.backward(m, cam, s, with_sink, *state, g, out);
  EXPECT_EQ(sink.taken, std::vector<int>(m.size(), 1));
  EXPECT_EQ(sink.visible, plain.visible);
  size_t in_view = 0;
  for (size_t i = 0; i < m.size(); ++i) {
    in_view += plain.visible[i];
    for (int k = 0; k < kShRestFloats; ++k) {
      const size_t at = kShRestFloats * i + k;
      ASSERT_TRUE(std::isnan(out.sh_rest[at])) << "sh_rest[" << at << "] written";
      if (plain.visible[i]) {
        ASSERT_EQ(sink.rows[at], plain.sh_rest[at]) << "sh_rest[" << at << "]";
      }
    }
  }
  EXPECT_GT(in_view, 16u);
  EXPECT_LT(in_view, m.size()) << "the scene must have culled Gaussians";
  // The one-by-one backward pass (camera gradient) has no batches to give.
  with_sink.camera_gradient = true;
  EXPECT_THROW(renderer.backward(m, cam, s, with_sink, *state, g, out), std::invalid_argument);
}

TEST(RendererBackward, BatchedBackwardWritesEveryGradient) {
  const GaussianModel m = random_scene(50, 28);
  const Camera cam = test_camera(32, 24);
  const CpuRenderer renderer;
  for (const bool colour : {true, false}) {
    RenderSettings s;
    s.sh_degree = 1;
    s.color = colour;
    RenderOutputGradients g = colour_alpha_depth_weights(cam, 41);
    if (!colour) g.color.clear();
    std::unique_ptr<RenderState> state;
    renderer.render(m, cam, s, &state);
    GaussianGradients out;
    out.resize(m.size());
    for (auto* a : gradient_arrays(out))
      const_cast<std::vector<float>*>(a)->assign(a->size(), std::nanf(""));
    out.mean2d_ndc.assign(out.mean2d_ndc.size(), std::nanf(""));
    renderer.backward(m, cam, s, *state, g, out);
    const GaussianGradients fresh = renderer.backward(m, cam, s, *state, g);
    const auto written = gradient_arrays(out), expected = gradient_arrays(fresh);
    for (size_t k = 0; k < written.size(); ++k)
      for (size_t i = 0; i < written[k]->size(); ++i)
        ASSERT_EQ((*written[k])[i], (*expected[k])[i]) << kArrayNames[k] << "[" << i << "]";
    for (size_t i = 0; i < m.size(); ++i)
      for (int k = 9; k < kShRestFloats; ++k) ASSERT_EQ(out.sh_rest[kShRestFloats * i + k], 0.f);
    EXPECT_EQ(out.mean2d_ndc, fresh.mean2d_ndc);
  }
}

}  // namespace
}  // namespace splat
