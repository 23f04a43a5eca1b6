#pragma once
// A tile's Gaussians copied into one contiguous array, front to back: the CPU
// counterpart of a CUDA block loading its Gaussians into shared memory.

#include <algorithm>
#include <cstdint>
#include <vector>

#include "splat/render/rasterize.h"

namespace splat {

struct TileGaussians {
  std::vector<SplatRecord> records;

  size_t size() const { return records.size(); }
  const SplatRecord& operator[](size_t k) const { return records[k]; }

  // Whether Gaussian k can reach (alpha >= 1/255) a pixel centre in
  // [x0, x1] x [y0, y1]: its bounding box first, then the exact test of its
  // ellipse against the rectangle, which culls elongated Gaussians that only
  // pass their box.
  bool reaches(size_t k, float x0, float x1, float y0, float y1) const {
    const SplatRecord& g = records[k];
    if (g.mx + g.reach_x < x0 || g.mx - g.reach_x > x1 || g.my + g.reach_y < y0 ||
        g.my - g.reach_y > y1)
      return false;
    // Offsets d = pixel - mean over the rectangle; q(d) = A dx^2 + 2 B dx dy + C dy^2.
    const float ax = x0 - g.mx, bx = x1 - g.mx, ay = y0 - g.my, by = y1 - g.my;
    if (ax <= 0 && bx >= 0 && ay <= 0 && by >= 0) return true;  // the mean is inside
    // Otherwise the minimum of the convex q lies on an edge.
    auto q = [&](float dx, float dy) { return g.A * dx * dx + 2 * g.B * dx * dy + g.C * dy * dy; };
    auto clamp = [](float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); };
    float best = 3.4e38f;
    for (float dx : {ax, bx}) best = std::min(best, q(dx, clamp(-g.B * dx / g.C, ay, by)));
    for (float dy : {ay, by}) best = std::min(best, q(clamp(-g.B * dy / g.A, ax, bx), dy));
    return best <= g.reach_level;
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
