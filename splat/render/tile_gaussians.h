#pragma once
// A tile's Gaussians copied into one contiguous array, front to back: the CPU
// counterpart of a CUDA block loading its Gaussians into shared memory. With
// them, which of the tile's 4x4 pixel blocks each Gaussian reaches, found once
// per tile with the blocks as vector lanes, so that the forward and backward
// loops visit only the (Gaussian, block) pairs that matter, without tests.

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>
#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "splat/render/pixel_block.h"
#include "splat/render/rasterize.h"

namespace splat {

static_assert(kBlocksPerTile == 16, "block masks are 16 bits");

// Pixel-centre rectangle of each block of a tile at the origin, as lanes.
struct TileBlockBounds {
  alignas(64) float x0[kBlocksPerTile];
  alignas(64) float y0[kBlocksPerTile];
  constexpr TileBlockBounds() : x0(), y0() {
    for (int b = 0; b < kBlocksPerTile; ++b) {
      const PixelBlock block = PixelBlock::in_tile(0, 0, b);
      x0[b] = block.cx0(), y0[b] = block.cy0();
    }
  }
};
inline constexpr TileBlockBounds kTileBlockBounds{};

struct TileGaussians {
  // The first count records are the tile's. The buffer only grows: resizing
  // it to each tile's count filled it anew after every smaller tile.
  std::vector<SplatRecord> records;
  size_t count = 0;
  // Bit b of block_mask[k]: Gaussian k reaches (alpha >= 1/255) a pixel
  // centre of block b. Points into RasterState::slot_blocks.
  const uint16_t* block_mask = nullptr;
  // The Gaussians reaching block b, front to back: block_count[b] of them
  // from block_list(b). Each block has room for every Gaussian of the tile,
  // so that the lists are written in one pass without counting first.
  std::vector<uint32_t> block_entries;
  size_t block_capacity = 0;
  std::array<uint32_t, kBlocksPerTile> block_count{};

  size_t size() const { return count; }
  const SplatRecord& operator[](size_t k) const { return records[k]; }
  const uint32_t* block_list(int b) const { return block_entries.data() + b * block_capacity; }

  // Copies the records of slots [slot_begin, slot_end), front to back.
  void gather(const RasterState& s, uint32_t slot_begin, uint32_t slot_end) {
    copy_records(s, slot_begin, slot_end, [](size_t, const SplatRecord&) {});
  }

  // The forward pass: gather, and the blocks of the tile whose top-left pixel
  // is (tile_x0, tile_y0) that each Gaussian reaches, found from the record
  // as it is loaded (re-reading the fresh copy would stall on it), written to
  // masks (one per record, kept for the backward pass) and to each block's list.
  void gather_with_blocks(const RasterState& s, uint32_t slot_begin, uint32_t slot_end, int tile_x0,
                          int tile_y0, uint16_t* masks) {
    block_capacity = slot_end - slot_begin;
    if (block_entries.size() < kBlocksPerTile * block_capacity)
      block_entries.resize(kBlocksPerTile * block_capacity);
#if defined(__AVX512F__)
    // The blocks as lanes: one scatter appends k to the lists of the blocks in
    // its mask. A loop over the mask's bits ends after a varying number of
    // blocks, which the branch predictor misses about once a record.
    const __m512i first =
        _mm512_mullo_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                           _mm512_set1_epi32(int32_t(block_capacity)));
    __m512i count = _mm512_setzero_si512();
    copy_records(s, slot_begin, slot_end, [&](size_t k, const SplatRecord& record) {
      const uint16_t mask = blocks_reached(record, float(tile_x0), float(tile_y0));
      masks[k] = mask;
      _mm512_mask_i32scatter_epi32(block_entries.data(), mask, _mm512_add_epi32(first, count),
                                   _mm512_set1_epi32(int32_t(k)), 4);
      count = _mm512_mask_add_epi32(count, mask, count, _mm512_set1_epi32(1));
    });
    _mm512_storeu_si512(block_count.data(), count);
#else
    block_count.fill(0);
    copy_records(s, slot_begin, slot_end, [&](size_t k, const SplatRecord& record) {
      const uint16_t mask = blocks_reached(record, float(tile_x0), float(tile_y0));
      masks[k] = mask;
      for (unsigned m = mask; m; m &= m - 1) {
        const int b = __builtin_ctz(m);
        block_entries[b * block_capacity + block_count[b]++] = uint32_t(k);
      }
    });
#endif
    block_mask = masks;
  }

  // The backward pass: the masks the forward pass found.
  void use_blocks(const uint16_t* masks) { block_mask = masks; }

 private:
  // Copies the records of the slots, calling on_record(k, record) on each as
  // it is loaded. The records are read in depth order, i.e. at random:
  // prefetching ahead overlaps the loads instead of waiting on memory one by one.
  template <typename OnRecord>
  void copy_records(const RasterState& s, uint32_t slot_begin, uint32_t slot_end,
                    OnRecord&& on_record) {
    const size_t n = slot_end - slot_begin;
    // data() + offset, not &v[offset]: the list is empty when no Gaussian is
    // in view, and indexing an empty vector is undefined (UBSan).
    const uint32_t* gaussian = s.bins.slot_gaussian.data() + slot_begin;
    if (records.size() < n) records.resize(n);
    count = n;
    constexpr size_t kAhead = 16;
    for (size_t k = 0; k < std::min(n, kAhead); ++k) __builtin_prefetch(&s.records[gaussian[k]]);
    for (size_t k = 0; k < n; ++k) {
      if (k + kAhead < n) __builtin_prefetch(&s.records[gaussian[k + kAhead]]);
      const SplatRecord& record = s.records[gaussian[k]];
      on_record(k, record);
      records[k] = record;
    }
  }

  static constexpr float kSpan = float(kBlockSize - 1);  // cx1 - cx0

  // Whether Gaussian g reaches a pixel centre of each block: its bounding box
  // first, then the exact test of its ellipse against the block's rectangle,
  // which culls elongated Gaussians that only pass their box. q(d) =
  // A dx^2 + 2 B dx dy + C dy^2 over offsets d = pixel - mean; if the mean is
  // outside the rectangle, the minimum of the convex q lies on an edge.
  static uint16_t blocks_reached(const SplatRecord& g, float tile_x0, float tile_y0) {
    const float inv_A = 1.f / g.A, inv_C = 1.f / g.C;
    alignas(64) float hit[kBlocksPerTile];
#pragma GCC ivdep
    for (int b = 0; b < kBlocksPerTile; ++b) {
      const float ax = tile_x0 + kTileBlockBounds.x0[b] - g.mx, bx = ax + kSpan;
      const float ay = tile_y0 + kTileBlockBounds.y0[b] - g.my, by = ay + kSpan;
      const float in_box = (bx >= -g.reach_x ? 1.f : 0.f) * (ax <= g.reach_x ? 1.f : 0.f) *
                           (by >= -g.reach_y ? 1.f : 0.f) * (ay <= g.reach_y ? 1.f : 0.f);
      const float mean_inside = (ax <= 0.f ? 1.f : 0.f) * (bx >= 0.f ? 1.f : 0.f) *
                                (ay <= 0.f ? 1.f : 0.f) * (by >= 0.f ? 1.f : 0.f);
      auto q = [&](float dx, float dy) {
        return g.A * dx * dx + 2 * g.B * dx * dy + g.C * dy * dy;
      };
      auto clamp = [](float v, float lo, float hi) { return std::min(std::max(v, lo), hi); };
      float best = q(ax, clamp(-g.B * ax * inv_C, ay, by));
      best = std::min(best, q(bx, clamp(-g.B * bx * inv_C, ay, by)));
      best = std::min(best, q(clamp(-g.B * ay * inv_A, ax, bx), ay));
      best = std::min(best, q(clamp(-g.B * by * inv_A, ax, bx), by));
      const float near = std::max(mean_inside, best <= g.reach_level ? 1.f : 0.f);
      hit[b] = in_box * near;
    }
#if defined(__AVX512F__)
    // One compare into a mask register, or two and their sign bits on AVX2;
    // GCC leaves the loop below scalar.
    return uint16_t(_mm512_cmp_ps_mask(_mm512_load_ps(hit), _mm512_setzero_ps(), _CMP_GT_OQ));
#elif defined(__AVX2__)
    const auto half = [&](int first) {
      const __m256 positive =
          _mm256_cmp_ps(_mm256_load_ps(hit + first), _mm256_setzero_ps(), _CMP_GT_OQ);
      return unsigned(_mm256_movemask_ps(positive));
    };
    return uint16_t(half(0) | half(8) << 8);
#else
    uint16_t mask = 0;
    for (int b = 0; b < kBlocksPerTile; ++b) mask |= uint16_t(hit[b] > 0.f ? 1u << b : 0u);
    return mask;
#endif
  }
};

}  // namespace splat
