#include "splat/render/tile_bins.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>

namespace splat {

namespace {

// Sort key of a visible Gaussian: depth first, then index, so the order is
// fully determined. Depths are > the near plane, and the bits of positive
// floats order like the floats.
uint64_t depth_key(float depth, uint32_t gaussian) {
  return (uint64_t(std::bit_cast<uint32_t>(depth)) << 32) | gaussian;
}

// Fixed chunks of [0, n) for the passes below, at least `grain` a chunk:
// each chunk's results have their own place, so the output is the same
// whatever the threads.
struct Chunks {
  size_t n, count;
  Chunks(size_t n, size_t grain) : n(n), count(std::clamp<size_t>(n / grain, 1, 64)) {}
  size_t begin(size_t c) const { return n * c / count; }
  size_t end(size_t c) const { return n * (c + 1) / count; }
};

// The keys of the visible Gaussians, in index order: each chunk counts its
// visible Gaussians, then writes them from its own position.
void visible_keys(const ProjectedGaussians& p, std::vector<uint64_t>& keys) {
  const Chunks chunks(p.size(), 4096);
  std::vector<size_t> first(chunks.count + 1, 0);
  tbb::parallel_for(size_t(0), chunks.count, [&](size_t c) {
    for (size_t i = chunks.begin(c); i < chunks.end(c); ++i) first[c + 1] += p.visible(i);
  });
  for (size_t c = 0; c < chunks.count; ++c) first[c + 1] += first[c];
  keys.resize(first[chunks.count]);
  tbb::parallel_for(size_t(0), chunks.count, [&](size_t c) {
    size_t at = first[c];
    for (size_t i = chunks.begin(c); i < chunks.end(c); ++i)
      if (p.visible(i)) keys[at++] = depth_key(p.depth[i], uint32_t(i));
  });
}

// Sorts keys by their high 32 bits (the depth), keeping the order of equal
// depths: LSD radix sort, one byte a pass, skipping bytes all keys share.
// Each pass counts and scatters in parallel over fixed chunks, each chunk
// from its own position in every bucket, so the sort stays stable.
void sort_by_depth(std::vector<uint64_t>& keys, std::vector<uint64_t>& scratch) {
  const size_t n = keys.size();
  if (n < 2) return;
  scratch.resize(n);
  const Chunks chunks(n, 8192);
  std::vector<uint32_t> position(chunks.count * 256);  // [chunk][digit]
  uint64_t* src = keys.data();
  uint64_t* dst = scratch.data();
  for (int shift = 32; shift < 64; shift += 8) {
    const auto digit = [shift](uint64_t key) { return size_t(key >> shift) & 0xff; };
    std::fill(position.begin(), position.end(), 0u);
    tbb::parallel_for(size_t(0), chunks.count, [&](size_t c) {
      uint32_t* count = &position[c * 256];
      for (size_t k = chunks.begin(c); k < chunks.end(c); ++k) ++count[digit(src[k])];
    });
    size_t shared = 0;  // keys with the first key's digit
    for (size_t c = 0; c < chunks.count; ++c) shared += position[c * 256 + digit(src[0])];
    if (shared == n) continue;  // one bucket: nothing to do
    uint32_t total = 0;
    for (size_t d = 0; d < 256; ++d)
      for (size_t c = 0; c < chunks.count; ++c) {
        const uint32_t count = position[c * 256 + d];
        position[c * 256 + d] = total;
        total += count;
      }
    tbb::parallel_for(size_t(0), chunks.count, [&](size_t c) {
      uint32_t* next = &position[c * 256];
      for (size_t k = chunks.begin(c); k < chunks.end(c); ++k) dst[next[digit(src[k])]++] = src[k];
    });
    std::swap(src, dst);
  }
  if (src != keys.data()) keys.swap(scratch);
}

}  // namespace

void bin_gaussians(const ProjectedGaussians& p, TileBins& b) {
  b.tiles_x = p.tiles_x;
  b.tiles_y = p.tiles_y;
  const size_t tiles = size_t(b.tiles_x) * b.tiles_y;
  // The visible Gaussians front to back, once for all tiles: appended in
  // this order, every tile's list comes out sorted (each tile's list sorted
  // on its own cost a few per cent of a step, a radix sort per tile).
  std::vector<uint64_t>& keys = b.sort_keys;
  visible_keys(p, keys);
  sort_by_depth(keys, b.sort_scratch);
  // Counting sort by tile without atomics: each chunk of the sorted
  // Gaussians counts its entries per tile, and gets its own write position
  // in every tile. Chunks of 256: early in training a few thousand large
  // Gaussians have tens of tiles each.
  const Chunks chunks(keys.size(), 256);
  auto for_each_tile = [&](size_t i, auto&& f) {
    const int32_t* r = &p.tile_rect[4 * i];
    for (int ty = r[1]; ty < r[3]; ++ty)
      for (int tx = r[0]; tx < r[2]; ++tx) f(size_t(ty) * b.tiles_x + tx);
  };
  std::vector<uint32_t> position(chunks.count * tiles, 0);  // [chunk][tile]
  tbb::parallel_for(size_t(0), chunks.count, [&](size_t c) {
    uint32_t* count = &position[c * tiles];
    for (size_t k = chunks.begin(c); k < chunks.end(c); ++k)
      for_each_tile(uint32_t(keys[k]), [&](size_t t) { ++count[t]; });
  });
  b.tile_start.resize(tiles + 1);
  uint32_t total = 0;
  for (size_t t = 0; t < tiles; ++t) {
    b.tile_start[t] = total;
    for (size_t c = 0; c < chunks.count; ++c) {
      const uint32_t count = position[c * tiles + t];
      position[c * tiles + t] = total;
      total += count;
    }
  }
  b.tile_start[tiles] = total;
  b.slot_gaussian.resize(total);
  tbb::parallel_for(size_t(0), chunks.count, [&](size_t c) {
    uint32_t* next = &position[c * tiles];
    for (size_t k = chunks.begin(c); k < chunks.end(c); ++k) {
      const uint32_t i = uint32_t(keys[k]);
      for_each_tile(i, [&](size_t t) { b.slot_gaussian[next[t]++] = i; });
    }
  });
}

}  // namespace splat
