#pragma once
// View-dependent colour from real spherical harmonics up to degree 3, with the
// constants and sign conventions of the reference 3DGS implementation:
// colour = sum_k basis_k(dir) * coeff_k + 0.5, clamped at 0.

#include <array>

namespace splat {

inline constexpr int kShCoeffs = 16;

// Basis values for a unit direction (x, y, z) (degree d uses the first
// (d+1)^2), and optionally their derivatives d basis_k / d dir. The
// direction comes in registers: callers have just computed it, and loading
// it back from their stores stalled (the loads spanned two stores).
void sh_basis(int degree, float x, float y, float z, float basis[kShCoeffs],
              float dbasis[kShCoeffs][3] = nullptr);

}  // namespace splat
