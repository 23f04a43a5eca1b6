#pragma once
// The exponent of a projected Gaussian at a pixel, shared by the forward and
// backward rasterizers so that both take the same side of every threshold.

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace splat {

// a * b + c, fused where the CPU has a fused multiply-add instruction.
// Written out because -ffp-contract=fast leaves the choice to the compiler
// wherever a sum has two products: GCC fused one or the other product of
// `power` depending on the surrounding loop, so two instantiations of the
// blend loop rounded differently, and a masks-only render did not equal the
// masks of a colour render bit for bit.
inline float multiply_add(float a, float b, float c) {
#if defined(__FP_FAST_FMAF)
  return __builtin_fmaf(a, b, c);
#else
  return a * b + c;  // no fused instruction, so nothing for the compiler to fuse
#endif
}

// -0.5 (A dx^2 + C dy^2) - B dx dy: the Gaussian's log falloff at offset
// (dx, dy) from its centre, for the conic (A, B, C).
inline float gaussian_power(float A, float B, float C, float dx, float dy) {
  const float quadratic = multiply_add(A * dx, dx, C * dy * dy);
  return multiply_add(-0.5f, quadratic, -(B * dx * dy));
}

#if defined(__AVX2__) && defined(__FMA__)
// gaussian_power of 8 lanes: the same products, fused alike.
inline __m256 gaussian_power8(float A, float B, float C, __m256 dx, __m256 dy) {
  const __m256 C_dy_dy = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(C), dy), dy);
  const __m256 quadratic = _mm256_fmadd_ps(_mm256_mul_ps(_mm256_set1_ps(A), dx), dx, C_dy_dy);
  const __m256 B_dx_dy = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(B), dx), dy);
  return _mm256_fmsub_ps(_mm256_set1_ps(-0.5f), quadratic, B_dx_dy);
}
#endif

#if defined(__AVX512F__)
// gaussian_power of 16 lanes, fused as GCC fuses the scalar form there.
inline __m512 gaussian_power16(float A, float B, float C, __m512 dx, __m512 dy) {
  const __m512 C_dy_dy = _mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(C), dy), dy);
  const __m512 quadratic = _mm512_fmadd_ps(_mm512_mul_ps(_mm512_set1_ps(A), dx), dx, C_dy_dy);
  const __m512 B_dx_dy = _mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(B), dx), dy);
  return _mm512_fmsub_ps(_mm512_set1_ps(-0.5f), quadratic, B_dx_dy);
}
#endif

}  // namespace splat
