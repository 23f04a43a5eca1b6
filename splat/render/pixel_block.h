#pragma once
// A 4x4 block of pixels inside a tile, whose pixels are the 16 lanes of the
// rasterizer's vector loops.

#include <algorithm>

#include "splat/render/rasterize.h"

namespace splat {

// Lane l sits at (x0 + l % 4, y0 + l / 4); offsets as floats for the loops.
struct LaneOffsets {
  alignas(64) float x[kBlockLanes];
  alignas(64) float y[kBlockLanes];
  constexpr LaneOffsets() : x(), y() {
    for (int l = 0; l < kBlockLanes; ++l)
      x[l] = float(l % kBlockSize), y[l] = float(l / kBlockSize);
  }
};
inline constexpr LaneOffsets kLaneOffsets{};

struct PixelBlock {
  int x0 = 0, y0 = 0;  // top-left pixel
  // Pixel-centre bounds of the block, for reach tests.
  constexpr float cx0() const { return float(x0) + 0.5f; }
  constexpr float cy0() const { return float(y0) + 0.5f; }
  constexpr float cx1() const { return float(x0 + kBlockSize) - 0.5f; }
  constexpr float cy1() const { return float(y0 + kBlockSize) - 0.5f; }
  // Whether lane l is a pixel of a width x height image, and which.
  bool inside(int l, int width, int height) const {
    return x0 + l % kBlockSize < width && y0 + l / kBlockSize < height;
  }
  size_t pixel(int l, int width) const {
    return size_t(y0 + l / kBlockSize) * width + x0 + l % kBlockSize;
  }
  // Block b (0..15) of the tile whose top-left pixel is (tile_x0, tile_y0).
  static constexpr PixelBlock in_tile(int tile_x0, int tile_y0, int b) {
    constexpr int per_row = kTileSize / kBlockSize;
    return {tile_x0 + (b % per_row) * kBlockSize, tile_y0 + (b / per_row) * kBlockSize};
  }
};

}  // namespace splat
