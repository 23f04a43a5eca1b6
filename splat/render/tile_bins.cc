#include "splat/render/tile_bins.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>

namespace splat {

void bin_gaussians(const ProjectedGaussians& p, TileBins& b) {
  const size_t n = p.size();
  b.tiles_x = p.tiles_x;
  b.tiles_y = p.tiles_y;
  const size_t tiles = size_t(b.tiles_x) * b.tiles_y;

  // Entries per Gaussian, numbered Gaussian by Gaussian.
  b.gaussian_entries.assign(n + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    const int32_t* r = &p.tile_rect[4 * i];
    const uint32_t count = p.visible(i) ? uint32_t((r[2] - r[0]) * (r[3] - r[1])) : 0;
    b.gaussian_entries[i + 1] = b.gaussian_entries[i] + count;
  }
  const size_t entries = b.gaussian_entries[n];

  // Counting sort by tile; within a tile entries stay in Gaussian order.
  b.tile_start.assign(tiles + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!p.visible(i)) continue;
    const int32_t* r = &p.tile_rect[4 * i];
    for (int ty = r[1]; ty < r[3]; ++ty)
      for (int tx = r[0]; tx < r[2]; ++tx) ++b.tile_start[size_t(ty) * b.tiles_x + tx + 1];
  }
  std::partial_sum(b.tile_start.begin(), b.tile_start.end(), b.tile_start.begin());
  b.slot_gaussian.resize(entries);
  b.slot_entry.resize(entries);
  std::vector<uint32_t> fill(b.tile_start.begin(), b.tile_start.end() - 1);
  for (size_t i = 0; i < n; ++i) {
    if (!p.visible(i)) continue;
    const int32_t* r = &p.tile_rect[4 * i];
    uint32_t entry = b.gaussian_entries[i];
    for (int ty = r[1]; ty < r[3]; ++ty)
      for (int tx = r[0]; tx < r[2]; ++tx) {
        const uint32_t slot = fill[size_t(ty) * b.tiles_x + tx]++;
        b.slot_gaussian[slot] = uint32_t(i);
        b.slot_entry[slot] = entry++;
      }
  }

  // Front to back within each tile; stable, so equal depths keep index order.
  tbb::parallel_for(size_t(0), tiles, [&](size_t t) {
    const uint32_t lo = b.tile_start[t], hi = b.tile_start[t + 1];
    if (hi - lo < 2) return;
    std::vector<uint32_t> order(hi - lo);
    std::iota(order.begin(), order.end(), lo);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t c) {
      return p.depth[b.slot_gaussian[a]] < p.depth[b.slot_gaussian[c]];
    });
    std::vector<uint32_t> g(order.size()), e(order.size());
    for (size_t k = 0; k < order.size(); ++k) {
      g[k] = b.slot_gaussian[order[k]];
      e[k] = b.slot_entry[order[k]];
    }
    std::copy(g.begin(), g.end(), b.slot_gaussian.begin() + lo);
    std::copy(e.begin(), e.end(), b.slot_entry.begin() + lo);
  });
}

}  // namespace splat
