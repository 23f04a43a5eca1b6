#pragma once
// exp(x) for x <= 0 in float, written without branches or calls so that the
// compiler vectorises the rasterizer's pixel loops (std::exp would not be,
// without -ffast-math). Cody-Waite range reduction and a degree-6 polynomial:
// relative error below 3e-7 on [-87, 0] (tested against std::exp); inputs
// below -87 give about 1e-38, far under any threshold of the renderer.

#include <cstdint>

#include "splat/render/avx512_ops.h"
#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

namespace splat {

inline float fast_exp(float x) {
  x = x < -87.0f ? -87.0f : x;
  // Round x / ln 2 to the nearest integer by adding and removing 1.5 * 2^23
  // (exact in float arithmetic, which the build never relaxes with
  // -ffast-math); unlike roundevenf, this vectorises.
  const float shifted = x * 1.44269504088896341f + 12582912.f;  // 1.5 * 2^23 + n
  const float n = shifted - 12582912.f;
  float r = x - n * 0.693145751953125f;   // ln 2, high part
  r = r - n * 1.428606765330187045e-06f;  // ln 2, low part
  float p = 1.0f / 720.0f;
  p = p * r + 1.0f / 120.0f;
  p = p * r + 1.0f / 24.0f;
  p = p * r + 1.0f / 6.0f;
  p = p * r + 0.5f;
  p = p * r + 1.0f;
  p = p * r + 1.0f;
  // 2^n, from shifted's bits (0x4B400000 + n): shifting them by 23 drops the
  // 0x4B400000 and leaves n as the exponent, without converting n to an integer.
  const uint32_t bits = (__builtin_bit_cast(uint32_t, shifted) << 23) + (127u << 23);
  return p * __builtin_bit_cast(float, bits);
}

#if defined(__AVX2__) && defined(__FMA__)
// fast_exp of 8 lanes, operation for operation as GCC compiles the scalar
// form in the rasterizer's lane loops (with its products and sums fused as
// -ffp-contract=fast fuses them there), so that both give the same bits. For
// the AVX2 loops that keep their state in registers.
inline __m256 fast_exp8(__m256 x) {
  x = _mm256_max_ps(x, _mm256_set1_ps(-87.0f));  // x < -87 ? -87 : x
  const __m256 magic = _mm256_set1_ps(12582912.f);
  const __m256 shifted = _mm256_fmadd_ps(x, _mm256_set1_ps(1.44269504088896341f), magic);
  const __m256 n = _mm256_sub_ps(shifted, magic);
  __m256 r = _mm256_fnmadd_ps(n, _mm256_set1_ps(0.693145751953125f), x);
  r = _mm256_fnmadd_ps(n, _mm256_set1_ps(1.428606765330187045e-06f), r);
  __m256 p = _mm256_set1_ps(1.0f / 720.0f);
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.0f / 120.0f));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.0f / 24.0f));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.0f / 6.0f));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(0.5f));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.0f));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.0f));
  const __m256i bits = _mm256_add_epi32(_mm256_slli_epi32(_mm256_castps_si256(shifted), 23),
                                        _mm256_set1_epi32(127 << 23));
  return _mm256_mul_ps(p, _mm256_castsi256_ps(bits));
}
#endif

#if defined(__AVX512F__)
// fast_exp of 16 lanes, the same operations as GCC's vectorised scalar form,
// but 2^n applied by one scale instruction instead of building its bits and
// multiplying: both round p 2^n once, so the same bits (n >= -126 here).
inline __m512 fast_exp16(__m512 x) {
  x = max16(x, _mm512_set1_ps(-87.0f));
  const __m512 magic = _mm512_set1_ps(12582912.f);
  const __m512 shifted = _mm512_fmadd_ps(x, _mm512_set1_ps(1.44269504088896341f), magic);
  const __m512 n = _mm512_sub_ps(shifted, magic);
  __m512 r = _mm512_fnmadd_ps(n, _mm512_set1_ps(0.693145751953125f), x);
  r = _mm512_fnmadd_ps(n, _mm512_set1_ps(1.428606765330187045e-06f), r);
  __m512 p = _mm512_set1_ps(1.0f / 720.0f);
  p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(1.0f / 120.0f));
  p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(1.0f / 24.0f));
  p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(1.0f / 6.0f));
  p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(0.5f));
  p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(1.0f));
  p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(1.0f));
  return scalef16(p, n);
}
#endif

// ln(x) for finite x > 0, likewise without branches or calls: x = m 2^e with
// m in [sqrt(1/2), sqrt(2)), ln m = 2 atanh(s) with s = (m - 1) / (m + 1),
// |s| < 0.172, by its series to s^7. Error below 1e-7 (1 + |ln x|), about
// a float ulp (tested).
inline float fast_log(float x) {
  const int32_t bits = __builtin_bit_cast(int32_t, x);
  int32_t e = ((bits >> 23) & 0xff) - 127;
  float m = __builtin_bit_cast(float, (bits & 0x7fffff) | 0x3f800000);  // in [1, 2)
  const bool high = m > 1.41421356f;
  m = high ? 0.5f * m : m;
  e = high ? e + 1 : e;
  const float s = (m - 1.f) / (m + 1.f), s2 = s * s;
  const float series = s * (2.f + s2 * (2.f / 3.f + s2 * (2.f / 5.f + s2 * (2.f / 7.f))));
  // ln 2 in two parts, as in fast_exp, so that e ln 2 rounds once.
  return float(e) * 0.693145751953125f + (float(e) * 1.428606765330187045e-06f + series);
}

}  // namespace splat
