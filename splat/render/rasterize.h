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

#include "splat/huge_page_allocator.h"
#include "splat/render/project.h"
#include "splat/render/render_types.h"
#include "splat/render/tile_bins.h"

namespace splat {

inline constexpr int kBlockSize = 4;  // blocks of kBlockSize x kBlockSize pixels
inline constexpr int kBlockLanes = kBlockSize * kBlockSize;
inline constexpr int kBlocksPerTile = (kTileSize / kBlockSize) * (kTileSize / kBlockSize);
inline constexpr int kTilePixels = kBlocksPerTile * kBlockLanes;

// Floats of gradient the backward pass keeps per (Gaussian, tile) entry.
inline constexpr int kRasterEntryGradients = 11;

// The backward pass holds one gradient per (Gaussian, tile) entry until it
// sums each Gaussian's entries. Tiles are taken in bands of whole tile rows
// holding at most this many entries per Gaussian (or kMinBandEntries), so
// that buffer stays small when Gaussians cover many tiles.
inline constexpr size_t kBandEntriesPerGaussian = 1;
inline constexpr size_t kMinBandEntries = size_t(1) << 16;

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

// Where one Gaussian's entries lie in a band's gradient buffer: the entry of
// tile (tx, ty) is base + ty * width + tx (row by row, like the tiles).
struct BandEntryIndex {
  int32_t base, width;
};

// The visible Gaussians whose tile rectangle meets each band of tile rows,
// in index order, band after band: members[start[b]] .. members[start[b + 1]].
struct BandMembers {
  std::vector<uint32_t> members;
  std::vector<size_t> start;  // bands + 1
};

// Everything the backward pass needs from the forward pass.
struct RasterState {
  int width = 0, height = 0;
  ProjectedGaussians projected;
  TileBins bins;
  // Per pixel in tile order (tile, block, lane: kTilePixels a tile, lanes
  // off the image holding 1 and 0), so that the backward pass reads a tile's
  // in one run: read as image rows, each tile's 16 rows missed the cache.
  std::vector<float> final_transmittance;
  std::vector<uint32_t> n_contrib;    // tile-list position of the last contributor + 1
  std::vector<int32_t> map_of_label;  // label -> instance map plane, -1 if none
  std::vector<int32_t> labels;        // per Gaussian (copied from the model, 0 if none)
  // Per Gaussian, filled for visible ones; read at random, tile by tile.
  std::vector<SplatRecord, HugePageAllocator<SplatRecord>> records;
  std::vector<uint16_t> slot_blocks;  // per slot: the tile's 4x4 blocks it reaches, a bit each
  // Backward scratch, for one band of tile rows at a time:
  std::vector<float> entry_grads;  // gradient per (Gaussian, tile) entry of the band (only grows)
  BandMembers band_members;        // of every band
  std::vector<uint32_t> band_chunk_counts;  // scratch of find_band_members
  std::vector<uint32_t> band_entries;       // members + 1: entries of member j are [j] .. [j+1]
  std::vector<BandEntryIndex> band_index;   // N, written for the band's members
  size_t max_band_entries = 0;              // 0: max(kBandEntriesPerGaussian * N, kMinBandEntries)
};

// Fills out (colour, alpha, depth, contributors, and what settings ask of
// the instance branch). state.projected and state.bins must be filled; this
// fills state.records.
void rasterize_forward(const RenderSettings& settings, RasterState& state, RenderOutput& out);

// Accumulates dLoss/d(projected quantities) from the output gradients.
void rasterize_backward(const RenderSettings& settings, const BackwardSettings& backward_settings,
                        RasterState& state, const RenderOutputGradients& grads,
                        ProjectedGradients& out);

}  // namespace splat
