#pragma once
// exp(x) for x <= 0 in float, written without branches or calls so that the
// compiler vectorises the rasterizer's pixel loops (std::exp would not be,
// without -ffast-math). Cody-Waite range reduction and a degree-6 polynomial:
// relative error below 3e-7 on [-87, 0] (tested against std::exp); inputs
// below -87 give about 1e-38, far under any threshold of the renderer.

#include <cstdint>
#include <cstring>

namespace splat {

inline float fast_exp(float x) {
  x = x < -87.0f ? -87.0f : x;
  const float n = __builtin_roundevenf(x * 1.44269504088896341f);  // x / ln 2
  float r = x - n * 0.693145751953125f;                         // ln 2, high part
  r = r - n * 1.428606765330187045e-06f;                        // ln 2, low part
  float p = 1.0f / 720.0f;
  p = p * r + 1.0f / 120.0f;
  p = p * r + 1.0f / 24.0f;
  p = p * r + 1.0f / 6.0f;
  p = p * r + 0.5f;
  p = p * r + 1.0f;
  p = p * r + 1.0f;
  const int32_t bits = (int32_t(n) + 127) << 23;  // 2^n
  float scale;
  std::memcpy(&scale, &bits, sizeof(scale));
  return p * scale;
}

}  // namespace splat
