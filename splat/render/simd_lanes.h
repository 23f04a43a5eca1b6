#pragma once
// The vector operations the rasterizer's register loops are written in, for
// one register of pixel lanes: 16 with AVX-512, 8 with AVX2. Each loop is
// written once, as a template over these, and rounds as GCC compiles the
// portable lane loop (splat/render/rasterize_forward.cc, _backward.cc).
// Conditions are a mask type: a mask register with AVX-512, a vector of
// all-ones or zero lanes with AVX2.
//
// RegisterLanes names the set a build uses; it is not defined where the
// target has neither (the portable lane loops run alone there).

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>

#include <cstdint>

namespace splat {

#if defined(__AVX512F__)
struct Lanes16 {
  static constexpr int kWidth = 16;
  using F = __m512;
  using I = __m512i;
  using M = __mmask16;

  static F zero() { return _mm512_setzero_ps(); }
  static F set1(float v) { return _mm512_set1_ps(v); }
  static I set1(int32_t v) { return _mm512_set1_epi32(v); }
  static F load(const float* p) { return _mm512_load_ps(p); }
  static F loadu(const float* p) { return _mm512_loadu_ps(p); }
  static I load(const int32_t* p) { return _mm512_load_si512(p); }
  static void store(float* p, F v) { _mm512_store_ps(p, v); }
  static void storeu(float* p, F v) { _mm512_storeu_ps(p, v); }
  static void store(int32_t* p, I v) { _mm512_store_si512(p, v); }

  static F add(F a, F b) { return _mm512_add_ps(a, b); }
  static F sub(F a, F b) { return _mm512_sub_ps(a, b); }
  static F mul(F a, F b) { return _mm512_mul_ps(a, b); }
  static F div(F a, F b) { return _mm512_div_ps(a, b); }
  static F fmadd(F a, F b, F c) { return _mm512_fmadd_ps(a, b, c); }
  static F fmsub(F a, F b, F c) { return _mm512_fmsub_ps(a, b, c); }
  static F fnmadd(F a, F b, F c) { return _mm512_fnmadd_ps(a, b, c); }
  // The masked forms with every lane kept: the plain min, max and scalef
  // intrinsics trip GCC 12's -Wuninitialized (their merge source is
  // _mm512_undefined_ps()). The same instructions.
  static F min(F a, F b) { return _mm512_maskz_min_ps(M(0xffff), a, b); }
  static F max(F a, F b) { return _mm512_maskz_max_ps(M(0xffff), a, b); }
  // p 2^n for integral n (shifted: n + 1.5 * 2^23, as fast_exp rounds
  // it), rounded once.
  static F times_two_to(F p, F n, F) { return _mm512_maskz_scalef_ps(M(0xffff), p, n); }

  static M less(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
  static M less_equal(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_LE_OQ); }
  static M greater_equal(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_GE_OQ); }
  static M not_equal(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_NEQ_UQ); }
  static M greater(I a, I b) { return _mm512_cmpgt_epi32_mask(a, b); }
  static M both(M a, M b) { return M(a & b); }
  static M either(M a, M b) { return M(a | b); }
  static M and_not(M a, M b) { return M(b & ~a); }  // b and not a
  static bool all(M m) { return m == M(0xffff); }

  static F select(M m, F if_set, F otherwise) { return _mm512_mask_mov_ps(otherwise, m, if_set); }
  static I select(M m, I if_set, I otherwise) {
    return _mm512_mask_mov_epi32(otherwise, m, if_set);
  }
  static F zero_unless(M m, F v) { return _mm512_maskz_mov_ps(m, v); }
  static F ones_where(M m) { return _mm512_maskz_mov_ps(m, set1(1.f)); }
  static I count_where(M m, I count) { return _mm512_mask_sub_epi32(count, m, count, set1(-1)); }
};
using RegisterLanes = Lanes16;
#else
struct Lanes8 {
  static constexpr int kWidth = 8;
  using F = __m256;
  using I = __m256i;
  using M = __m256;  // all-ones or zero lanes

  static F zero() { return _mm256_setzero_ps(); }
  static F set1(float v) { return _mm256_set1_ps(v); }
  static I set1(int32_t v) { return _mm256_set1_epi32(v); }
  static F load(const float* p) { return _mm256_load_ps(p); }
  static F loadu(const float* p) { return _mm256_loadu_ps(p); }
  static I load(const int32_t* p) { return _mm256_load_si256(reinterpret_cast<const I*>(p)); }
  static void store(float* p, F v) { _mm256_store_ps(p, v); }
  static void storeu(float* p, F v) { _mm256_storeu_ps(p, v); }
  static void store(int32_t* p, I v) { _mm256_store_si256(reinterpret_cast<I*>(p), v); }

  static F add(F a, F b) { return _mm256_add_ps(a, b); }
  static F sub(F a, F b) { return _mm256_sub_ps(a, b); }
  static F mul(F a, F b) { return _mm256_mul_ps(a, b); }
  static F div(F a, F b) { return _mm256_div_ps(a, b); }
  static F fmadd(F a, F b, F c) { return _mm256_fmadd_ps(a, b, c); }
  static F fmsub(F a, F b, F c) { return _mm256_fmsub_ps(a, b, c); }
  static F fnmadd(F a, F b, F c) { return _mm256_fnmadd_ps(a, b, c); }
  static F min(F a, F b) { return _mm256_min_ps(a, b); }
  static F max(F a, F b) { return _mm256_max_ps(a, b); }
  // p 2^n from shifted's bits, as fast_exp builds it.
  static F times_two_to(F p, F, F shifted) {
    const I bits =
        _mm256_add_epi32(_mm256_slli_epi32(_mm256_castps_si256(shifted), 23), set1(127 << 23));
    return _mm256_mul_ps(p, _mm256_castsi256_ps(bits));
  }

  static M less(F a, F b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
  static M less_equal(F a, F b) { return _mm256_cmp_ps(a, b, _CMP_LE_OQ); }
  static M greater_equal(F a, F b) { return _mm256_cmp_ps(a, b, _CMP_GE_OQ); }
  static M not_equal(F a, F b) { return _mm256_cmp_ps(a, b, _CMP_NEQ_UQ); }
  static M greater(I a, I b) { return _mm256_castsi256_ps(_mm256_cmpgt_epi32(a, b)); }
  static M both(M a, M b) { return _mm256_and_ps(a, b); }
  static M either(M a, M b) { return _mm256_or_ps(a, b); }
  static M and_not(M a, M b) { return _mm256_andnot_ps(a, b); }  // b and not a
  static bool all(M m) { return _mm256_movemask_ps(m) == 0xff; }

  static F select(M m, F if_set, F otherwise) { return _mm256_blendv_ps(otherwise, if_set, m); }
  static I select(M m, I if_set, I otherwise) {
    return _mm256_blendv_epi8(otherwise, if_set, _mm256_castps_si256(m));
  }
  static F zero_unless(M m, F v) { return _mm256_and_ps(m, v); }
  static F ones_where(M m) { return _mm256_and_ps(m, set1(1.f)); }
  // A set lane is -1 as an integer.
  static I count_where(M m, I count) { return _mm256_sub_epi32(count, _mm256_castps_si256(m)); }
};
using RegisterLanes = Lanes8;
#endif

}  // namespace splat
#endif
