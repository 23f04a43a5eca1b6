#pragma once
// The SH coefficients of a batch of Gaussians turned into vector lanes and
// back. The model keeps each Gaussian's 45 rest coefficients together
// (kShRestFloats), which suits the optimiser and the file formats; the colour
// and its backward compute the Gaussians of a batch in lanes, so they want
// coefficient j of every Gaussian of the batch together. With AVX-512 a batch
// is turned by 16 x 16 transposes in registers (48 loads and 192 shuffles a
// batch), with AVX2 by 8 x 8 ones (96 loads and 288 shuffles); a loop of
// scalar loads and stores does the same elsewhere (720 of each).

#include <cstddef>
#include <cstdint>
#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "splat/gaussians.h"
#include "splat/render/projection_view.h"

namespace splat {

static_assert(kProjectionBatch == 16, "a batch is one 16 x 16 transpose per 16 coefficients");

// rows[j][l]: rest coefficient j of the batch's Gaussian l. Rows 45 to 47
// pad the last transpose and are not used.
struct ShRestLanes {
  static constexpr int kRows = 48;
  alignas(64) float rows[kRows][kProjectionBatch];
};

#if defined(__AVX512F__)
namespace sh_lanes_detail {

// The shuffles in their zero-masked forms with every lane kept (the same
// instructions): the unmasked intrinsics trip GCC 12's -Wmaybe-uninitialized.
constexpr __mmask16 kAll16 = 0xffff;
constexpr __mmask8 kAll8 = 0xff;
inline __m512 unpacklo(__m512 a, __m512 b) { return _mm512_maskz_unpacklo_ps(kAll16, a, b); }
inline __m512 unpackhi(__m512 a, __m512 b) { return _mm512_maskz_unpackhi_ps(kAll16, a, b); }
inline __m512 unpacklo_pairs(__m512 a, __m512 b) {
  return _mm512_castpd_ps(
      _mm512_maskz_unpacklo_pd(kAll8, _mm512_castps_pd(a), _mm512_castps_pd(b)));
}
inline __m512 unpackhi_pairs(__m512 a, __m512 b) {
  return _mm512_castpd_ps(
      _mm512_maskz_unpackhi_pd(kAll8, _mm512_castps_pd(a), _mm512_castps_pd(b)));
}
template <int kImm>
inline __m512 shuffle_blocks(__m512 a, __m512 b) {
  return _mm512_maskz_shuffle_f32x4(kAll16, a, b, kImm);
}

// In place: r[i] lane j becomes the old r[j] lane i.
inline void transpose_16x16(__m512 r[16]) {
  __m512 t[16];
  for (int i = 0; i < 16; i += 2) {
    t[i] = unpacklo(r[i], r[i + 1]);
    t[i + 1] = unpackhi(r[i], r[i + 1]);
  }
  // Now 128-bit block q of r[4i + j] holds column 4q + j of rows 4i..4i+3.
  for (int i = 0; i < 16; i += 4) {
    r[i] = unpacklo_pairs(t[i], t[i + 2]);
    r[i + 1] = unpackhi_pairs(t[i], t[i + 2]);
    r[i + 2] = unpacklo_pairs(t[i + 1], t[i + 3]);
    r[i + 3] = unpackhi_pairs(t[i + 1], t[i + 3]);
  }
  // A 4 x 4 transpose of the 128-bit blocks of r[j], r[4 + j], r[8 + j], r[12 + j].
  for (int j = 0; j < 4; ++j) {
    // 0x88 takes blocks 0 and 2 of each operand, 0xdd blocks 1 and 3.
    const __m512 x0 = shuffle_blocks<0x88>(r[j], r[4 + j]);
    const __m512 x1 = shuffle_blocks<0xdd>(r[j], r[4 + j]);
    const __m512 y0 = shuffle_blocks<0x88>(r[8 + j], r[12 + j]);
    const __m512 y1 = shuffle_blocks<0xdd>(r[8 + j], r[12 + j]);
    t[j] = shuffle_blocks<0x88>(x0, y0);
    t[4 + j] = shuffle_blocks<0x88>(x1, y1);
    t[8 + j] = shuffle_blocks<0xdd>(x0, y0);
    t[12 + j] = shuffle_blocks<0xdd>(x1, y1);
  }
  // t[4q + j] is column 4q + j.
  for (int i = 0; i < 16; ++i) r[i] = t[i];
}

// The 16 coefficients from `first` of a row; the last block has 13.
inline __mmask16 block_mask(int first) {
  return first + 16 <= kShRestFloats ? __mmask16(0xffff) : __mmask16(0x1fff);
}

}  // namespace sh_lanes_detail
#elif defined(__AVX2__)
namespace sh_lanes_detail {

// In place: r[i] lane j becomes the old r[j] lane i.
inline void transpose_8x8(__m256 r[8]) {
  __m256 t[8];
  for (int i = 0; i < 8; i += 2) {
    t[i] = _mm256_unpacklo_ps(r[i], r[i + 1]);
    t[i + 1] = _mm256_unpackhi_ps(r[i], r[i + 1]);
  }
  // Now 128-bit half h of r[4i + j] holds columns 4h + j of rows 4i..4i+3.
  for (int i = 0; i < 8; i += 4) {
    r[i] = _mm256_shuffle_ps(t[i], t[i + 2], _MM_SHUFFLE(1, 0, 1, 0));
    r[i + 1] = _mm256_shuffle_ps(t[i], t[i + 2], _MM_SHUFFLE(3, 2, 3, 2));
    r[i + 2] = _mm256_shuffle_ps(t[i + 1], t[i + 3], _MM_SHUFFLE(1, 0, 1, 0));
    r[i + 3] = _mm256_shuffle_ps(t[i + 1], t[i + 3], _MM_SHUFFLE(3, 2, 3, 2));
  }
  for (int j = 0; j < 4; ++j) {
    t[j] = _mm256_permute2f128_ps(r[j], r[4 + j], 0x20);
    t[4 + j] = _mm256_permute2f128_ps(r[j], r[4 + j], 0x31);
  }
  for (int i = 0; i < 8; ++i) r[i] = t[i];
}

// The last block of a row has 5 of its 8 coefficients (40..44).
constexpr int kLastBlock = kShRestFloats / 8 * 8;
static_assert(kShRestFloats - kLastBlock == 5);

inline __m256 load_block(const float* row, int first) {
  if (first < kLastBlock) return _mm256_loadu_ps(row + first);
  return _mm256_maskload_ps(row + first, _mm256_setr_epi32(-1, -1, -1, -1, -1, 0, 0, 0));
}

// The last block's 5 as 4 + 1 plain stores: masked stores are microcoded on
// some AMD CPUs.
inline void store_block(__m256 values, float* row, int first) {
  if (first < kLastBlock) return _mm256_storeu_ps(row + first, values);
  _mm_storeu_ps(row + first, _mm256_castps256_ps128(values));
  _mm_store_ss(row + first + 4, _mm256_extractf128_ps(values, 1));
}

}  // namespace sh_lanes_detail
#endif

// rows[l]: the 45 rest coefficients of the batch's Gaussian l.
inline void load_sh_rest_lanes(const float* const rows[kProjectionBatch], ShRestLanes& out) {
#if defined(__AVX512F__)
  using namespace sh_lanes_detail;
  for (int first = 0; first < ShRestLanes::kRows; first += 16) {
    __m512 r[16];
    for (int l = 0; l < 16; ++l) r[l] = _mm512_maskz_loadu_ps(block_mask(first), rows[l] + first);
    transpose_16x16(r);
    for (int j = 0; j < 16; ++j) _mm512_store_ps(out.rows[first + j], r[j]);
  }
#elif defined(__AVX2__)
  using namespace sh_lanes_detail;
  for (int first = 0; first < ShRestLanes::kRows; first += 8)
    for (int lane = 0; lane < kProjectionBatch; lane += 8) {
      __m256 r[8];
      for (int l = 0; l < 8; ++l) r[l] = load_block(rows[lane + l], first);
      transpose_8x8(r);
      for (int j = 0; j < 8; ++j) _mm256_store_ps(&out.rows[first + j][lane], r[j]);
    }
#else
  for (int l = 0; l < kProjectionBatch; ++l)
    for (int j = 0; j < kShRestFloats; ++j) out.rows[j][l] = rows[l][j];
#endif
}

// Writes the 45 coefficients of each Gaussian l whose bit is set in `which`
// to rows[l]; the other rows are not touched.
inline void store_sh_rest_rows(const ShRestLanes& in, float* const rows[kProjectionBatch],
                               uint32_t which) {
#if defined(__AVX512F__)
  using namespace sh_lanes_detail;
  for (int first = 0; first < ShRestLanes::kRows; first += 16) {
    __m512 r[16];
    for (int j = 0; j < 16; ++j) r[j] = _mm512_load_ps(in.rows[first + j]);
    transpose_16x16(r);
    for (int l = 0; l < 16; ++l)
      if (which >> l & 1) _mm512_mask_storeu_ps(rows[l] + first, block_mask(first), r[l]);
  }
#elif defined(__AVX2__)
  using namespace sh_lanes_detail;
  for (int first = 0; first < ShRestLanes::kRows; first += 8)
    for (int lane = 0; lane < kProjectionBatch; lane += 8) {
      if ((which >> lane & 0xff) == 0) continue;
      __m256 r[8];
      for (int j = 0; j < 8; ++j) r[j] = _mm256_load_ps(&in.rows[first + j][lane]);
      transpose_8x8(r);
      for (int l = 0; l < 8; ++l)
        if (which >> (lane + l) & 1) store_block(r[l], rows[lane + l], first);
    }
#else
  for (int l = 0; l < kProjectionBatch; ++l)
    if (which >> l & 1)
      for (int j = 0; j < kShRestFloats; ++j) rows[l][j] = in.rows[j][l];
#endif
}

}  // namespace splat
