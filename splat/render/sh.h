#pragma once
// View-dependent colour from real spherical harmonics up to degree 3, with the
// constants and sign conventions of the reference 3DGS implementation:
// colour = sum_k basis_k(dir) * coeff_k + 0.5, clamped at 0.

namespace splat {

inline constexpr int kShCoeffs = 16;

namespace sh_constants {
inline constexpr float C0 = 0.28209479177387814f;
inline constexpr float C1 = 0.4886025119029199f;
inline constexpr float C2[5] = {1.0925484305920792f, -1.0925484305920792f, 0.31539156525252005f,
                                -1.0925484305920792f, 0.5462742152960396f};
inline constexpr float C3[7] = {-0.5900435899266435f, 2.890611442640554f,   -0.4570457994644658f,
                                0.3731763325901154f,  -0.4570457994644658f, 1.445305721320277f,
                                -0.5900435899266435f};
}  // namespace sh_constants

// The basis of degree `degree` at the unit direction (x, y, z): calls
// visit(k, basis_k, d basis_k / dx, d basis_k / dy, d basis_k / dz) for
// k = 0 .. (degree + 1)^2 - 1, in order, with k a constant.
// Written out and inline so that the values stay in registers: as an array
// on the stack, stored one by one and loaded back as vectors by the colour
// loops, they stalled every load (a vector load does not forward from
// several stores). The derivatives a caller ignores are never computed.
template <typename Visit>
inline void for_each_sh_basis(int degree, float x, float y, float z, Visit&& visit) {
  using namespace sh_constants;
  visit(0, C0, 0.f, 0.f, 0.f);
  if (degree < 1) return;
  visit(1, -C1 * y, 0.f, -C1, 0.f);
  visit(2, C1 * z, 0.f, 0.f, C1);
  visit(3, -C1 * x, -C1, 0.f, 0.f);
  if (degree < 2) return;
  const float xx = x * x, yy = y * y, zz = z * z, xy = x * y, yz = y * z, xz = x * z;
  visit(4, C2[0] * xy, C2[0] * y, C2[0] * x, 0.f);
  visit(5, C2[1] * yz, 0.f, C2[1] * z, C2[1] * y);
  visit(6, C2[2] * (2 * zz - xx - yy), -2 * C2[2] * x, -2 * C2[2] * y, 4 * C2[2] * z);
  visit(7, C2[3] * xz, C2[3] * z, 0.f, C2[3] * x);
  visit(8, C2[4] * (xx - yy), 2 * C2[4] * x, -2 * C2[4] * y, 0.f);
  if (degree < 3) return;
  visit(9, C3[0] * y * (3 * xx - yy), 6 * C3[0] * xy, C3[0] * (3 * xx - 3 * yy), 0.f);
  visit(10, C3[1] * xy * z, C3[1] * yz, C3[1] * xz, C3[1] * xy);
  visit(11, C3[2] * y * (4 * zz - xx - yy), -2 * C3[2] * xy, C3[2] * (4 * zz - xx - 3 * yy),
        8 * C3[2] * yz);
  visit(12, C3[3] * z * (2 * zz - 3 * xx - 3 * yy), -6 * C3[3] * xz, -6 * C3[3] * yz,
        C3[3] * (6 * zz - 3 * xx - 3 * yy));
  visit(13, C3[4] * x * (4 * zz - xx - yy), C3[4] * (4 * zz - 3 * xx - yy), -2 * C3[4] * xy,
        8 * C3[4] * xz);
  visit(14, C3[5] * z * (xx - yy), 2 * C3[5] * xz, -2 * C3[5] * yz, C3[5] * (xx - yy));
  visit(15, C3[6] * x * (xx - 3 * yy), C3[6] * (3 * xx - 3 * yy), -6 * C3[6] * xy, 0.f);
}

}  // namespace splat
