#pragma once
// A tile's Gaussians copied into contiguous arrays, front to back: the CPU
// counterpart of a CUDA block loading its Gaussians into shared memory.

#include <cstdint>
#include <vector>

#include "splat/render/rasterize.h"

namespace splat {

struct TileGaussians {
  std::vector<float> mx, my;      // 2D mean
  std::vector<float> A, B, C;     // conic
  std::vector<float> opacity, instance_opacity;
  std::vector<float> r, g, b;     // colour (when rendering colour)
  std::vector<float> depth;
  std::vector<float> y_lo, y_hi;  // pixel-centre rows the Gaussian can reach
  std::vector<int32_t> plane;     // instance map plane of its label, -1 if none
  std::vector<int32_t> label;
  size_t size() const { return mx.size(); }

  void gather(const RasterState& s, uint32_t slot_begin, uint32_t slot_end, bool color) {
    const ProjectedGaussians& p = s.projected;
    const size_t n = slot_end - slot_begin;
    for (auto* v : {&mx, &my, &A, &B, &C, &opacity, &instance_opacity, &depth, &y_lo, &y_hi})
      v->resize(n);
    for (auto* v : {&r, &g, &b}) v->resize(color ? n : 0);
    plane.resize(n);
    label.resize(n);
    for (size_t k = 0; k < n; ++k) {
      const uint32_t i = s.bins.slot_gaussian[slot_begin + k];
      mx[k] = p.mean2d[2 * i];
      my[k] = p.mean2d[2 * i + 1];
      A[k] = p.conic[3 * i];
      B[k] = p.conic[3 * i + 1];
      C[k] = p.conic[3 * i + 2];
      opacity[k] = p.opacity[i];
      instance_opacity[k] = p.instance_opacity[i];
      depth[k] = p.depth[i];
      y_lo[k] = my[k] - p.reach[2 * i + 1];
      y_hi[k] = my[k] + p.reach[2 * i + 1];
      if (color) {
        r[k] = p.color[3 * i];
        g[k] = p.color[3 * i + 1];
        b[k] = p.color[3 * i + 2];
      }
      label[k] = s.labels[i];
      const int32_t l = s.labels[i];
      plane[k] = (l >= 0 && size_t(l) < s.map_of_label.size()) ? s.map_of_label[l] : -1;
    }
  }
};

}  // namespace splat
