#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>

#include "splat/render/renderer.h"
#include "tests/splat/render/reference_renderer.h"
#include "tests/splat/render/scenes.h"

namespace splat {
namespace {

using testing_scenes::random_scene;
using testing_scenes::test_camera;

// |fast - ref| <= 1e-5 relative, with a floor of 1e-5 for values near zero.
void expect_close(std::span<const float> fast, const std::vector<double>& ref, const char* what) {
  ASSERT_EQ(fast.size(), ref.size()) << what;
  double worst = 0;
  size_t where = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    const double err = std::abs(fast[i] - ref[i]) / std::max(std::abs(ref[i]), 1.0);
    if (err > worst) worst = err, where = i;
  }
  EXPECT_LE(worst, 1e-5) << what << " at " << where << ": " << fast[where] << " vs " << ref[where];
}

void expect_same_labels(std::span<const int32_t> fast, const std::vector<int>& ref,
                        const char* what) {
  ASSERT_EQ(fast.size(), ref.size()) << what;
  size_t differ = 0;
  for (size_t i = 0; i < ref.size(); ++i) differ += fast[i] != ref[i];
  EXPECT_EQ(differ, 0u) << what;
}

RenderSettings full_settings() {
  RenderSettings s;
  s.background[0] = 0.2f, s.background[1] = 0.5f, s.background[2] = 0.9f;
  s.instance_labels = {3, 1, 4};
  s.instance_label_map = s.baseline_label_map = true;
  return s;
}

class ForwardMatchesReference : public ::testing::TestWithParam<unsigned> {};

TEST_P(ForwardMatchesReference, OnRandomScenes) {
  const GaussianModel m = random_scene(300, GetParam());
  const Camera cam = test_camera(70, 45);  // not a multiple of the tile size
  for (int degree : {0, 3}) {
    RenderSettings s = full_settings();
    s.sh_degree = degree;
    const RenderOutput fast = CpuRenderer().render(m, cam, s);
    const reference::Output ref = reference::render(reference::Params::from(m), cam, s);
    expect_close(fast.color, ref.color, "color");
    expect_close(fast.alpha, ref.alpha, "alpha");
    expect_close(fast.depth, ref.depth, "depth");
    expect_close(fast.instance_maps, ref.instance_maps, "instance maps");
    EXPECT_EQ(fast.instance_map_labels, (std::vector<int32_t>{3, 1, 4}));
    expect_same_labels(fast.instance_label, ref.instance_label, "instance label map");
    expect_same_labels(fast.baseline_label, ref.baseline_label, "baseline label map");
    std::vector<int32_t> counts(fast.contributors.begin(), fast.contributors.end());
    expect_same_labels(counts, ref.contributors, "contributors");
  }
}

// Training renders colour alone (no depth, maps or labels): a path of its own.
TEST_P(ForwardMatchesReference, TrainingRenderOnRandomScenes) {
  const GaussianModel m = random_scene(300, GetParam());
  const Camera cam = test_camera(70, 45);
  RenderSettings s;
  s.background[0] = 0.2f, s.background[1] = 0.5f, s.background[2] = 0.9f;
  s.depth = false;
  const RenderOutput fast = CpuRenderer().render(m, cam, s);
  const reference::Output ref = reference::render(reference::Params::from(m), cam, s);
  expect_close(fast.color, ref.color, "color");
  expect_close(fast.alpha, ref.alpha, "alpha");
  EXPECT_TRUE(fast.depth.empty());
  std::vector<int32_t> counts(fast.contributors.begin(), fast.contributors.end());
  expect_same_labels(counts, ref.contributors, "contributors");
}

INSTANTIATE_TEST_SUITE_P(Seeds, ForwardMatchesReference, ::testing::Values(1u, 2u, 3u, 4u));

TEST(Renderer, AllObjectMapsMatchReferenceAndSumToOccupancy) {
  const GaussianModel m = random_scene(250, 7, /*labels=*/6);
  const Camera cam = test_camera();
  RenderSettings s;
  s.all_instance_labels = true;
  const RenderOutput fast = CpuRenderer().render(m, cam, s);
  const reference::Output ref = reference::render(reference::Params::from(m), cam, s);
  EXPECT_EQ(fast.instance_map_labels, (std::vector<int32_t>{1, 2, 3, 4, 5, 6}));
  expect_close(fast.instance_maps, ref.instance_maps, "all-object maps");
}

// Labels from other mask tools need not be contiguous: a plane per label the
// model holds, none for the IDs in between.
TEST(Renderer, AllObjectMapsSkipAbsentLabels) {
  GaussianModel m = random_scene(250, 8, /*labels=*/3);
  const int32_t sparse[] = {0, 7, 300, 65535};
  for (int32_t& l : m.labels) l = sparse[l];
  const Camera cam = test_camera();
  RenderSettings s;
  s.all_instance_labels = true;
  const RenderOutput fast = CpuRenderer().render(m, cam, s);
  const reference::Output ref = reference::render(reference::Params::from(m), cam, s);
  EXPECT_EQ(fast.instance_map_labels, (std::vector<int32_t>{7, 300, 65535}));
  EXPECT_EQ(fast.instance_maps.size(), 3u * cam.width * cam.height);
  expect_close(fast.instance_maps, ref.instance_maps, "sparse-label maps");
}

// Labels given in the settings replace the model's: splitting each object's
// Gaussians in two (stage two's vote protection) gives two maps that add up
// to the object's map, each as the reference renders the relabelled model.
TEST(Renderer, LabelsOfTheSettingsSplitAnObjectsMapInTwo) {
  const GaussianModel m = random_scene(250, 9, /*labels=*/3);
  const Camera cam = test_camera();
  RenderSettings whole;
  whole.instance_labels = {1, 2, 3};
  const RenderOutput joined = CpuRenderer().render(m, cam, whole);
  std::vector<int32_t> split = m.labels;
  for (size_t i = 1; i < split.size(); i += 2) split[i] += 10;
  RenderSettings s;
  s.labels = split;
  s.instance_labels = {1, 2, 3, 11, 12, 13};
  const RenderOutput parts = CpuRenderer().render(m, cam, s);
  GaussianModel relabelled = m;
  relabelled.labels = split;
  const reference::Output ref = reference::render(reference::Params::from(relabelled), cam, s);
  expect_close(parts.instance_maps, ref.instance_maps, "split maps");
  const size_t pixels = size_t(cam.width) * cam.height;
  double worst = 0;
  for (size_t k = 0; k < 3 * pixels; ++k)
    worst = std::max(worst,
                     double(std::abs(parts.instance_maps[k] + parts.instance_maps[3 * pixels + k] -
                                     joined.instance_maps[k])));
  EXPECT_LE(worst, 1e-5);
  split.pop_back();
  s.labels = split;
  EXPECT_THROW(CpuRenderer().render(m, cam, s), std::invalid_argument);  // one per Gaussian
}

TEST(Renderer, InstanceOnlyRenderGivesTheSameMaps) {
  const GaussianModel m = random_scene(250, 8);
  const Camera cam = test_camera();
  RenderSettings s = full_settings();
  const RenderOutput with_color = CpuRenderer().render(m, cam, s);
  auto expect_same_masks = [&](const RenderOutput& r) {
    EXPECT_TRUE(r.color.empty());
    EXPECT_EQ(r.instance_maps, with_color.instance_maps);
    EXPECT_EQ(r.instance_label, with_color.instance_label);
    EXPECT_EQ(r.baseline_label, with_color.baseline_label);
    EXPECT_EQ(r.alpha, with_color.alpha);
  };
  s.color = false;
  const RenderOutput masks_only = CpuRenderer().render(m, cam, s);
  expect_same_masks(masks_only);
  EXPECT_EQ(masks_only.depth, with_color.depth);
  // A mask query needs no depth either.
  s.depth = false;
  const RenderOutput no_depth = CpuRenderer().render(m, cam, s);
  expect_same_masks(no_depth);
  EXPECT_TRUE(no_depth.depth.empty());
}

// A render with the label maps blends in the loop over lanes; one without
// them, with AVX-512, one block a register with its state in registers, and
// on AVX2 without AVX-512 one 8-lane half at a time likewise (with or without
// the occupancy maps). Both must give the same
// bits, whichever loop a build runs.
TEST(Renderer, RenderIsTheSameWithOrWithoutTheLabelMaps) {
  for (unsigned seed : {3u, 12u}) {
    const GaussianModel m = random_scene(400, seed);
    const Camera cam = test_camera(70, 45);  // lanes off the image in the last blocks
    const RenderSettings with_labels = full_settings();
    const RenderOutput reference = CpuRenderer().render(m, cam, with_labels);
    for (bool maps : {true, false})
      for (bool depth : {true, false}) {
        RenderSettings s;
        std::copy_n(with_labels.background, 3, s.background);
        if (maps) s.instance_labels = with_labels.instance_labels;
        s.depth = depth;
        const RenderOutput r = CpuRenderer().render(m, cam, s);
        const std::string where = "seed " + std::to_string(seed) + ", maps " +
                                  std::to_string(maps) + ", depth " + std::to_string(depth);
        EXPECT_EQ(r.color, reference.color) << where;
        EXPECT_EQ(r.alpha, reference.alpha) << where;
        EXPECT_EQ(r.contributors, reference.contributors) << where;
        if (depth) {
          EXPECT_EQ(r.depth, reference.depth) << where;
        }
        if (maps) {
          EXPECT_EQ(r.instance_maps, reference.instance_maps) << where;
        }
      }
  }
}

// Outputs are not cleared when they are reused or grow (ImageBuffer), so
// every element must be written by every render: fill a reused output with
// NaN and render into it again, with each kind of settings.
TEST(Renderer, ReusedOutputIsWrittenEverywhere) {
  const GaussianModel m = random_scene(250, 11, /*labels=*/5);
  const Camera cam = test_camera(70, 45);  // partial tiles at the right and bottom
  RenderSettings all_masks;
  all_masks.color = all_masks.depth = false;
  all_masks.all_instance_labels = true;
  for (const RenderSettings& s : {full_settings(), all_masks}) {
    const RenderOutput fresh = CpuRenderer().render(m, cam, s);
    RenderOutput reused = fresh;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (auto* v : {&reused.color, &reused.alpha, &reused.depth, &reused.instance_maps})
      std::fill(v->begin(), v->end(), nan);
    std::fill(reused.contributors.begin(), reused.contributors.end(), 0xdeadbeefu);
    for (auto* v : {&reused.instance_label, &reused.baseline_label})
      std::fill(v->begin(), v->end(), -7);
    CpuRenderer().render(m, cam, s, reused);
    EXPECT_EQ(reused.color, fresh.color);
    EXPECT_EQ(reused.alpha, fresh.alpha);
    EXPECT_EQ(reused.depth, fresh.depth);
    EXPECT_EQ(reused.contributors, fresh.contributors);
    EXPECT_EQ(reused.instance_maps, fresh.instance_maps);
    EXPECT_EQ(reused.instance_label, fresh.instance_label);
    EXPECT_EQ(reused.baseline_label, fresh.baseline_label);
  }
}

TEST(Renderer, NoGaussiansGivesBackground) {
  GaussianModel m;
  RenderSettings s;
  s.background[1] = 0.25f;
  s.instance_labels = {1};
  const RenderOutput out = CpuRenderer().render(m, test_camera(), s);
  for (size_t p = 0; p < out.alpha.size(); ++p) {
    ASSERT_EQ(out.alpha[p], 0.f);
    ASSERT_EQ(out.color[3 * p + 1], 0.25f);
    ASSERT_EQ(out.instance_maps[p], 0.f);
  }
}

TEST(Renderer, GaussiansBehindTheCameraAreCulled) {
  GaussianModel m = random_scene(50, 9, 4, false);
  for (size_t i = 0; i < m.size(); ++i) m.means[3 * i + 2] = -4.1f;  // camera at z = -4, looking +z
  const RenderOutput out = CpuRenderer().render(m, test_camera(), RenderSettings{});
  for (float a : out.alpha) ASSERT_EQ(a, 0.f);
}

TEST(Renderer, ResultDoesNotDependOnThreadCount) {
  const GaussianModel m = random_scene(2000, 10);
  const Camera cam = test_camera(160, 120);
  const RenderSettings s = full_settings();
  RenderOutput one, many;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = CpuRenderer().render(m, cam, s);
  }
  many = CpuRenderer().render(m, cam, s);
  EXPECT_EQ(one.color, many.color);
  EXPECT_EQ(one.instance_maps, many.instance_maps);
}

TEST(Renderer, RejectsBadSettings) {
  RenderSettings s;
  s.sh_degree = 4;
  EXPECT_THROW(CpuRenderer().render(GaussianModel{}, test_camera(), s), std::invalid_argument);
  s.sh_degree = 3;
  s.instance_labels = {2, 2};
  EXPECT_THROW(CpuRenderer().render(GaussianModel{}, test_camera(), s), std::invalid_argument);
}

}  // namespace
}  // namespace splat

namespace splat {
namespace {

TEST(Renderer, EmptyTilesAroundAGaussianCluster) {
  // All Gaussians in one corner of the view: most tiles are empty.
  GaussianModel m = testing_scenes::random_scene(60, 31, 3, false);
  for (size_t i = 0; i < m.size(); ++i) {
    m.means[3 * i] = -1.1f + 0.1f * m.means[3 * i];
    m.means[3 * i + 1] = -0.8f + 0.1f * m.means[3 * i + 1];
    for (int k = 0; k < 3; ++k) m.log_scales[3 * i + k] = std::log(0.03f);
  }
  const Camera cam = testing_scenes::test_camera(96, 64);
  RenderSettings s;
  s.background[2] = 1.f;
  s.instance_labels = {1};
  const RenderOutput fast = CpuRenderer().render(m, cam, s);
  const reference::Output ref = reference::render(reference::Params::from(m), cam, s);
  size_t empty = 0;
  for (size_t p = 0; p < ref.alpha.size(); ++p) {
    ASSERT_NEAR(fast.color[3 * p + 2], ref.color[3 * p + 2], 1e-5);
    ASSERT_NEAR(fast.instance_maps[p], ref.instance_maps[p], 1e-5);
    empty += ref.alpha[p] == 0;
  }
  EXPECT_GT(empty, ref.alpha.size() / 2);
}

TEST(RendererBackward, GradientsDoNotDependOnThreadCount) {
  const GaussianModel m = testing_scenes::random_scene(2000, 32);
  const Camera cam = testing_scenes::test_camera(160, 120);
  RenderSettings s;
  s.instance_labels = {1, 2, 3};
  const size_t pixels = size_t(cam.width) * cam.height;
  RenderOutputGradients g;
  g.color.assign(3 * pixels, 0.01f);
  g.alpha.assign(pixels, -0.02f);
  g.instance_maps.assign(3 * pixels, 0.03f);
  auto run = [&] {
    std::unique_ptr<RenderState> state;
    CpuRenderer().render(m, cam, s, &state);
    return CpuRenderer().backward(m, cam, s, *state, g);
  };
  GaussianGradients one;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = run();
  }
  const GaussianGradients many = run();
  EXPECT_EQ(one.means, many.means);
  EXPECT_EQ(one.sh_rest, many.sh_rest);
  EXPECT_EQ(one.rotations, many.rotations);
  EXPECT_EQ(one.instance_opacity_logits, many.instance_opacity_logits);
  EXPECT_EQ(one.mean2d_ndc, many.mean2d_ndc);
}

TEST(RendererBackward, ReusedStateGivesTheSameResult) {
  // A training loop passes the same state and outputs back every iteration.
  const Camera cam = testing_scenes::test_camera(80, 60);
  RenderSettings s;
  s.instance_labels = {2};
  std::unique_ptr<RenderState> state;
  RenderOutput out;
  GaussianGradients grads;
  RenderOutputGradients g;
  for (unsigned seed : {41u, 42u, 41u}) {
    const GaussianModel m = testing_scenes::random_scene(seed == 42 ? 900 : 300, seed);
    CpuRenderer().render(m, cam, s, out, &state);
    g.color.assign(out.color.size(), 0.1f);
    g.instance_maps.assign(out.instance_maps.size(), 0.1f);
    CpuRenderer().backward(m, cam, s, *state, g, grads);
    std::unique_ptr<RenderState> fresh;
    const RenderOutput expected = CpuRenderer().render(m, cam, s, &fresh);
    EXPECT_EQ(out.color, expected.color);
    EXPECT_EQ(out.instance_maps, expected.instance_maps);
    EXPECT_EQ(grads.means, CpuRenderer().backward(m, cam, s, *fresh, g).means);
  }
}

}  // namespace
}  // namespace splat
