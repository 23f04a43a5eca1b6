#include "splat/image_quality.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace splat {
namespace {

constexpr int kRadius = 5;  // 11x11 window
constexpr float kC1 = 0.01f * 0.01f, kC2 = 0.03f * 0.03f;

std::array<float, 2 * kRadius + 1> gaussian_window() {
  std::array<float, 2 * kRadius + 1> w{};
  float sum = 0;
  for (int i = -kRadius; i <= kRadius; ++i)
    sum += w[i + kRadius] = std::exp(-float(i * i) / (2 * 1.5f * 1.5f));
  for (float& v : w) v /= sum;
  return w;
}

// Separable 11x11 Gaussian filter of one plane with zero padding ("same"
// size). The window is symmetric, so this is also its own adjoint. The
// interior runs without bounds checks and the vertical pass runs along rows,
// so both vectorise.
void blur(const std::vector<float>& in, std::vector<float>& out, int W, int H) {
  static const auto w = gaussian_window();
  std::vector<float> tmp(in.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, H, 8), [&](const auto& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      const float* src = &in[size_t(y) * W];
      float* dst = &tmp[size_t(y) * W];
      for (int x = 0; x < W; ++x) {
        if (x >= kRadius && x < W - kRadius) {
          float s = 0;
          for (int k = 0; k <= 2 * kRadius; ++k) s += w[k] * src[x - kRadius + k];
          dst[x] = s;
        } else {
          float s = 0;
          for (int k = -kRadius; k <= kRadius; ++k)
            if (x + k >= 0 && x + k < W) s += w[k + kRadius] * src[x + k];
          dst[x] = s;
        }
      }
    }
  });
  out.assign(in.size(), 0.f);
  tbb::parallel_for(tbb::blocked_range<int>(0, H, 8), [&](const auto& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      float* dst = &out[size_t(y) * W];
      for (int k = -kRadius; k <= kRadius; ++k) {
        const int yy = y + k;
        if (yy < 0 || yy >= H) continue;
        const float wk = w[k + kRadius];
        const float* src = &tmp[size_t(yy) * W];
        for (int x = 0; x < W; ++x) dst[x] += wk * src[x];
      }
    }
  });
}

}  // namespace

double ssim_plane(const std::vector<float>& x, const std::vector<float>& y, int W, int H,
                  std::vector<float>* dx) {
  const size_t n = x.size();
  std::vector<float> xx(n), yy(n), xy(n);
  for (size_t i = 0; i < n; ++i) xx[i] = x[i] * x[i], yy[i] = y[i] * y[i], xy[i] = x[i] * y[i];
  std::vector<float> mx, my, exx, eyy, exy;
  blur(x, mx, W, H);
  blur(y, my, W, H);
  blur(xx, exx, W, H);
  blur(yy, eyy, W, H);
  blur(xy, exy, W, H);
  double sum = 0;
  std::vector<float> d_mu, d_exx, d_exy;
  if (dx) d_mu.resize(n), d_exx.resize(n), d_exy.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const double mux = mx[i], muy = my[i];
    const double sxx = exx[i] - mux * mux, syy = eyy[i] - muy * muy, sxy = exy[i] - mux * muy;
    const double A1 = 2 * mux * muy + kC1, A2 = 2 * sxy + kC2;
    const double B1 = mux * mux + muy * muy + kC1, B2 = sxx + syy + kC2;
    const double S = A1 * A2 / (B1 * B2);
    sum += S;
    if (dx) {
      // S as a function of (mu_x, E[x^2], E[xy]) with the y statistics fixed.
      d_mu[i] =
          float((2 * muy * A2 - 2 * muy * A1) / (B1 * B2) - S * (2 * mux / B1 - 2 * mux / B2));
      d_exx[i] = float(-S / B2);
      d_exy[i] = float(2 * A1 / (B1 * B2));
    }
  }
  if (dx) {
    std::vector<float> g_mu, g_exx, g_exy;
    blur(d_mu, g_mu, W, H);
    blur(d_exx, g_exx, W, H);
    blur(d_exy, g_exy, W, H);
    for (size_t i = 0; i < n; ++i) (*dx)[i] += g_mu[i] + 2 * x[i] * g_exx[i] + y[i] * g_exy[i];
  }
  return sum;
}

std::vector<float> rgb_channel(std::span<const float> rgb, int c) {
  std::vector<float> p(rgb.size() / 3);
  for (size_t i = 0; i < p.size(); ++i) p[i] = rgb[3 * i + c];
  return p;
}

double ssim(std::span<const float> a, std::span<const float> b, int width, int height) {
  double sum = 0;
  for (int c = 0; c < 3; ++c)
    sum += ssim_plane(rgb_channel(a, c), rgb_channel(b, c), width, height, nullptr);
  return sum / a.size();
}

double psnr(std::span<const float> a, std::span<const float> b) {
  double mse = 0;
  for (size_t i = 0; i < a.size(); ++i) mse += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
  mse /= a.size();
  return 10 * std::log10(1.0 / std::max(mse, 1e-20));
}

}  // namespace splat
