#pragma once
// AVX-512 operations whose plain intrinsics trip GCC 12's -Wuninitialized
// (they pass _mm512_undefined_ps() as the merge source): the same
// instructions, written as their masked forms with every lane kept.

#if defined(__AVX512F__)
#include <immintrin.h>

namespace splat {

inline __m512 min16(__m512 a, __m512 b) { return _mm512_maskz_min_ps(__mmask16(0xffff), a, b); }
inline __m512 max16(__m512 a, __m512 b) { return _mm512_maskz_max_ps(__mmask16(0xffff), a, b); }
// a 2^floor(b), rounded once.
inline __m512 scalef16(__m512 a, __m512 b) {
  return _mm512_maskz_scalef_ps(__mmask16(0xffff), a, b);
}

}  // namespace splat
#endif
