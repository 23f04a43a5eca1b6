#pragma once
// The exponent of a projected Gaussian at a pixel, shared by the forward and
// backward rasterizers so that both take the same side of every threshold.

#include "splat/render/simd_lanes.h"

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
// gaussian_power of a register of lanes (splat/render/simd_lanes.h): the
// same products, fused alike.
template <typename V>
inline typename V::F gaussian_power_lanes(float A, float B, float C, typename V::F dx,
                                          typename V::F dy) {
  using F = typename V::F;
  const F C_dy_dy = V::mul(V::mul(V::set1(C), dy), dy);
  const F quadratic = V::fmadd(V::mul(V::set1(A), dx), dx, C_dy_dy);
  const F B_dx_dy = V::mul(V::mul(V::set1(B), dx), dy);
  return V::fmsub(V::set1(-0.5f), quadratic, B_dx_dy);
}
#endif

}  // namespace splat
