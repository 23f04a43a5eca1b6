#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#if defined(__SSE__)
#include <immintrin.h>
#endif

#include "splat/render/fast_exp.h"
#include "splat/render/gaussian_power.h"
#include "splat/render/pixel_block.h"
#include "splat/render/rasterize.h"
#include "splat/render/tile_gaussians.h"

namespace splat {
namespace {

constexpr int kLanes = kBlockLanes;

// Per-pixel blending state of one 4x4 block.
struct BlockState {
  alignas(64) float T[kLanes];
  alignas(64) float color[3][kLanes];
  alignas(64) float depth[kLanes];
  alignas(64) float done[kLanes];  // 1 once the ray has terminated (or lies off the image)
  alignas(64) int32_t last[kLanes];
  alignas(64) int32_t blended[kLanes];
  alignas(64) float best_instance_alpha[kLanes];
  alignas(64) int32_t instance_label[kLanes];
  alignas(64) float best_weight[kLanes];
  alignas(64) int32_t baseline_label[kLanes];
  // Instance maps, plane-major, kLanes each. A plane is cleared when a
  // Gaussian first reaches it in this block: a block sees few objects, and
  // clearing all of them for every block cost a few per cent of a mask render.
  std::vector<float> planes;
  std::vector<uint8_t> touched;         // per plane: cleared and written in this block
  std::vector<int32_t> touched_planes;  // which, to reset them cheaply

  // Field by field, each a vector store: one loop over the lanes setting
  // every field became a scalar store per lane and field, a sixth of the
  // tile loop's time early in training (a block per 16 pixels).
  void reset(const PixelBlock& block, int width, int height, size_t num_planes) {
    std::fill_n(T, kLanes, 1.f);
    for (float* field : {color[0], color[1], color[2], depth, best_instance_alpha, best_weight})
      std::fill_n(field, kLanes, 0.f);
    for (int32_t* field : {last, blended, instance_label, baseline_label})
      std::fill_n(field, kLanes, 0);
    if (block.x0 + kBlockSize <= width && block.y0 + kBlockSize <= height)
      std::fill_n(done, kLanes, 0.f);
    else
      for (int l = 0; l < kLanes; ++l) done[l] = block.inside(l, width, height) ? 0.f : 1.f;
    planes.resize(num_planes * kLanes);
    touched.resize(num_planes, 0);
    for (int32_t p : touched_planes) touched[size_t(p)] = 0;
    touched_planes.clear();
  }
  void touch(int32_t p) {
    if (touched[size_t(p)]) return;
    touched[size_t(p)] = 1;
    touched_planes.push_back(p);
    std::fill_n(&planes[size_t(p) * kLanes], kLanes, 0.f);
  }
  bool all_done() const {
    float d = 1.f;
    for (int l = 0; l < kLanes; ++l) d = std::min(d, done[l]);
    return d > 0.f;
  }
};

// Blends Gaussian k of the tile into the block whose first pixel centre is
// (px0, py0).
template <bool kColor, bool kDepth, bool kInstance, bool kLabels>
inline void blend(const TileGaussians& tg, size_t k, float px0, float py0, BlockState& s) {
  const SplatRecord& g = tg[k];
  const float mx = g.mx - px0, my = g.my - py0, A = g.A, B = g.B, C = g.C;
  const float op = g.opacity, op_star = g.instance_opacity, z = g.depth;
  const int32_t position = int32_t(k) + 1, label = g.label;
  float* plane = kInstance ? &s.planes[size_t(g.plane) * kLanes] : nullptr;
  float cr = 0, cg = 0, cb = 0;
  if constexpr (kColor) cr = g.r, cg = g.g, cb = g.b;
#pragma GCC ivdep
  for (int l = 0; l < kLanes; ++l) {
    const float dx = mx - kLaneOffsets.x[l], dy = my - kLaneOffsets.y[l];
    const float power = gaussian_power(A, B, C, dx, dy);
    const float G = fast_exp(std::min(power, 0.f));
    const float alpha = std::min(kMaxAlpha, op * G);
    // Conditions as float 0/1 masks and selects on them: GCC if-converts
    // these, so the lanes vectorise (bool & bool ? a : b it does not).
    const float m_valid = (s.done[l] == 0.f ? 1.f : 0.f) * (power <= 0.f ? 1.f : 0.f) *
                          (alpha >= kMinAlpha ? 1.f : 0.f);
    const float next_T = s.T[l] * (1.f - alpha);
    const float m_terminate = next_T < kMinTransmittance ? m_valid : 0.f;
    const float m_contribute = m_valid - m_terminate;
    const float w = m_contribute * alpha * s.T[l];
    if constexpr (kColor) {
      s.color[0][l] += w * cr;
      s.color[1][l] += w * cg;
      s.color[2][l] += w * cb;
    }
    if constexpr (kDepth) s.depth[l] += w * z;
    if constexpr (kInstance || kLabels) {
      const float alpha_star = std::min(kMaxAlpha, op_star * G);
      if constexpr (kInstance) plane[l] += m_contribute * alpha_star * s.T[l];
      if constexpr (kLabels) {
        const float m_better = m_contribute * (alpha_star >= kMinAlpha ? 1.f : 0.f) *
                               (alpha_star > s.best_instance_alpha[l] ? 1.f : 0.f);
        s.best_instance_alpha[l] = m_better > 0.f ? alpha_star : s.best_instance_alpha[l];
        s.instance_label[l] = m_better > 0.f ? label : s.instance_label[l];
        // w > 0 only where the Gaussian contributes.
        const float m_heavier = w > s.best_weight[l] ? 1.f : 0.f;
        s.best_weight[l] = m_heavier > 0.f ? w : s.best_weight[l];
        s.baseline_label[l] = m_heavier > 0.f ? label : s.baseline_label[l];
      }
    }
    s.last[l] = m_contribute > 0.f ? position : s.last[l];
    // m_contribute is 0 or 1: added as a number, since GCC made the
    // conditional add a branch and a masked store on AVX2.
    s.blended[l] += int32_t(m_contribute);
    s.T[l] = m_contribute > 0.f ? next_T : s.T[l];
    s.done[l] = std::max(s.done[l], m_terminate);
  }
}

#if defined(__AVX2__) && defined(__FMA__)
// blend_block without the label branch, a register of lanes at a time (the
// whole block with AVX-512, one 8-lane half with AVX2), its state in
// registers for the whole list and its conditions as masks: GCC's lane loop
// stores the state after every entry and carries each condition as a float
// 0/1 value, a third more vector instructions an entry (twice the vectors
// on AVX2). The same operations as blend's where they round, fused alike,
// so the same bits. The occupancy planes stay in memory: an entry adds to
// its label's plane only.
template <bool kColor, bool kDepth, bool kInstance>
void blend_block_in_registers(const TileGaussians& tg, int b, const PixelBlock& block,
                              BlockState& s) {
  using V = RegisterLanes;
  using F = V::F;
  using M = V::M;
  const uint32_t* entries = tg.block_list(b);
  const uint32_t count = tg.block_count[b];
  const float x0 = block.cx0(), y0 = block.cy0();
  const F zero = V::zero(), one = V::set1(1.f);
  for (int h = 0; h < kLanes; h += V::kWidth) {
    const F offset_x = V::load(kLaneOffsets.x + h), offset_y = V::load(kLaneOffsets.y + h);
    F T = V::load(s.T + h);
    M done = V::not_equal(V::load(s.done + h), zero);
    F red = V::load(s.color[0] + h), green = V::load(s.color[1] + h);
    F blue = V::load(s.color[2] + h), depth = V::load(s.depth + h);
    V::I last = V::load(s.last + h), blended = V::load(s.blended + h);
    for (uint32_t e = 0; e < count; ++e) {
      const size_t k = entries[e];
      const SplatRecord& g = tg[k];
      const F dx = V::sub(V::set1(g.mx - x0), offset_x);
      const F dy = V::sub(V::set1(g.my - y0), offset_y);
      const F power = gaussian_power_lanes<V>(g.A, g.B, g.C, dx, dy);
      const F G = fast_exp_lanes<V>(V::min(power, zero));
      const F alpha = V::min(V::mul(V::set1(g.opacity), G), V::set1(kMaxAlpha));
      const M valid = V::and_not(
          done, V::both(V::less_equal(power, zero), V::greater_equal(alpha, V::set1(kMinAlpha))));
      const F next_T = V::mul(T, V::sub(one, alpha));
      const M terminate = V::both(valid, V::less(next_T, V::set1(kMinTransmittance)));
      const M contribute = V::and_not(terminate, valid);
      const F w = V::zero_unless(contribute, V::mul(alpha, T));
      if constexpr (kColor) {
        red = V::fmadd(w, V::set1(g.r), red);
        green = V::fmadd(w, V::set1(g.g), green);
        blue = V::fmadd(w, V::set1(g.b), blue);
      }
      if constexpr (kDepth) depth = V::fmadd(w, V::set1(g.depth), depth);
      if (kInstance && g.plane >= 0) {
        s.touch(g.plane);
        float* plane = &s.planes[size_t(g.plane) * kLanes + h];
        const F alpha_star = V::min(V::mul(V::set1(g.instance_opacity), G), V::set1(kMaxAlpha));
        V::storeu(plane, V::fmadd(V::zero_unless(contribute, alpha_star), T, V::loadu(plane)));
      }
      last = V::select(contribute, V::set1(int32_t(k) + 1), last);
      blended = V::count_where(contribute, blended);
      T = V::select(contribute, next_T, T);
      done = V::either(done, terminate);
      if ((e & 15) == 15 && V::all(done)) break;
    }
    // What store_block reads; `done` is not read after the block.
    V::store(s.T + h, T);
    V::store(s.color[0] + h, red);
    V::store(s.color[1] + h, green);
    V::store(s.color[2] + h, blue);
    V::store(s.depth + h, depth);
    V::store(s.last + h, last);
    V::store(s.blended + h, blended);
  }
}
#endif

template <bool kColor, bool kDepth, bool kInstance, bool kLabels>
void blend_block(const TileGaussians& tg, int b, const PixelBlock& block, BlockState& s) {
#if defined(__AVX2__) && defined(__FMA__)
  if constexpr (!kLabels)
    return blend_block_in_registers<kColor, kDepth, kInstance>(tg, b, block, s);
#endif
  const uint32_t* entries = tg.block_list(b);
  const uint32_t count = tg.block_count[b];
  const float x0 = block.cx0(), y0 = block.cy0();
  for (uint32_t e = 0; e < count; ++e) {
    const size_t k = entries[e];
    // Only Gaussians whose label has a map pay for the instance branch.
    if (kInstance && tg[k].plane >= 0) {
      s.touch(tg[k].plane);
      blend<kColor, kDepth, kInstance, kLabels>(tg, k, x0, y0, s);
    } else
      blend<kColor, kDepth, false, kLabels>(tg, k, x0, y0, s);
    if ((e & 15) == 15 && s.all_done()) break;
  }
}

using BlockFunction = void (*)(const TileGaussians&, int, const PixelBlock&, BlockState&);

template <int... kFlags>
constexpr auto block_functions(std::integer_sequence<int, kFlags...>) {
  return std::array<BlockFunction, sizeof...(kFlags)>{
      blend_block<bool(kFlags & 8), bool(kFlags & 4), bool(kFlags & 2), bool(kFlags & 1)>...};
}

BlockFunction pick_block_function(bool color, bool depth, bool instance, bool labels) {
  static constexpr auto table = block_functions(std::make_integer_sequence<int, 16>());
  return table[(color ? 8 : 0) + (depth ? 4 : 0) + (instance ? 2 : 0) + (labels ? 1 : 0)];
}

// The block's pixels into the outputs, and the backward pass's state of
// all its lanes into the tile-ordered arrays from `slot` on.
void store_block(const RenderSettings& settings, const PixelBlock& block, const BlockState& s,
                 size_t slot, RasterState& st, RenderOutput& out) {
  const int W = st.width, H = st.height;
  for (int l = 0; l < kLanes; ++l) {
    st.final_transmittance[slot + l] = s.T[l];
    st.n_contrib[slot + l] = uint32_t(s.last[l]);
  }
  // Row by row over the block's pixels on the image, without a test per
  // lane, and output by output: with the outputs' tests inside one loop
  // over the pixels GCC stored them a value at a time.
  const int rows = std::min(kBlockSize, H - block.y0), columns = std::min(kBlockSize, W - block.x0);
  for (int r = 0; r < rows; ++r) {
    const int l = r * kBlockSize;  // the row's first lane
    const size_t pix = size_t(block.y0 + r) * W + block.x0;
    if (settings.color)
      for (int i = 0; i < columns; ++i)
        for (int c = 0; c < 3; ++c)
          out.color[3 * (pix + i) + c] = s.color[c][l + i] + s.T[l + i] * settings.background[c];
    for (int i = 0; i < columns; ++i) out.alpha[pix + i] = 1.f - s.T[l + i];
    if (settings.depth)
      for (int i = 0; i < columns; ++i) out.depth[pix + i] = s.depth[l + i];
    for (int i = 0; i < columns; ++i) out.contributors[pix + i] = uint32_t(s.blended[l + i]);
    if (settings.instance_label_map)
      for (int i = 0; i < columns; ++i) out.instance_label[pix + i] = s.instance_label[l + i];
    if (settings.baseline_label_map)
      for (int i = 0; i < columns; ++i) out.baseline_label[pix + i] = s.baseline_label[l + i];
  }
}

// Writes 16 floats (64 bytes) to the output. The occupancy planes are the
// bulk of a mask render's output (4 bytes a pixel and object) and are not
// read back: where the row is one whole aligned cache line, streaming stores
// write it without first reading it into the cache.
inline void write_tile_row(const float* from, float* to) {
#if defined(__SSE__)
  if (reinterpret_cast<uintptr_t>(to) % 64 == 0) {
    for (int x = 0; x < kTileSize; x += 4) _mm_stream_ps(to + x, _mm_loadu_ps(from + x));
    return;
  }
#endif
  std::copy_n(from, kTileSize, to);
}

// The occupancy planes of one tile, gathered from its blocks and written out
// a tile row at a time. A plane no block of the tile reached is written as
// zeros without being cleared here.
struct TilePlanes {
  std::vector<float> values;     // [plane][row][column], kTileSize x kTileSize each
  std::vector<uint8_t> touched;  // per plane: a block of this tile wrote it
  alignas(64) float zeros[kTileSize] = {};

  void begin(size_t planes) {
    values.resize(planes * kTileSize * kTileSize);
    touched.assign(planes, 0);
  }
  // Copies block b's planes; a plane the block did not reach is zero there.
  void add_block(const BlockState& s, int b) {
    const PixelBlock block = PixelBlock::in_tile(0, 0, b);
    for (int32_t m : s.touched_planes) {
      float* plane = &values[size_t(m) * kTileSize * kTileSize];
      if (!touched[size_t(m)]) std::fill_n(plane, kTileSize * kTileSize, 0.f);
      touched[size_t(m)] = 1;
      for (int row = 0; row < kBlockSize; ++row)
        std::copy_n(&s.planes[size_t(m) * kLanes + row * kBlockSize], kBlockSize,
                    plane + (block.y0 + row) * kTileSize + block.x0);
    }
  }
  void store(int tile_x0, int tile_y0, int W, int H, float* maps) const {
    const size_t pixels = size_t(W) * H;
    const int columns = std::min(kTileSize, W - tile_x0), rows = std::min(kTileSize, H - tile_y0);
    for (size_t m = 0; m < touched.size(); ++m) {
      const float* plane = touched[m] ? &values[m * kTileSize * kTileSize] : nullptr;
      for (int row = 0; row < rows; ++row) {
        const float* from = plane ? plane + row * kTileSize : zeros;
        float* to = maps + m * pixels + size_t(tile_y0 + row) * W + tile_x0;
        if (columns == kTileSize)
          write_tile_row(from, to);
        else
          std::copy_n(from, columns, to);
      }
    }
  }
};

void pack_records(bool color, RasterState& st) {
  const ProjectedGaussians& p = st.projected;
  st.records.resize(p.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, p.size(), 8192), [&](const auto& range) {
    for (size_t i = range.begin(); i < range.end(); ++i) {
      if (!p.visible(i)) continue;
      SplatRecord& r = st.records[i];
      r.mx = p.mean2d[2 * i];
      r.my = p.mean2d[2 * i + 1];
      r.A = p.conic[3 * i];
      r.B = p.conic[3 * i + 1];
      r.C = p.conic[3 * i + 2];
      r.opacity = p.opacity[i];
      r.instance_opacity = p.instance_opacity[i];
      r.depth = p.depth[i];
      r.r = color ? p.color[3 * i] : 0.f;
      r.g = color ? p.color[3 * i + 1] : 0.f;
      r.b = color ? p.color[3 * i + 2] : 0.f;
      r.reach_x = p.reach[2 * i];
      r.reach_y = p.reach[2 * i + 1];
      r.label = st.labels[i];
      const int32_t l = st.labels[i];
      r.plane = (l >= 0 && size_t(l) < st.map_of_label.size()) ? st.map_of_label[l] : -1;
      r.reach_level = 2.002f * std::log(255.f * r.opacity) + 1e-3f;
    }
  });
}

}  // namespace

void rasterize_forward(const RenderSettings& settings, RasterState& st, RenderOutput& out) {
  const int W = st.width, H = st.height;
  const size_t pixels = size_t(W) * H;
  const size_t planes = out.instance_map_labels.size();
  const bool labels = settings.instance_label_map || settings.baseline_label_map;
  out.width = W;
  out.height = H;
  // store_block writes every pixel of every output: sizes only, no fill.
  out.color.resize(settings.color ? 3 * pixels : 0);
  out.alpha.resize(pixels);
  out.depth.resize(settings.depth ? pixels : 0);
  out.contributors.resize(pixels);
  out.instance_maps.resize(planes * pixels);
  out.instance_label.resize(settings.instance_label_map ? pixels : 0);
  out.baseline_label.resize(settings.baseline_label_map ? pixels : 0);
  const size_t tiles = size_t(st.bins.tiles_x) * st.bins.tiles_y;
  st.final_transmittance.resize(tiles * kTilePixels);
  st.n_contrib.resize(tiles * kTilePixels);
  const BlockFunction block_fn =
      pick_block_function(settings.color, settings.depth, planes > 0, labels);
  pack_records(settings.color, st);
  st.slot_blocks.resize(st.bins.num_entries());

  // The tile's Gaussians per thread, not per task: a task's buffers grew
  // tile by tile and were freed at its end, some hundred times a view.
  tbb::enumerable_thread_specific<TileGaussians> gathered;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles, 1), [&](const auto& range) {
    TileGaussians& tg = gathered.local();
    BlockState s;
    TilePlanes tile_planes;
    for (size_t t = range.begin(); t < range.end(); ++t) {
      const int tile_x0 = int(t % st.bins.tiles_x) * kTileSize;
      const int tile_y0 = int(t / st.bins.tiles_x) * kTileSize;
      const uint32_t lo = st.bins.tile_start[t], hi = st.bins.tile_start[t + 1];
      tg.gather_with_blocks(st, lo, hi, tile_x0, tile_y0, st.slot_blocks.data() + lo);
      tile_planes.begin(planes);
      for (int b = 0; b < kBlocksPerTile; ++b) {
        const PixelBlock block = PixelBlock::in_tile(tile_x0, tile_y0, b);
        const size_t slot = t * kTilePixels + size_t(b) * kLanes;
        if (block.x0 >= W || block.y0 >= H) {
          std::fill_n(&st.final_transmittance[slot], kLanes, 1.f);
          std::fill_n(&st.n_contrib[slot], kLanes, 0u);
          continue;
        }
        s.reset(block, W, H, planes);
        block_fn(tg, b, block, s);
        store_block(settings, block, s, slot, st, out);
        tile_planes.add_block(s, b);
      }
      tile_planes.store(tile_x0, tile_y0, W, H, out.instance_maps.data());
    }
#if defined(__SSE__)
    _mm_sfence();  // the streaming stores are visible before the loop returns
#endif
  });
}

}  // namespace splat
