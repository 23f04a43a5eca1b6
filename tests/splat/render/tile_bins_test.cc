#include "splat/render/tile_bins.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <random>
#include <tuple>

namespace splat {
namespace {

// Projected Gaussians with random tile rectangles, a share of them culled,
// and depths from a small set so that many tie (the index breaks the tie).
ProjectedGaussians random_projection(size_t n, int tiles_x, int tiles_y, unsigned seed) {
  std::mt19937 rng(seed);
  ProjectedGaussians p;
  p.tiles_x = tiles_x;
  p.tiles_y = tiles_y;
  p.depth.resize(n);
  p.radius.resize(n);
  p.tile_rect.resize(4 * n);
  std::uniform_int_distribution<int> depth_step(1, 300), culled(0, 4);
  for (size_t i = 0; i < n; ++i) {
    p.depth[i] = 0.5f + 0.25f * float(depth_step(rng));  // depths spanning several exponents
    p.radius[i] = culled(rng) == 0 ? 0 : 1;
    std::uniform_int_distribution<int> x(0, tiles_x - 1), y(0, tiles_y - 1), span(1, 6);
    const int x0 = x(rng), y0 = y(rng);
    p.tile_rect[4 * i] = x0;
    p.tile_rect[4 * i + 1] = y0;
    p.tile_rect[4 * i + 2] = std::min(tiles_x, x0 + span(rng));
    p.tile_rect[4 * i + 3] = std::min(tiles_y, y0 + span(rng));
  }
  return p;
}

// Each tile's list, the slow way: every visible Gaussian whose rectangle
// holds the tile, by depth, then index.
std::vector<std::vector<uint32_t>> reference_lists(const ProjectedGaussians& p) {
  std::vector<std::vector<uint32_t>> lists(size_t(p.tiles_x) * p.tiles_y);
  for (size_t i = 0; i < p.size(); ++i) {
    if (!p.visible(i)) continue;
    const int32_t* r = &p.tile_rect[4 * i];
    for (int ty = r[1]; ty < r[3]; ++ty)
      for (int tx = r[0]; tx < r[2]; ++tx)
        lists[size_t(ty) * p.tiles_x + tx].push_back(uint32_t(i));
  }
  for (auto& list : lists)
    std::sort(list.begin(), list.end(), [&](uint32_t a, uint32_t b) {
      return std::tie(p.depth[a], a) < std::tie(p.depth[b], b);
    });
  return lists;
}

void expect_lists(const TileBins& bins, const std::vector<std::vector<uint32_t>>& want) {
  ASSERT_EQ(bins.tile_start.size(), want.size() + 1);
  for (size_t t = 0; t < want.size(); ++t) {
    const std::vector<uint32_t> got(bins.slot_gaussian.begin() + bins.tile_start[t],
                                    bins.slot_gaussian.begin() + bins.tile_start[t + 1]);
    ASSERT_EQ(got, want[t]) << "tile " << t;
  }
}

// Sizes that take one chunk and many (the binning's chunks of 256 and the
// depth sort's of 8,192 sorted Gaussians), on one thread and two.
TEST(TileBins, ListsAreEachTilesGaussiansByDepthThenIndex) {
  for (size_t n : {size_t(0), size_t(1), size_t(200), size_t(3000), size_t(40000)})
    for (int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      const ProjectedGaussians p = random_projection(n, 23, 17, unsigned(n) + 7);
      TileBins bins;
      bin_gaussians(p, bins);
      SCOPED_TRACE(testing::Message() << n << " Gaussians, " << threads << " threads");
      expect_lists(bins, reference_lists(p));
    }
}

// The buffers are reused from view to view: a smaller view after a larger
// one gets its own lists, nothing left over.
TEST(TileBins, ReusedBinsHoldOnlyTheLastView) {
  TileBins bins;
  bin_gaussians(random_projection(20000, 30, 20, 1), bins);
  const ProjectedGaussians small = random_projection(500, 8, 5, 2);
  bin_gaussians(small, bins);
  expect_lists(bins, reference_lists(small));
}

}  // namespace
}  // namespace splat
