#pragma once
// exp(x) for x <= 0 in float, written without branches or calls so that the
// compiler vectorises the rasterizer's pixel loops (std::exp would not be,
// without -ffast-math). Cody-Waite range reduction and a degree-6 polynomial:
// relative error below 3e-7 on [-87, 0] (tested against std::exp); inputs
// below -87 give about 1e-38, far under any threshold of the renderer.

#include <cstdint>

#include "splat/render/simd_lanes.h"

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
// fast_exp of a register of lanes (splat/render/simd_lanes.h), operation for
// operation as GCC compiles the scalar form in the rasterizer's lane loops
// (with its products and sums fused as -ffp-contract=fast fuses them there),
// so that both give the same bits; 2^n is applied by V::times_two_to, which
// rounds p 2^n once (n >= -126 here). For the loops that keep their state in
// registers.
template <typename V>
inline typename V::F fast_exp_lanes(typename V::F x) {
  using F = typename V::F;
  x = V::max(x, V::set1(-87.0f));  // x < -87 ? -87 : x
  const F magic = V::set1(12582912.f);
  const F shifted = V::fmadd(x, V::set1(1.44269504088896341f), magic);
  const F n = V::sub(shifted, magic);
  F r = V::fnmadd(n, V::set1(0.693145751953125f), x);
  r = V::fnmadd(n, V::set1(1.428606765330187045e-06f), r);
  F p = V::set1(1.0f / 720.0f);
  p = V::fmadd(p, r, V::set1(1.0f / 120.0f));
  p = V::fmadd(p, r, V::set1(1.0f / 24.0f));
  p = V::fmadd(p, r, V::set1(1.0f / 6.0f));
  p = V::fmadd(p, r, V::set1(0.5f));
  p = V::fmadd(p, r, V::set1(1.0f));
  p = V::fmadd(p, r, V::set1(1.0f));
  return V::times_two_to(p, n, shifted);
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
