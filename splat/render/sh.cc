#include "splat/render/sh.h"

namespace splat {
namespace {
constexpr float C0 = 0.28209479177387814f;
constexpr float C1 = 0.4886025119029199f;
constexpr float C2[5] = {1.0925484305920792f, -1.0925484305920792f, 0.31539156525252005f,
                         -1.0925484305920792f, 0.5462742152960396f};
constexpr float C3[7] = {-0.5900435899266435f, 2.890611442640554f,   -0.4570457994644658f,
                         0.3731763325901154f,  -0.4570457994644658f, 1.445305721320277f,
                         -0.5900435899266435f};
}  // namespace

void sh_basis(int degree, float x, float y, float z, float b[kShCoeffs], float db[kShCoeffs][3]) {
  const int n = (degree + 1) * (degree + 1);
  for (int k = 0; k < kShCoeffs; ++k) {
    b[k] = 0;
    if (db) db[k][0] = db[k][1] = db[k][2] = 0;
  }
  b[0] = C0;
  if (n <= 1) return;
  b[1] = -C1 * y;
  b[2] = C1 * z;
  b[3] = -C1 * x;
  if (db) {
    db[1][1] = -C1;
    db[2][2] = C1;
    db[3][0] = -C1;
  }
  if (n <= 4) return;
  const float xx = x * x, yy = y * y, zz = z * z, xy = x * y, yz = y * z, xz = x * z;
  b[4] = C2[0] * xy;
  b[5] = C2[1] * yz;
  b[6] = C2[2] * (2 * zz - xx - yy);
  b[7] = C2[3] * xz;
  b[8] = C2[4] * (xx - yy);
  if (db) {
    db[4][0] = C2[0] * y, db[4][1] = C2[0] * x;
    db[5][1] = C2[1] * z, db[5][2] = C2[1] * y;
    db[6][0] = -2 * C2[2] * x, db[6][1] = -2 * C2[2] * y, db[6][2] = 4 * C2[2] * z;
    db[7][0] = C2[3] * z, db[7][2] = C2[3] * x;
    db[8][0] = 2 * C2[4] * x, db[8][1] = -2 * C2[4] * y;
  }
  if (n <= 9) return;
  b[9] = C3[0] * y * (3 * xx - yy);
  b[10] = C3[1] * xy * z;
  b[11] = C3[2] * y * (4 * zz - xx - yy);
  b[12] = C3[3] * z * (2 * zz - 3 * xx - 3 * yy);
  b[13] = C3[4] * x * (4 * zz - xx - yy);
  b[14] = C3[5] * z * (xx - yy);
  b[15] = C3[6] * x * (xx - 3 * yy);
  if (db) {
    db[9][0] = 6 * C3[0] * xy, db[9][1] = C3[0] * (3 * xx - 3 * yy);
    db[10][0] = C3[1] * yz, db[10][1] = C3[1] * xz, db[10][2] = C3[1] * xy;
    db[11][0] = -2 * C3[2] * xy, db[11][1] = C3[2] * (4 * zz - xx - 3 * yy),
    db[11][2] = 8 * C3[2] * yz;
    db[12][0] = -6 * C3[3] * xz, db[12][1] = -6 * C3[3] * yz,
    db[12][2] = C3[3] * (6 * zz - 3 * xx - 3 * yy);
    db[13][0] = C3[4] * (4 * zz - 3 * xx - yy), db[13][1] = -2 * C3[4] * xy,
    db[13][2] = 8 * C3[4] * xz;
    db[14][0] = 2 * C3[5] * xz, db[14][1] = -2 * C3[5] * yz, db[14][2] = C3[5] * (xx - yy);
    db[15][0] = C3[6] * (3 * xx - 3 * yy), db[15][1] = -6 * C3[6] * xy;
  }
}

}  // namespace splat
