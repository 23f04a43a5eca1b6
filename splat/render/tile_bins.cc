#include "splat/render/tile_bins.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>

namespace splat {

namespace {

// Sort key of a (tile, Gaussian) slot: depth first, then Gaussian index, so
// the order is fully determined. Depths are > the near plane, and the bits
// of positive floats order like the floats.
uint64_t depth_key(float depth, uint32_t gaussian) {
  return (uint64_t(std::bit_cast<uint32_t>(depth)) << 32) | gaussian;
}

// Sorts keys by their high 32 bits (the depth), keeping the order of equal
// depths: LSD radix sort, one byte a pass, skipping bytes all keys share.
void radix_sort_by_depth(uint64_t* keys, size_t n, std::vector<uint64_t>& scratch) {
  if (n < 2) return;
  scratch.resize(n);
  uint64_t* src = keys;
  uint64_t* dst = scratch.data();
  for (int shift = 32; shift < 64; shift += 8) {
    uint32_t count[257] = {};
    for (size_t k = 0; k < n; ++k) ++count[((src[k] >> shift) & 0xff) + 1];
    if (count[((src[0] >> shift) & 0xff) + 1] == n) continue;  // one bucket: nothing to do
    for (int d = 0; d < 256; ++d) count[d + 1] += count[d];
    for (size_t k = 0; k < n; ++k) dst[count[(src[k] >> shift) & 0xff]++] = src[k];
    std::swap(src, dst);
  }
  if (src != keys) std::copy(src, src + n, keys);
}

}  // namespace

void bin_gaussians(const ProjectedGaussians& p, TileBins& b) {
  const size_t n = p.size();
  b.tiles_x = p.tiles_x;
  b.tiles_y = p.tiles_y;
  const size_t tiles = size_t(b.tiles_x) * b.tiles_y;
  // Counting sort by tile without atomics: each chunk of Gaussians counts its
  // entries per tile, and gets its own write position in every tile. Early in
  // training a few thousand large Gaussians have tens of tiles each: chunks
  // of 256, so that they too are counted and scattered in parallel (with
  // 4,096 they were one chunk, a few per cent of the step on one thread).
  // The slots come out the same whatever the chunks.
  const size_t chunks = std::clamp<size_t>(n / 256, 1, 64);
  auto chunk_range = [&](size_t c) { return std::pair{n * c / chunks, n * (c + 1) / chunks}; };
  auto for_each_tile = [&](size_t i, auto&& f) {
    const int32_t* r = &p.tile_rect[4 * i];
    for (int ty = r[1]; ty < r[3]; ++ty)
      for (int tx = r[0]; tx < r[2]; ++tx) f(size_t(ty) * b.tiles_x + tx);
  };
  std::vector<uint32_t> position(chunks * tiles, 0);  // [chunk][tile]
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    uint32_t* count = &position[c * tiles];
    const auto [lo, hi] = chunk_range(c);
    for (size_t i = lo; i < hi; ++i)
      if (p.visible(i)) for_each_tile(i, [&](size_t t) { ++count[t]; });
  });
  b.tile_start.resize(tiles + 1);
  uint32_t total = 0;
  for (size_t t = 0; t < tiles; ++t) {
    b.tile_start[t] = total;
    for (size_t c = 0; c < chunks; ++c) {
      const uint32_t count = position[c * tiles + t];
      position[c * tiles + t] = total;
      total += count;
    }
  }
  b.tile_start[tiles] = total;
  const size_t entries = total;
  std::vector<uint64_t>& keys = b.sort_keys;
  keys.resize(entries);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    uint32_t* next = &position[c * tiles];
    const auto [lo, hi] = chunk_range(c);
    for (size_t i = lo; i < hi; ++i) {
      if (!p.visible(i)) continue;
      const uint64_t key = depth_key(p.depth[i], uint32_t(i));
      for_each_tile(i, [&](size_t t) { keys[next[t]++] = key; });
    }
  });

  b.slot_gaussian.resize(entries);
  // Chunks scatter in Gaussian order, so each tile's keys ascend by index
  // and a stable sort by depth gives the (depth, index) order.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles, 16), [&](const auto& range) {
    std::vector<uint64_t> scratch;
    for (size_t t = range.begin(); t < range.end(); ++t) {
      const uint32_t lo = b.tile_start[t], hi = b.tile_start[t + 1];
      radix_sort_by_depth(keys.data() + lo, hi - lo, scratch);
      for (uint32_t s = lo; s < hi; ++s) b.slot_gaussian[s] = uint32_t(keys[s]);
    }
  });
}

}  // namespace splat
