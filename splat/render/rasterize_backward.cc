// The rasterizer's backward pass: one tile's pixels walked back to front,
// each Gaussian's gradient summed over its pixels as moments, with a portable
// form of its lane sums and AVX-512 and AVX2 forms that add the lanes in one
// order, and for the training losses a loop with its sums in registers, a
// whole block a register with AVX-512 and an 8-lane half with AVX2 (the
// same values). One step kept in one file, as gsplat
// keeps its rasterize backward: its parts share the per-tile state and are
// only correct together. The slow reference it is tested against is kept
// apart, in tests/splat/render/reference_renderer.cc.
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#if defined(__AVX2__)
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
constexpr int kBlocks = kBlocksPerTile;  // state arrays are [block][lane]

// Gradient of one entry (Gaussian in one tile), summed over its pixels.
enum EntryGrad {
  kMeanX,
  kMeanY,
  kConicA,
  kConicB,
  kConicC,
  kRed,
  kGreen,
  kBlue,
  kDepth,
  kOpacity,
  kInstanceOpacity,
  kEntryGrads
};
static_assert(kEntryGrads == kRasterEntryGradients);

// While a Gaussian's pixels are summed, the slots of the mean and conic hold
// moments of g = dL/dpower over the offsets d = mean - pixel: sum g dx, sum g
// dy, sum g dx^2, sum g dx dy, sum g dy^2. With power = -(A dx^2 + 2 B dx dy +
// C dy^2) / 2, the gradients follow from them (to_mean_conic_gradients):
// seven operations a pixel instead of the fourteen of each pixel's gradient.
enum PowerMoment {
  kSumX = kMeanX,
  kSumY = kMeanY,
  kSumXX = kConicA,
  kSumXY = kConicB,
  kSumYY = kConicC
};

// Turns the summed moments of one entry into its mean and conic gradients.
inline void to_mean_conic_gradients(const SplatRecord& g, float* entry) {
  const float sx = entry[kSumX], sy = entry[kSumY];
  const float sxx = entry[kSumXX], sxy = entry[kSumXY], syy = entry[kSumYY];
  entry[kMeanX] = -(g.A * sx + g.B * sy);
  entry[kMeanY] = -(g.C * sy + g.B * sx);
  entry[kConicA] = -0.5f * sxx;
  entry[kConicB] = -sxy;
  entry[kConicC] = -0.5f * syy;
}

// Per-pixel state of one tile, going back to front: [block][lane].
struct TileBackState {
  alignas(64) float T[kBlocks][kLanes];  // transmittance after the current Gaussian
  alignas(64) float T_final[kBlocks][kLanes];
  alignas(64) int32_t last[kBlocks][kLanes];
  alignas(64) float g_color[3][kBlocks][kLanes];  // dL/d(output colour)
  alignas(64) float g_alpha[kBlocks][kLanes];
  alignas(64) float g_depth[kBlocks][kLanes];
  // What lies behind the current Gaussian, weighted by the colour gradient:
  // sum over channels of dL/dC_ch (sum of w_k c_k,ch over the Gaussians
  // behind + T_final background_ch). Only this sum enters dL/dalpha, so one
  // plane instead of three of colour and three of background.
  alignas(64) float behind_color[kBlocks][kLanes];
  alignas(64) float behind_depth[kBlocks][kLanes];
  alignas(64) int32_t block_last[kBlocks];  // largest `last` of each block
  // First pixel centre of each block (PixelBlock's cx0 and cy0), once per
  // tile: in the register loop, finding them from the block's index for
  // every entry took a tenth of its instructions.
  alignas(64) float block_cx0[kBlocks];
  alignas(64) float block_cy0[kBlocks];
  std::vector<float> g_planes;       // dL/dS: [plane][block][lane]
  std::vector<uint8_t> tile_planes;  // per plane: loaded for this tile
  int32_t first_geometry_plane = 0;  // planes below it reach sigma* only
};

// sum += value, or, for the first block an entry visits (kFirst), sum =
// value: an entry's sums start unset, since clearing them cost a call to
// memset per entry. Only a sum of zeros can come out different, as -0
// instead of +0, which no step after the rasterizer tells apart.
template <bool kFirst>
inline void accumulate(float& sum, float value) {
  if constexpr (kFirst)
    sum = value;
  else
    sum += value;
}

// One Gaussian on one block (first pixel centre px0, py0): adds its pixels'
// gradient terms to acc, or sets them with kFirst (acc's rows the
// instantiation has no terms for set to zero). kAlphaDepth: whether the loss
// has alpha or depth terms (training has neither; leaving them out saves a
// tenth of the work). instance_geometry: 1, or 0 when the Gaussian's
// occupancy map does not reach the geometry.
template <bool kColor, bool kInstance, bool kAlphaDepth, bool kFirst>
inline void back_block(const TileGaussians& tg, size_t k, float px0, float py0, int block,
                       const float* g_plane, float instance_geometry, TileBackState& s,
                       float (&acc)[kEntryGrads][kLanes]) {
  const SplatRecord& gs = tg[k];
  const float mx = gs.mx - px0, my = gs.my - py0, A = gs.A, B = gs.B, C = gs.C;
  const float op = gs.opacity, op_star = gs.instance_opacity, z = gs.depth;
  const float op_star_geometry = instance_geometry * op_star;  // once, not per lane
  const int32_t position = int32_t(k);
  float c[3] = {0, 0, 0};
  if constexpr (kColor) c[0] = gs.r, c[1] = gs.g, c[2] = gs.b;
  float* T = s.T[block];
#pragma GCC ivdep
  for (int l = 0; l < kLanes; ++l) {
    const float dx = mx - kLaneOffsets.x[l], dy = my - kLaneOffsets.y[l];
    const float power = gaussian_power(A, B, C, dx, dy);
    const float G = fast_exp(std::min(power, 0.f));
    const float raw_alpha = op * G;
    const float alpha = std::min(kMaxAlpha, raw_alpha);
    // Float 0/1 masks and selects on them keep the lanes vectorised.
    const float m_valid = (position < s.last[block][l] ? 1.f : 0.f) * (power <= 0.f ? 1.f : 0.f) *
                          (alpha >= kMinAlpha ? 1.f : 0.f);
    const float inv_one_minus = 1.f / (1.f - alpha);
    const float T_i = m_valid > 0.f ? T[l] * inv_one_minus : T[l];
    const float w = m_valid * alpha * T_i;

    float g_alpha = 0.f;
    if constexpr (kAlphaDepth) {
      g_alpha += s.g_alpha[block][l] * s.T_final[block][l] * inv_one_minus;
      g_alpha += s.g_depth[block][l] * (z * T_i - s.behind_depth[block][l] * inv_one_minus);
      accumulate<kFirst>(acc[kDepth][l], s.g_depth[block][l] * w);
      s.behind_depth[block][l] += w * z;
    }
    if constexpr (kColor) {
      // dL/dalpha from colour: sum over ch of g_ch (c_ch T_i - behind_ch / (1 - alpha)).
      const float g_c = s.g_color[0][block][l] * c[0] + s.g_color[1][block][l] * c[1] +
                        s.g_color[2][block][l] * c[2];
      g_alpha += g_c * T_i - s.behind_color[block][l] * inv_one_minus;
      for (int ch = 0; ch < 3; ++ch)
        accumulate<kFirst>(acc[kRed + ch][l], s.g_color[ch][block][l] * w);
      s.behind_color[block][l] += w * g_c;
    }
    // The alpha clamp at 0.99 has zero derivative, in both branches.
    g_alpha *= m_valid * (raw_alpha < kMaxAlpha ? 1.f : 0.f);
    float g_G = g_alpha * op;
    accumulate<kFirst>(acc[kOpacity][l], g_alpha * G);
    if constexpr (kInstance) {
      // S_j = sum alpha*_i T_i with T_i held constant: the object loss reaches
      // sigma* and the geometry (through G), never sigma or colour.
      const float g_star = m_valid * (op_star * G < kMaxAlpha ? 1.f : 0.f) * g_plane[l] * T_i;
      accumulate<kFirst>(acc[kInstanceOpacity][l], g_star * G);
      g_G += g_star * op_star_geometry;
    }
    // The moments of dL/dpower over the offsets (see PowerMoment); A, B and C
    // are the same for every pixel, so they are applied once per entry.
    const float g_power = g_G * G;
    const float g_dx = g_power * dx, g_dy = g_power * dy;
    accumulate<kFirst>(acc[kSumX][l], g_dx);
    accumulate<kFirst>(acc[kSumY][l], g_dy);
    accumulate<kFirst>(acc[kSumXX][l], g_dx * dx);
    accumulate<kFirst>(acc[kSumXY][l], g_dx * dy);
    accumulate<kFirst>(acc[kSumYY][l], g_dy * dy);
    if constexpr (kFirst) {
      if constexpr (!kAlphaDepth) acc[kDepth][l] = 0.f;
      if constexpr (!kColor)
        for (int ch = 0; ch < 3; ++ch) acc[kRed + ch][l] = 0.f;
      if constexpr (!kInstance) acc[kInstanceOpacity][l] = 0.f;
    }
    T[l] = T_i;
  }
}

// Bit b: block b has a pixel whose last contributor is entry k or one behind
// it, so that k may have blended there. One mask, not a branch per block: the
// branch predictor misses such tests often.
inline unsigned blocks_blended_past(const TileBackState& s, int32_t k) {
#if defined(__AVX512F__)
  return _mm512_cmpgt_epi32_mask(_mm512_load_si512(s.block_last), _mm512_set1_epi32(k));
#elif defined(__AVX2__)
  // GCC 12 made the portable loop sixteen scalar compares and shifts.
  const __m256i key = _mm256_set1_epi32(k);
  const auto half = [&](int first) {
    const __m256i last = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.block_last + first));
    return unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(last, key))));
  };
  return half(0) | half(8) << 8;
#else
  unsigned mask = 0;
  for (int b = 0; b < kBlocks; ++b) mask |= s.block_last[b] > k ? 1u << b : 0u;
  return mask;
#endif
}

#if defined(__AVX512F__)
// Shuffles written as their masked forms with every lane kept (the same
// instructions): the unmasked intrinsics trip GCC 12's -Wmaybe-uninitialized.
template <int kImm>
inline __m512 shuffle_quarters(__m512 a, __m512 b) {
  return _mm512_maskz_shuffle_f32x4(__mmask16(0xffff), a, b, kImm);
}
// Lanes 0 and 1 swapped, 2 and 3, and so on.
inline __m512 swap_pairs(__m512 a) {
  return _mm512_maskz_permute_ps(__mmask16(0xffff), a, _MM_SHUFFLE(2, 3, 0, 1));
}

// Lane j: the sum of acc[j] over its 16 lanes. The 11 rows are summed at once
// by a tree of shuffles and adds: the lanes are added pairwise, not in lane
// order, so float rounding differs from the portable loop, whose adds a
// compiler must keep in order (a quarter of the tile loop's time went there).
inline __m512 lane_sums(const float (&acc)[kEntryGrads][kLanes]) {
  static_assert(kLanes == 16 && kEntryGrads <= 16);
  // The tree sums slot s into output lane p[s]; p is its own inverse, so
  // slot s takes row p[s] and lane j gets row j.
  constexpr int p[16] = {0, 2, 1, 3, 8, 10, 9, 11, 4, 6, 5, 7, 12, 14, 13, 15};
  __m512 v[16];
  for (int slot = 0; slot < 16; ++slot)
    v[slot] = p[slot] < kEntryGrads ? _mm512_load_ps(acc[p[slot]]) : _mm512_set1_ps(0.f);
  // 16 -> 8 vectors: each 256-bit half holds 8 partial sums of one row.
  for (int j = 0; j < 8; ++j)
    v[j] = _mm512_add_ps(shuffle_quarters<_MM_SHUFFLE(1, 0, 1, 0)>(v[j], v[j + 8]),
                         shuffle_quarters<_MM_SHUFFLE(3, 2, 3, 2)>(v[j], v[j + 8]));
  // 8 -> 4: each 128-bit quarter holds 4 partial sums of one row.
  for (int j = 0; j < 4; ++j)
    v[j] = _mm512_add_ps(shuffle_quarters<_MM_SHUFFLE(2, 0, 2, 0)>(v[j], v[j + 4]),
                         shuffle_quarters<_MM_SHUFFLE(3, 1, 3, 1)>(v[j], v[j + 4]));
  // 4 -> 2: 2 partial sums of a row, within each quarter.
  for (int j = 0; j < 2; ++j)
    v[j] = _mm512_add_ps(_mm512_shuffle_ps(v[j], v[j + 2], _MM_SHUFFLE(1, 0, 1, 0)),
                         _mm512_shuffle_ps(v[j], v[j + 2], _MM_SHUFFLE(3, 2, 3, 2)));
  // 2 -> 1.
  return _mm512_add_ps(_mm512_shuffle_ps(v[0], v[1], _MM_SHUFFLE(2, 0, 2, 0)),
                       _mm512_shuffle_ps(v[0], v[1], _MM_SHUFFLE(3, 1, 3, 1)));
}

// to_mean_conic_gradients on the vector of sums, which then goes to memory
// in one store (reading it back from memory to finish it stalls: a masked
// store does not forward to loads).
inline void store_entry(__m512 sums, const SplatRecord& g, float* entry) {
  // entry = -(scale * sums + cross * swapped), with the moments' two first
  // lanes swapped: scale (A, C, 1/2, 1, 1/2, -1, ...), cross (B, B, 0, ...).
  const __m512 swapped = swap_pairs(sums);
  const __m512 scale = _mm512_mask_blend_ps(
      __mmask16(0b11),
      _mm512_set_ps(-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0.5f, 1, 0.5f, 0, 0),
      _mm512_mask_blend_ps(__mmask16(0b10), _mm512_set1_ps(g.A), _mm512_set1_ps(g.C)));
  const __m512 cross = _mm512_maskz_mov_ps(__mmask16(0b11), _mm512_set1_ps(g.B));
  const __m512 out = _mm512_fnmsub_ps(scale, sums, _mm512_mul_ps(cross, swapped));
  _mm512_mask_storeu_ps(entry, __mmask16((1u << kEntryGrads) - 1), out);
}
#elif defined(__AVX2__) && defined(__FMA__)
// The AVX-512 tree above on 8-float vectors: each row's 16 lanes are added
// in the same pairs (lane l with l + 8, then l + 4, l + 2, l + 1), so both
// builds round alike. GCC's in-order sums of the portable loop were a sixth
// of the tile loop's time on AVX2.
//
// Lane j: the sum of row j of rows[0..7] (null: a row of zeros).
inline __m256 lane_sums_of_rows(const float* const (&rows)[8]) {
  __m256 v[8];
  for (int j = 0; j < 8; ++j)
    v[j] = rows[j] ? _mm256_add_ps(_mm256_load_ps(rows[j]), _mm256_load_ps(rows[j] + 8))
                   : _mm256_setzero_ps();
  // Rows j and j + 4 share a vector: their 4 partial sums in each half.
  __m256 pair[4];
  for (int j = 0; j < 4; ++j)
    pair[j] = _mm256_add_ps(_mm256_permute2f128_ps(v[j], v[j + 4], 0x20),
                            _mm256_permute2f128_ps(v[j], v[j + 4], 0x31));
  // 2 partial sums of rows 2j and 2j + 1 in the low half, of 2j + 4 and 2j + 5
  // in the high.
  __m256 quad[2];
  for (int j = 0; j < 2; ++j)
    quad[j] =
        _mm256_add_ps(_mm256_shuffle_ps(pair[2 * j], pair[2 * j + 1], _MM_SHUFFLE(1, 0, 1, 0)),
                      _mm256_shuffle_ps(pair[2 * j], pair[2 * j + 1], _MM_SHUFFLE(3, 2, 3, 2)));
  return _mm256_add_ps(_mm256_shuffle_ps(quad[0], quad[1], _MM_SHUFFLE(2, 0, 2, 0)),
                       _mm256_shuffle_ps(quad[0], quad[1], _MM_SHUFFLE(3, 1, 3, 1)));
}

// -(scale * sums + cross * (sums with lanes 0 and 1 swapped, 2 and 3, ...)),
// as store_entry computes it with AVX-512.
inline __m256 finish_sums(__m256 sums, __m256 scale, __m256 cross) {
  const __m256 swapped = _mm256_permute_ps(sums, _MM_SHUFFLE(2, 3, 0, 1));
  return _mm256_fnmsub_ps(scale, sums, _mm256_mul_ps(cross, swapped));
}

inline void write_entry_avx2(const float (&acc)[kEntryGrads][kLanes], const SplatRecord& g,
                             float* entry) {
  static_assert(kLanes == 16 && kEntryGrads == 11);
  const float* const low[8] = {acc[0], acc[1], acc[2], acc[3], acc[4], acc[5], acc[6], acc[7]};
  const float* const high[8] = {acc[8], acc[9], acc[10]};
  // Lanes 0-4 are the moments (see to_mean_conic_gradients), the rest plain sums.
  const __m256 out_low =
      finish_sums(lane_sums_of_rows(low), _mm256_setr_ps(g.A, g.C, 0.5f, 1, 0.5f, -1, -1, -1),
                  _mm256_setr_ps(g.B, g.B, 0, 0, 0, 0, 0, 0));
  const __m256 out_high =
      finish_sums(lane_sums_of_rows(high), _mm256_set1_ps(-1), _mm256_setzero_ps());
  // The last 3 as 2 + 1 plain stores: masked stores are microcoded on some
  // AMD CPUs.
  const __m128 last = _mm256_castps256_ps128(out_high);
  _mm256_storeu_ps(entry, out_low);
  _mm_storel_pi(reinterpret_cast<__m64*>(entry + 8), last);
  _mm_store_ss(entry + 10, _mm_movehl_ps(last, last));
}
#endif

// The entry's gradient: its lanes' sums, the moments turned into the mean
// and conic gradients.
inline void write_entry(const float (&acc)[kEntryGrads][kLanes], const SplatRecord& g,
                        float* entry) {
#if defined(__AVX512F__)
  store_entry(lane_sums(acc), g, entry);
#elif defined(__AVX2__) && defined(__FMA__)
  write_entry_avx2(acc, g, entry);
#else
  for (int j = 0; j < kEntryGrads; ++j) {
    float sum = 0.f;
    for (int l = 0; l < kLanes; ++l) sum += acc[j][l];
    entry[j] = sum;
  }
  to_mean_conic_gradients(g, entry);
#endif
}

#if defined(__AVX2__) && defined(__FMA__)
// An entry's sums over the blocks it reaches, one register of lanes each,
// in registers (acc's rows but depth).
struct LaneSums {
  RegisterLanes::F x, y, xx, xy, yy, red, green, blue, opacity, instance_opacity;
};

// sum + value, or value for the first block (kFirst).
template <bool kFirst>
inline RegisterLanes::F add_sum(RegisterLanes::F sum, RegisterLanes::F value) {
  if constexpr (kFirst) return value;
  return RegisterLanes::add(sum, value);
}
// sum + a b, fused as GCC fuses the lane loop's `sum += a * b`; a b first.
template <bool kFirst>
inline RegisterLanes::F add_product(RegisterLanes::F sum, RegisterLanes::F a, RegisterLanes::F b) {
  if constexpr (kFirst) return RegisterLanes::mul(a, b);
  return RegisterLanes::fmadd(a, b, sum);
}

// back_block<kColor, kInstance, no alpha or depth terms> on lanes h .. h +
// kWidth - 1 of one block, the sums in registers and the conditions as
// masks: the same operations where they round, fused alike, as GCC compiles
// the lane loop, so the same bits but for the sign of zeros: dL/dalpha
// starts as its colour term (the lane loop adds it to +0) and is zeroed by
// a mask (the lane loop multiplies it by 0, which makes -0 of a negative
// one), two instructions fewer. -0 and +0 are the same to every step after
// the rasterizer (the trained models are the same to the byte).
template <bool kInstance, bool kFirst>
inline void back_lanes(const SplatRecord& gs, int32_t position, float px0, float py0, int block,
                       int h, const float* g_plane, float op_star_geometry, TileBackState& s,
                       LaneSums& sum) {
  using V = RegisterLanes;
  using F = V::F;
  using M = V::M;
  const F zero = V::zero(), one = V::set1(1.f);
  const F dx = V::sub(V::set1(gs.mx - px0), V::load(kLaneOffsets.x + h));
  const F dy = V::sub(V::set1(gs.my - py0), V::load(kLaneOffsets.y + h));
  const F op = V::set1(gs.opacity);
  const F power = gaussian_power_lanes<V>(gs.A, gs.B, gs.C, dx, dy);
  const F G = fast_exp_lanes<V>(V::min(power, zero));
  const F raw_alpha = V::mul(op, G);
  const F alpha = V::min(raw_alpha, V::set1(kMaxAlpha));
  const M valid =
      V::both(V::greater(V::load(s.last[block] + h), V::set1(position)),
              V::both(V::less_equal(power, zero), V::greater_equal(alpha, V::set1(kMinAlpha))));
  const F inv_one_minus = V::div(one, V::sub(one, alpha));
  float* T = s.T[block] + h;
  const F T_after = V::load(T);
  const F T_i = V::select(valid, V::mul(T_after, inv_one_minus), T_after);
  const F w = V::zero_unless(valid, V::mul(alpha, T_i));
  const F g_red = V::load(s.g_color[0][block] + h);
  const F g_green = V::load(s.g_color[1][block] + h);
  const F g_blue = V::load(s.g_color[2][block] + h);
  // g_c = (g_red r + g_green g) + g_blue b, fused as GCC contracts it: the
  // first product into the first sum, the last into the second.
  F g_c = V::mul(g_green, V::set1(gs.g));
  g_c = V::fmadd(g_red, V::set1(gs.r), g_c);
  g_c = V::fmadd(g_blue, V::set1(gs.b), g_c);
  float* behind = s.behind_color[block] + h;
  const F behind_before = V::load(behind);
  F g_alpha = V::fmsub(g_c, T_i, V::mul(behind_before, inv_one_minus));
  sum.red = add_product<kFirst>(sum.red, g_red, w);
  sum.green = add_product<kFirst>(sum.green, g_green, w);
  sum.blue = add_product<kFirst>(sum.blue, g_blue, w);
  V::store(behind, V::fmadd(w, g_c, behind_before));
  const M unclamped = V::less(raw_alpha, V::set1(kMaxAlpha));
  g_alpha = V::zero_unless(V::both(valid, unclamped), g_alpha);
  sum.opacity = add_product<kFirst>(sum.opacity, g_alpha, G);
  F g_G = V::mul(g_alpha, op);
  if constexpr (kInstance) {
    const M unclamped_star = V::less(V::mul(V::set1(gs.instance_opacity), G), V::set1(kMaxAlpha));
    const F g_star =
        V::mul(V::mul(V::ones_where(V::both(valid, unclamped_star)), V::loadu(g_plane + h)), T_i);
    sum.instance_opacity = add_product<kFirst>(sum.instance_opacity, g_star, G);
    // g_alpha op + g_star sigma*: GCC fuses the first product.
    g_G = V::fmadd(g_alpha, op, V::mul(g_star, V::set1(op_star_geometry)));
  }
  const F g_power = V::mul(g_G, G);
  const F g_dx = V::mul(g_power, dx), g_dy = V::mul(g_power, dy);
  sum.x = add_sum<kFirst>(sum.x, g_dx);
  sum.y = add_sum<kFirst>(sum.y, g_dy);
  sum.xx = add_product<kFirst>(sum.xx, g_dx, dx);
  sum.xy = add_product<kFirst>(sum.xy, g_dx, dy);
  sum.yy = add_product<kFirst>(sum.yy, g_dy, dy);
  V::store(T, T_i);
}

// back_blocks without alpha or depth terms (training's), a register of
// lanes of every block at a time (the whole block with AVX-512, one 8-lane
// half with AVX2) so that the entry's sums stay in registers: the lane loop
// loads and stores all eleven rows for every block and carries its
// conditions as float 0/1 values. Blocks in the same order, so the same
// sums.
template <bool kInstance>
inline void back_blocks_in_registers(const TileGaussians& tg, size_t k, unsigned reached,
                                     const float* g_planes, float instance_geometry,
                                     TileBackState& s, float (&acc)[kEntryGrads][kLanes]) {
  using V = RegisterLanes;
  const SplatRecord& gs = tg[k];
  const int first = __builtin_ctz(reached);
  const float op_star_geometry = instance_geometry * gs.instance_opacity;  // as back_block's
  auto plane = [&](int b) { return kInstance ? g_planes + b * kLanes : nullptr; };
  for (int h = 0; h < kLanes; h += V::kWidth) {
    LaneSums sum{};  // the first block sets every row
    back_lanes<kInstance, true>(gs, int32_t(k), s.block_cx0[first], s.block_cy0[first], first, h,
                                plane(first), op_star_geometry, s, sum);
    for (unsigned rest = reached & (reached - 1); rest; rest &= rest - 1) {
      const int b = __builtin_ctz(rest);
      back_lanes<kInstance, false>(gs, int32_t(k), s.block_cx0[b], s.block_cy0[b], b, h, plane(b),
                                   op_star_geometry, s, sum);
    }
    const auto store = [&](int row, V::F value) { V::store(acc[row] + h, value); };
    store(kSumX, sum.x), store(kSumY, sum.y), store(kSumXX, sum.xx), store(kSumXY, sum.xy);
    store(kSumYY, sum.yy), store(kRed, sum.red), store(kGreen, sum.green), store(kBlue, sum.blue);
    store(kOpacity, sum.opacity);
    store(kDepth, V::zero());
    store(kInstanceOpacity, kInstance ? sum.instance_opacity : V::zero());
  }
}
#endif

// Entry k's gradient terms over the blocks in `reached` (not empty) into
// acc: the first block sets them, the others add to them.
template <bool kColor, bool kInstance, bool kAlphaDepth>
inline void back_blocks(const TileGaussians& tg, size_t k, unsigned reached, const float* g_planes,
                        float instance_geometry, TileBackState& s,
                        float (&acc)[kEntryGrads][kLanes]) {
#if defined(__AVX2__) && defined(__FMA__)
  if constexpr (kColor && !kAlphaDepth)
    return back_blocks_in_registers<kInstance>(tg, k, reached, g_planes, instance_geometry, s, acc);
#endif
  auto plane = [&](int b) { return kInstance ? g_planes + b * kLanes : nullptr; };
  const int first = __builtin_ctz(reached);
  back_block<kColor, kInstance, kAlphaDepth, true>(tg, k, s.block_cx0[first], s.block_cy0[first],
                                                   first, plane(first), instance_geometry, s, acc);
  for (unsigned rest = reached & (reached - 1); rest; rest &= rest - 1) {
    const int b = __builtin_ctz(rest);
    back_block<kColor, kInstance, kAlphaDepth, false>(tg, k, s.block_cx0[b], s.block_cy0[b], b,
                                                      plane(b), instance_geometry, s, acc);
  }
}

// All blocks of one tile, Gaussians back to front; each Gaussian's gradient
// is summed over the blocks it reaches, then over lanes, once.
template <bool kColor, bool kInstance, bool kAlphaDepth>
void backward_tile(const TileGaussians& tg, const uint32_t* entries, TileBackState& s,
                   std::vector<float>& entry_grads) {
  int32_t last = 0;
  for (int b = 0; b < kBlocks; ++b) last = std::max(last, s.block_last[b]);
  // Entries behind every pixel's last contributor get no gradient.
  for (size_t k = size_t(last); k < tg.size(); ++k)
    std::fill_n(&entry_grads[size_t(entries[k]) * kEntryGrads], kEntryGrads, 0.f);
  for (int32_t k = last - 1; k >= 0; --k) {
    float* entry = &entry_grads[size_t(entries[k]) * kEntryGrads];
    // The blocks it reaches, among those with a pixel blended up to or past
    // it. About a fifth of a tile's entries reach none of its blocks' pixel
    // centres (their bounding box only grazes the tile): zeros, without the
    // lane sums.
    const unsigned reached = tg.block_mask[size_t(k)] & blocks_blended_past(s, k);
    if (reached == 0) {
      std::fill_n(entry, kEntryGrads, 0.f);
      continue;
    }
    alignas(64) float acc[kEntryGrads][kLanes];  // set by the first block
    // Only Gaussians whose label has a map pay for the instance terms (the
    // others' dL/dS is zero: they would add only zeros).
    if (kInstance && tg[k].plane >= 0) {
      const float* g_planes = &s.g_planes[size_t(tg[k].plane) * kBlocks * kLanes];
      const float instance_geometry = tg[k].plane >= s.first_geometry_plane ? 1.f : 0.f;
      back_blocks<kColor, true, kAlphaDepth>(tg, size_t(k), reached, g_planes, instance_geometry, s,
                                             acc);
    } else {
      back_blocks<kColor, false, kAlphaDepth>(tg, size_t(k), reached, nullptr, 0.f, s, acc);
    }
    write_entry(acc, tg[size_t(k)], entry);
  }
}

using TileFunction = void (*)(const TileGaussians&, const uint32_t*, TileBackState&,
                              std::vector<float>&);

TileFunction pick_tile_function(bool color, bool instance, bool alpha_depth) {
  static constexpr TileFunction table[8] = {
      backward_tile<false, false, false>, backward_tile<false, false, true>,
      backward_tile<false, true, false>,  backward_tile<false, true, true>,
      backward_tile<true, false, false>,  backward_tile<true, false, true>,
      backward_tile<true, true, false>,   backward_tile<true, true, true>};
  return table[(color ? 4 : 0) + (instance ? 2 : 0) + (alpha_depth ? 1 : 0)];
}

// dL/dS of the tile's pixels, for the planes its Gaussians draw on: a plane
// is read only by the Gaussians whose label maps to it, and most tiles show
// none of the few sampled objects. A plane at a time: across the planes, each
// pixel's load missed the cache anew.
void load_tile_planes(const TileGaussians& tg, const RasterState& st,
                      const RenderOutputGradients& grads, size_t planes, int tile_x0, int tile_y0,
                      TileBackState& s) {
  s.tile_planes.assign(planes, 0);
  for (size_t k = 0; k < tg.size(); ++k)
    if (tg[k].plane >= 0) s.tile_planes[size_t(tg[k].plane)] = 1;
  const size_t pixels = size_t(st.width) * st.height;
  for (size_t m = 0; m < planes; ++m) {
    if (!s.tile_planes[m]) continue;
    const float* plane = &grads.instance_maps[m * pixels];
    for (int b = 0; b < kBlocks; ++b) {
      const PixelBlock block = PixelBlock::in_tile(tile_x0, tile_y0, b);
      float* to = &s.g_planes[(m * kBlocks + b) * kLanes];
      for (int l = 0; l < kLanes; ++l)
        to[l] = block.inside(l, st.width, st.height) ? plane[block.pixel(l, st.width)] : 0.f;
    }
  }
}

// Copies one image row of a tile (`columns` pixels) into its blocks' lanes:
// pixel x of tile row r goes to block (r / 4) * 4 + x / 4, lane (r % 4) * 4
// + x % 4, so a whole row is four copies of 4 floats (a copy per pixel, with
// its index arithmetic, was most of loading a tile's state).
void row_into_blocks(const float* row, int r, int columns, float (&to)[kBlocks][kLanes]) {
  constexpr int kBlocksPerRow = kTileSize / kBlockSize;
  float* lanes = &to[(r / kBlockSize) * kBlocksPerRow][(r % kBlockSize) * kBlockSize];
  if (columns == kTileSize) {
    for (int bx = 0; bx < kBlocksPerRow; ++bx)
      std::copy_n(row + bx * kBlockSize, kBlockSize, lanes + bx * kLanes);
    return;
  }
  for (int x = 0; x < columns; ++x) lanes[(x / kBlockSize) * kLanes + x % kBlockSize] = row[x];
}

// Copies one plane's pixels of the tile (rows x columns from `from`, whose
// rows are `stride` values apart) into to[block][lane]; lanes off the image
// keep their value.
void scatter_tile_rows(const float* from, size_t stride, int rows, int columns,
                       float (&to)[kBlocks][kLanes]) {
  for (int r = 0; r < rows; ++r) row_into_blocks(from + r * stride, r, columns, to);
}

// The same for interleaved RGB (rows `stride` floats apart), each row split
// into its channels first.
void scatter_tile_color_rows(const float* from, size_t stride, int rows, int columns,
                             float (&to)[3][kBlocks][kLanes]) {
  for (int r = 0; r < rows; ++r) {
    alignas(64) float channel[3][kTileSize];
    const float* rgb = from + r * stride;
    for (int x = 0; x < columns; ++x)
      channel[0][x] = rgb[3 * x], channel[1][x] = rgb[3 * x + 1], channel[2][x] = rgb[3 * x + 2];
    for (int c = 0; c < 3; ++c) row_into_blocks(channel[c], r, columns, to[c]);
  }
}

// The state of tile t (top-left pixel tile_x0, tile_y0): the forward pass's
// transmittance and last contributors, the output gradients (zero off the
// image), and what lies behind the last contributor (the background).
void load_tile_state(const RenderSettings& settings, const RasterState& st,
                     const RenderOutputGradients& grads, bool color, size_t t, int tile_x0,
                     int tile_y0, TileBackState& s) {
  const float* T_final = &st.final_transmittance[t * kTilePixels];
  const uint32_t* last = &st.n_contrib[t * kTilePixels];
  for (int b = 0; b < kBlocks; ++b) {
    const PixelBlock block = PixelBlock::in_tile(tile_x0, tile_y0, b);
    s.block_cx0[b] = block.cx0(), s.block_cy0[b] = block.cy0();
    s.block_last[b] = 0;
    for (int l = 0; l < kLanes; ++l) {
      s.T[b][l] = s.T_final[b][l] = T_final[b * kLanes + l];
      s.last[b][l] = int32_t(last[b * kLanes + l]);
      s.block_last[b] = std::max(s.block_last[b], s.last[b][l]);
    }
  }
  // Image rows, not lanes one by one: a lane's test of lying on the image
  // and its scattered loads cost more than the copy.
  for (auto* plane :
       {&s.g_alpha, &s.g_depth, &s.behind_depth, &s.g_color[0], &s.g_color[1], &s.g_color[2]})
    std::fill_n(&(*plane)[0][0], kTilePixels, 0.f);
  const int W = st.width;
  const int rows = std::min(kTileSize, st.height - tile_y0),
            columns = std::min(kTileSize, W - tile_x0);
  const size_t first = size_t(tile_y0) * W + tile_x0;
  if (!grads.alpha.empty()) scatter_tile_rows(&grads.alpha[first], W, rows, columns, s.g_alpha);
  if (!grads.depth.empty()) scatter_tile_rows(&grads.depth[first], W, rows, columns, s.g_depth);
  if (color)
    scatter_tile_color_rows(&grads.color[3 * first], 3 * size_t(W), rows, columns, s.g_color);
  for (int b = 0; b < kBlocks; ++b)
    for (int l = 0; l < kLanes; ++l) {
      s.behind_color[b][l] = 0.f;
      for (int c = 0; c < 3; ++c)
        s.behind_color[b][l] += s.g_color[c][b][l] * s.T_final[b][l] * settings.background[c];
    }
}

// The rows of tiles [row_begin, row_end) whose entries' gradients are held at once.
struct TileRowBand {
  int row_begin, row_end;
};

// Whole tile rows, greedily, each band with at most max_entries entries
// unless one row alone has more.
std::vector<TileRowBand> plan_bands(const TileBins& bins, size_t max_entries) {
  std::vector<TileRowBand> bands;
  auto row_entries = [&](int row) {
    return size_t(bins.tile_start[size_t(row + 1) * bins.tiles_x] -
                  bins.tile_start[size_t(row) * bins.tiles_x]);
  };
  size_t held = 0;
  for (int row = 0; row < bins.tiles_y; ++row) {
    const size_t entries = row_entries(row);
    if (bands.empty() || held + entries > max_entries) {
      bands.push_back({row, row + 1});
      held = entries;
    } else {
      bands.back().row_end = row + 1;
      held += entries;
    }
  }
  return bands;
}

// Fills out with the visible Gaussians whose tile rectangle meets each band
// (counts: scratch). Most Gaussians meet one band, and fewer than half of all
// are visible late in training, when there are three bands: each band's
// passes visit its members alone, not every Gaussian.
void find_band_members(const ProjectedGaussians& p, const std::vector<TileRowBand>& bands,
                       int tiles_y, std::vector<uint32_t>& counts, BandMembers& out) {
  std::vector<int32_t> band_of_row(size_t(tiles_y), 0);
  for (size_t b = 0; b < bands.size(); ++b)
    for (int row = bands[b].row_begin; row < bands[b].row_end; ++row) band_of_row[row] = int32_t(b);
  const size_t n = p.size(), n_bands = bands.size();
  // Fixed chunks, so that the members come in index order whatever the threads.
  constexpr size_t kChunk = 8192;
  const size_t chunks = (n + kChunk - 1) / kChunk;
  // Calls visit(i, b) for each band b that visible Gaussian i of chunk c meets.
  auto for_each_member = [&](size_t c, auto&& visit) {
    for (size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
      if (!p.visible(i)) continue;
      const int32_t* r = &p.tile_rect[4 * i];
      for (int32_t b = band_of_row[r[1]]; b <= band_of_row[r[3] - 1]; ++b) visit(i, size_t(b));
    }
  };
  counts.assign(chunks * n_bands, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks, 1), [&](const auto& range) {
    for (size_t c = range.begin(); c < range.end(); ++c)
      for_each_member(c, [&](size_t, size_t b) { ++counts[c * n_bands + b]; });
  });
  // counts becomes each (chunk, band)'s first position in out.members.
  out.start.assign(n_bands + 1, 0);
  size_t at = 0;
  for (size_t b = 0; b < n_bands; ++b) {
    out.start[b] = at;
    for (size_t c = 0; c < chunks; ++c) {
      const uint32_t count = counts[c * n_bands + b];
      counts[c * n_bands + b] = uint32_t(at);
      at += count;
    }
  }
  out.start[n_bands] = at;
  out.members.resize(at);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks, 1), [&](const auto& range) {
    for (size_t c = range.begin(); c < range.end(); ++c)
      for_each_member(
          c, [&](size_t i, size_t b) { out.members[counts[c * n_bands + b]++] = uint32_t(i); });
  });
}

// Numbers the band's entries Gaussian by Gaussian (its members, in order),
// and each Gaussian's row by row: fills st.band_entries (by member) and
// st.band_index (by Gaussian, for the members); returns the entry count.
size_t number_band_entries(RasterState& st, TileRowBand band, std::span<const uint32_t> members) {
  const ProjectedGaussians& p = st.projected;
  const size_t n = members.size();
  st.band_entries.resize(n + 1);
  st.band_index.resize(p.size());
  st.band_entries[0] = 0;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 8192), [&](const auto& range) {
    for (size_t j = range.begin(); j < range.end(); ++j) {
      const int32_t* r = &p.tile_rect[4 * members[j]];
      const int32_t rows = std::min(r[3], band.row_end) - std::max(r[1], band.row_begin);
      st.band_entries[j + 1] = uint32_t(rows * (r[2] - r[0]));
    }
  });
  for (size_t j = 0; j < n; ++j) st.band_entries[j + 1] += st.band_entries[j];
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 8192), [&](const auto& range) {
    for (size_t j = range.begin(); j < range.end(); ++j) {
      const int32_t* r = &p.tile_rect[4 * members[j]];
      const int32_t width = r[2] - r[0], first_row = std::max(r[1], band.row_begin);
      st.band_index[members[j]] = {int32_t(st.band_entries[j]) - first_row * width - r[0], width};
    }
  });
  return st.band_entries[n];
}

// Gradients of every entry of the band's tiles, into st.entry_grads.
void backward_band(const RenderSettings& settings, const BackwardSettings& backward_settings,
                   RasterState& st, const RenderOutputGradients& grads, TileFunction tile_fn,
                   bool color, size_t planes, TileRowBand band) {
  const size_t tile_begin = size_t(band.row_begin) * st.bins.tiles_x,
               tile_end = size_t(band.row_end) * st.bins.tiles_x;
  // Scratch per thread, not per task: a task's buffers grew tile by tile
  // and were freed at its end, some hundred times a view.
  struct Scratch {
    TileGaussians tg;
    std::vector<uint32_t> entries;
    std::unique_ptr<TileBackState> s;
  };
  tbb::enumerable_thread_specific<Scratch> scratch;
  tbb::parallel_for(tbb::blocked_range<size_t>(tile_begin, tile_end, 1), [&](const auto& range) {
    auto& [tg, entries, s] = scratch.local();
    if (!s) {
      s = std::make_unique<TileBackState>();
      s->g_planes.assign(planes * kBlocks * kLanes, 0.f);
      s->first_geometry_plane = backward_settings.maps_without_geometry_gradient;
    }
    for (size_t t = range.begin(); t < range.end(); ++t) {
      const uint32_t lo = st.bins.tile_start[t], hi = st.bins.tile_start[t + 1];
      if (lo == hi) continue;  // no entries to write
      const int tx = int(t % st.bins.tiles_x), ty = int(t / st.bins.tiles_x);
      entries.resize(hi - lo);
      // The Gaussians come in depth order, so their indices are read at
      // random: prefetched ahead, as TileGaussians prefetches their records.
      constexpr uint32_t kAhead = 16;
      for (uint32_t k = lo; k < hi; ++k) {
        if (k + kAhead < hi) __builtin_prefetch(&st.band_index[st.bins.slot_gaussian[k + kAhead]]);
        const BandEntryIndex e = st.band_index[st.bins.slot_gaussian[k]];
        entries[k - lo] = uint32_t(e.base + ty * e.width + tx);
      }
      tg.gather(st, lo, hi);
      tg.use_blocks(st.slot_blocks.data() + lo);
      load_tile_state(settings, st, grads, color, t, tx * kTileSize, ty * kTileSize, *s);
      if (planes) load_tile_planes(tg, st, grads, planes, tx * kTileSize, ty * kTileSize, *s);
      tile_fn(tg, entries.data(), *s, st.entry_grads);
    }
  });
}

// sum[k] += value k of entries [first, last), in entry order (sum: zero
// unless `continued`). With AVX-512 an entry's 11 values are added at once:
// GCC's loop added them one or two at a time.
inline void add_entries(const float* entry_grads, uint32_t first, uint32_t last, bool continued,
                        std::array<float, 16>& sum) {
#if defined(__AVX512F__)
  constexpr __mmask16 kValues = (1u << kEntryGrads) - 1;
  // Loaded only when set: a load over several smaller stores waits for them.
  __m512 s = continued ? _mm512_load_ps(sum.data()) : _mm512_setzero_ps();
  for (uint32_t e = first; e < last; ++e)
    s = _mm512_add_ps(s, _mm512_maskz_loadu_ps(kValues, entry_grads + size_t(e) * kEntryGrads));
  _mm512_store_ps(sum.data(), s);
#else
  (void)continued;
  for (uint32_t e = first; e < last; ++e)
    for (int k = 0; k < kEntryGrads; ++k) sum[k] += entry_grads[size_t(e) * kEntryGrads + k];
#endif
}

// Adds each member's entries of the band, in entry order, to its sums; a
// Gaussian's sums start at zero in its first band (that of its first row).
void sum_band_entries(const RasterState& st, TileRowBand band, std::span<const uint32_t> members,
                      ProjectedGradients& out) {
  // Tasks of at least 64 members: early in training a few thousand members
  // have tens of entries each, and a grain of 4,096 left them to one thread.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, members.size(), 64), [&](const auto& range) {
    for (size_t j = range.begin(); j < range.end(); ++j) {
      const size_t i = members[j];
      const uint32_t first = st.band_entries[j], last = st.band_entries[j + 1];
      alignas(64) std::array<float, 16> sum{};
      const bool continued = st.projected.tile_rect[4 * i + 1] < band.row_begin;
      if (continued)
        sum = {out.mean2d[2 * i],    out.mean2d[2 * i + 1],  out.conic[3 * i],
               out.conic[3 * i + 1], out.conic[3 * i + 2],   out.color[3 * i],
               out.color[3 * i + 1], out.color[3 * i + 2],   out.depth[i],
               out.opacity[i],       out.instance_opacity[i]};
      add_entries(st.entry_grads.data(), first, last, continued, sum);
      out.mean2d[2 * i] = sum[kMeanX];
      out.mean2d[2 * i + 1] = sum[kMeanY];
      out.conic[3 * i] = sum[kConicA];
      out.conic[3 * i + 1] = sum[kConicB];
      out.conic[3 * i + 2] = sum[kConicC];
      out.color[3 * i] = sum[kRed];
      out.color[3 * i + 1] = sum[kGreen];
      out.color[3 * i + 2] = sum[kBlue];
      out.depth[i] = sum[kDepth];
      out.opacity[i] = sum[kOpacity];
      out.instance_opacity[i] = sum[kInstanceOpacity];
    }
  });
}

}  // namespace

void rasterize_backward(const RenderSettings& settings, const BackwardSettings& backward_settings,
                        RasterState& st, const RenderOutputGradients& grads,
                        ProjectedGradients& out) {
  const size_t pixels = size_t(st.width) * st.height;
  const size_t planes = pixels ? grads.instance_maps.size() / pixels : 0;
  const bool color = settings.color && !grads.color.empty();
  const bool instance = planes > 0;
  const bool alpha_depth = !grads.alpha.empty() || !grads.depth.empty();
  const TileFunction tile_fn = pick_tile_function(color, instance, alpha_depth);
  const size_t n = st.projected.size();
  const size_t max_entries = st.max_band_entries
                                 ? st.max_band_entries
                                 : std::max(kBandEntriesPerGaussian * n, kMinBandEntries);
  out.resize(n);
  const std::vector<TileRowBand> bands = plan_bands(st.bins, max_entries);
  find_band_members(st.projected, bands, st.bins.tiles_y, st.band_chunk_counts, st.band_members);
  // Band after band, each Gaussian's entries are added in tile order, the
  // same order whatever the banding or the thread count.
  for (size_t b = 0; b < bands.size(); ++b) {
    const std::span<const uint32_t> members(
        st.band_members.members.data() + st.band_members.start[b],
        st.band_members.start[b + 1] - st.band_members.start[b]);
    const size_t entries = number_band_entries(st, bands[b], members);
    // Every entry is written by the tile it belongs to: no zero fill needed,
    // and the buffer only grows (growing a vector zero-fills the new part,
    // which band after band of different sizes did every iteration).
    if (st.entry_grads.size() < entries * kEntryGrads) st.entry_grads.resize(entries * kEntryGrads);
    backward_band(settings, backward_settings, st, grads, tile_fn, color, planes, bands[b]);
    sum_band_entries(st, bands[b], members, out);
  }
}

}  // namespace splat
