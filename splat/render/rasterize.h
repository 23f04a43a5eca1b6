#pragma once
// Steps 3 and 4 of rendering: blend each tile's depth-sorted Gaussians front
// to back for every pixel (forward), and send the output gradients back to
// the projected quantities (backward).
//
// Each 16x16 tile is split into 16 blocks of 4x4 pixels; a block's pixels are
// 16 lanes that the compiler vectorises. A Gaussian is skipped for a block
// that lies outside its reach (where alpha >= 1/255), which changes no pixel;
// 4x4 blocks waste fewer lanes on small Gaussians than 16x1 rows would.

#include <cstdint>
#include <vector>

#include "splat/render/project.h"
#include "splat/render/render_types.h"
#include "splat/render/tile_bins.h"

namespace splat {

inline constexpr int kBlockSize = 4;  // blocks of kBlockSize x kBlockSize pixels
inline constexpr int kBlockLanes = kBlockSize * kBlockSize;
inline constexpr int kBlocksPerTile = (kTileSize / kBlockSize) * (kTileSize / kBlockSize);

// Floats of gradient the backward pass keeps per (Gaussian, tile) entry.
inline constexpr int kRasterEntryGradients = 11;

// What the rasterizer reads of one Gaussian, packed into one cache line so
// that gathering a tile's Gaussians costs one load each.
struct alignas(64) SplatRecord {
  float mx, my;   // 2D mean
  float A, B, C;  // conic
  float opacity, instance_opacity;
  float depth;
  float r, g, b;  // colour (0 when not rendering colour)
  float reach_x, reach_y;
  int32_t label;
  int32_t plane;  // instance map plane of the label, -1 if none
  // Pixels with (d^T conic d) above this have alpha < 1/255: 2 ln(255 sigma),
  // with a small margin.
  float reach_level;
};
static_assert(sizeof(SplatRecord) == 64);

// Everything the backward pass needs from the forward pass.
struct RasterState {
  int width = 0, height = 0;
  ProjectedGaussians projected;
  TileBins bins;
  std::vector<float> final_transmittance;  // W * H
  std::vector<uint32_t> n_contrib;         // W * H: tile-list position of the last contributor + 1
  std::vector<int32_t> map_of_label;       // label -> instance map plane, -1 if none
  std::vector<int32_t> labels;             // per Gaussian (copied from the model, 0 if none)
  std::vector<SplatRecord> records;        // per Gaussian, filled for visible ones
  std::vector<uint16_t> slot_blocks;       // per slot: the tile's 4x4 blocks it reaches, a bit each
  std::vector<float> entry_grads;          // backward scratch: gradient per (Gaussian, tile) entry
};

// Fills out (colour, alpha, depth, contributors, and what settings ask of
// the instance branch). state.projected and state.bins must be filled; this
// fills state.records.
void rasterize_forward(const RenderSettings& settings, RasterState& state, RenderOutput& out);

// Accumulates dLoss/d(projected quantities) from the output gradients.
void rasterize_backward(const RenderSettings& settings, RasterState& state,
                        const RenderOutputGradients& grads, ProjectedGradients& out);

}  // namespace splat
