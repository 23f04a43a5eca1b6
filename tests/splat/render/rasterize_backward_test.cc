#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "splat/render/project.h"
#include "splat/render/rasterize.h"
#include "splat/render/tile_bins.h"
#include "tests/splat/render/scenes.h"

namespace splat {
namespace {

// The forward steps of a render, keeping the state the backward pass needs.
RasterState forward_state(const GaussianModel& m, const Camera& cam, const RenderSettings& s) {
  RasterState st;
  st.width = cam.width;
  st.height = cam.height;
  st.labels = m.labels;
  st.map_of_label.assign(5, -1);
  for (size_t k = 0; k < s.instance_labels.size(); ++k) st.map_of_label[s.instance_labels[k]] = k;
  project_gaussians(m, cam, s, st.projected);
  bin_gaussians(st.projected, st.bins);
  RenderOutput out;
  rasterize_forward(s, st, out);
  return st;
}

void expect_same(const ProjectedGradients& a, const ProjectedGradients& b) {
  EXPECT_EQ(a.mean2d, b.mean2d);
  EXPECT_EQ(a.conic, b.conic);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.color, b.color);
  EXPECT_EQ(a.opacity, b.opacity);
  EXPECT_EQ(a.instance_opacity, b.instance_opacity);
}

TEST(RasterizeBackward, BandsOfTileRowsGiveTheSameGradientsToTheBit) {
  // Large Gaussians on 5 x 4 tiles: most cover several tile rows, so a
  // Gaussian's entries are split across bands.
  const GaussianModel m = testing_scenes::random_scene(300, 31);
  const Camera cam = testing_scenes::test_camera(80, 64);
  RenderSettings s;
  s.instance_labels = {1, 3};
  const size_t pixels = size_t(cam.width) * cam.height;
  RenderOutputGradients g;
  g.color.resize(3 * pixels);
  g.depth.resize(pixels);
  g.instance_maps.resize(2 * pixels);
  for (size_t k = 0; k < g.color.size(); ++k) g.color[k] = 0.01f * float(int(k % 7) - 3);
  for (size_t k = 0; k < g.depth.size(); ++k) g.depth[k] = 0.002f * float(int(k % 5) - 2);
  for (size_t k = 0; k < g.instance_maps.size(); ++k) g.instance_maps[k] = 0.03f * (k % 3);

  RasterState one_band = forward_state(m, cam, s);
  ProjectedGradients whole;
  rasterize_backward(s, BackwardSettings{}, one_band, g, whole);
  ASSERT_EQ(one_band.entry_grads.size(), one_band.bins.num_entries() * kRasterEntryGradients);

  RasterState row_bands = forward_state(m, cam, s);
  row_bands.max_band_entries = 1;  // one tile row per band
  ProjectedGradients banded;
  rasterize_backward(s, BackwardSettings{}, row_bands, g, banded);
  // The buffer held one row's entries at most.
  EXPECT_LT(row_bands.entry_grads.capacity(), one_band.entry_grads.size());

  expect_same(whole, banded);
  EXPECT_TRUE(std::any_of(whole.opacity.begin(), whole.opacity.end(), [](float v) { return v; }));
}

// The buffers are reused from view to view and only the visible Gaussians'
// values are written, from zero: what the buffer held before (NaN here)
// changes none of them, and the culled ones' are left alone.
TEST(RasterizeBackward, VisibleGradientsDoNotDependOnWhatTheBufferHeld) {
  const GaussianModel m = testing_scenes::random_scene(300, 32);
  const Camera cam = testing_scenes::test_camera(80, 64);
  RenderSettings s;
  const size_t pixels = size_t(cam.width) * cam.height;
  RenderOutputGradients g;
  g.color.resize(3 * pixels);
  for (size_t k = 0; k < g.color.size(); ++k) g.color[k] = 0.01f * float(int(k % 7) - 3);
  RasterState st = forward_state(m, cam, s);
  st.max_band_entries = 1;  // Gaussians split across bands, too
  ProjectedGradients fresh;
  rasterize_backward(s, BackwardSettings{}, st, g, fresh);
  ProjectedGradients reused;
  reused.resize(m.size());
  for (auto* v : {&reused.mean2d, &reused.conic, &reused.depth, &reused.color, &reused.opacity,
                  &reused.instance_opacity})
    v->assign(v->size(), std::nanf(""));
  rasterize_backward(s, BackwardSettings{}, st, g, reused);
  size_t culled = 0;
  for (size_t i = 0; i < m.size(); ++i) {
    if (!st.projected.visible(i)) {
      ++culled;
      EXPECT_TRUE(std::isnan(reused.opacity[i]));
      continue;
    }
    EXPECT_EQ(reused.mean2d[2 * i], fresh.mean2d[2 * i]);
    EXPECT_EQ(reused.mean2d[2 * i + 1], fresh.mean2d[2 * i + 1]);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(reused.conic[3 * i + k], fresh.conic[3 * i + k]);
      EXPECT_EQ(reused.color[3 * i + k], fresh.color[3 * i + k]);
    }
    EXPECT_EQ(reused.depth[i], fresh.depth[i]);
    EXPECT_EQ(reused.opacity[i], fresh.opacity[i]);
    EXPECT_EQ(reused.instance_opacity[i], fresh.instance_opacity[i]);
  }
  EXPECT_GT(culled, 0u) << "the scene must have culled Gaussians";
}

}  // namespace
}  // namespace splat
