#pragma once
// A tile's Gaussians copied into one contiguous array, front to back: the CPU
// counterpart of a CUDA block loading its Gaussians into shared memory.

#include <cstdint>
#include <vector>

#include "splat/render/rasterize.h"

namespace splat {

struct TileGaussians {
  std::vector<SplatRecord> records;

  size_t size() const { return records.size(); }
  const SplatRecord& operator[](size_t k) const { return records[k]; }

  // Whether Gaussian k can reach a pixel centre in [x0, x1] x [y0, y1].
  bool reaches(size_t k, float x0, float x1, float y0, float y1) const {
    const SplatRecord& g = records[k];
    return g.mx + g.reach_x >= x0 && g.mx - g.reach_x <= x1 && g.my + g.reach_y >= y0 &&
           g.my - g.reach_y <= y1;
  }

  void gather(const RasterState& s, uint32_t slot_begin, uint32_t slot_end) {
    const size_t n = slot_end - slot_begin;
    const uint32_t* gaussian = &s.bins.slot_gaussian[slot_begin];
    records.resize(n);
    // The records are read in depth order, i.e. at random: prefetch ahead so
    // the loads overlap instead of waiting on memory one by one.
    constexpr size_t kAhead = 16;
    for (size_t k = 0; k < std::min(n, kAhead); ++k) __builtin_prefetch(&s.records[gaussian[k]]);
    for (size_t k = 0; k < n; ++k) {
      if (k + kAhead < n) __builtin_prefetch(&s.records[gaussian[k + kAhead]]);
      records[k] = s.records[gaussian[k]];
    }
  }
};

}  // namespace splat
