#include "splat/train/image_loss.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace splat {
namespace {

constexpr int kRadius = 5;  // 11x11 window, sigma 1.5
constexpr float kC1 = 0.01f * 0.01f, kC2 = 0.03f * 0.03f;
// Rows are processed in bands of this many, in parallel; each band's sum is
// kept apart and the bands are added in order, so the result is the same
// whatever the number of threads.
constexpr int kBandRows = 8;
constexpr int kLanes = 16;  // partial sums kept apart (one AVX-512 register of floats)

using Window = std::array<float, 2 * kRadius + 1>;

Window gaussian_window() {
  Window w{};
  float sum = 0;
  for (int i = -kRadius; i <= kRadius; ++i)
    sum += w[i + kRadius] = std::exp(-float(i * i) / (2 * 1.5f * 1.5f));
  for (float& v : w) v /= sum;
  return w;
}

int bands_of(int H) { return (H + kBandRows - 1) / kBandRows; }

template <typename Body>
void for_each_band(int H, const Body& body) {
  tbb::parallel_for(tbb::blocked_range<int>(0, bands_of(H)), [&](const auto& r) {
    for (int b = r.begin(); b < r.end(); ++b)
      body(b, b * kBandRows, std::min(H, (b + 1) * kBandRows));
  });
}

// One row of the horizontal pass (zero padding): out[x] = sum_k w[k] in[x+k].
// Taps are added in the same order at every pixel; the interior runs as
// whole-row multiply-adds, which vectorise.
void blur_row(const Window& w, const float* in, float* out, int W) {
  const int lo = std::min(kRadius, W), hi = std::max(lo, W - kRadius);
  // The interior as whole-row multiply-adds, one tap at a time (the row
  // stays in the L1 cache; this form vectorises cleanly, while summing the
  // taps per pixel made GCC shuffle lanes); each pixel adds its taps in the
  // same order as the borders below.
  for (int x = lo; x < hi; ++x) out[x] = 0;
  for (int k = 0; k <= 2 * kRadius; ++k) {
    const float wk = w[k];
    for (int x = lo; x < hi; ++x) out[x] += wk * in[x + k - kRadius];
  }
  const auto border = [&](int b) {
    float s = 0;
    for (int k = -kRadius; k <= kRadius; ++k)
      if (b + k >= 0 && b + k < W) s += w[k + kRadius] * in[b + k];
    out[b] = s;
  };
  for (int b = 0; b < lo; ++b) border(b);
  for (int b = hi; b < W; ++b) border(b);
}

// One row of the vertical pass over a horizontally blurred plane.
void blur_column_row(const Window& w, const std::vector<float>& in, int y, float* out, int W,
                     int H) {
  for (int x = 0; x < W; ++x) out[x] = 0;
  for (int k = -kRadius; k <= kRadius; ++k) {
    const int yy = y + k;
    if (yy < 0 || yy >= H) continue;
    const float wk = w[k + kRadius];
    const float* src = &in[size_t(yy) * W];
    for (int x = 0; x < W; ++x) out[x] += wk * src[x];
  }
}

// The horizontal pass of x, y, x^2, y^2 and xy of one channel.
void blur_statistics_horizontally(const Window& w, ImageLossBuffers& b, int W, int H) {
  for_each_band(H, [&](int, int y0, int y1) {
    std::vector<float> row(W);
    for (int y = y0; y < y1; ++y) {
      const size_t o = size_t(y) * W;
      const float *x = &b.x[o], *t = &b.y[o];
      blur_row(w, x, &b.blurred[0][o], W);
      blur_row(w, t, &b.blurred[1][o], W);
      for (int i = 0; i < W; ++i) row[i] = x[i] * x[i];
      blur_row(w, row.data(), &b.blurred[2][o], W);
      for (int i = 0; i < W; ++i) row[i] = t[i] * t[i];
      blur_row(w, row.data(), &b.blurred[3][o], W);
      for (int i = 0; i < W; ++i) row[i] = x[i] * t[i];
      blur_row(w, row.data(), &b.blurred[4][o], W);
    }
  });
}

// The SSIM map of one row from its five blurred statistics (rows of W in
// `stats`) and, with kGradient, its derivatives with respect to the
// render's statistics. Returns the row's sum. In float, as the reference
// computes SSIM (float32 tensors); one partial sum per vector lane, since a
// single running sum would chain every pixel to the one before and keep the
// loop from vectorising.
template <bool kGradient>
double ssim_row(const float* stats, int W, float* d_mu, float* d_exx, float* d_exy) {
  const float *mx = stats, *my = stats + W, *exx = stats + 2 * W, *eyy = stats + 3 * W,
              *exy = stats + 4 * W;
  float lane_sums[kLanes] = {};
  const auto pixel = [&](int i, int lane) {
    const float mux = mx[i], muy = my[i];
    const float sxx = exx[i] - mux * mux, syy = eyy[i] - muy * muy, sxy = exy[i] - mux * muy;
    const float A1 = 2 * mux * muy + kC1, A2 = 2 * sxy + kC2;
    const float B1 = mux * mux + muy * muy + kC1, B2 = sxx + syy + kC2;
    const float inv_B = 1 / (B1 * B2);
    const float S = A1 * A2 * inv_B;
    lane_sums[lane] += S;
    if constexpr (kGradient) {
      // S as a function of (mu_x, E[x^2], E[xy]) with the y statistics fixed.
      d_mu[i] = (2 * muy * A2 - 2 * muy * A1) * inv_B - S * (2 * mux / B1 - 2 * mux / B2);
      d_exx[i] = -S / B2;
      d_exy[i] = 2 * A1 * inv_B;
    }
  };
  int i = 0;
  for (; i + kLanes <= W; i += kLanes)
    for (int l = 0; l < kLanes; ++l) pixel(i + l, l);
  for (; i < W; ++i) pixel(i, 0);
  double sum = 0;
  for (float lane : lane_sums) sum += lane;
  return sum;
}

// The vertical pass, then the SSIM map and, with `gradient`, its derivatives
// (b.d_stats). Returns the map's sum.
double ssim_from_statistics(const Window& w, ImageLossBuffers& b, int W, int H, bool gradient) {
  for_each_band(H, [&](int band, int y0, int y1) {
    std::vector<float> stats(5 * size_t(W));
    double sum = 0;
    for (int y = y0; y < y1; ++y) {
      for (int q = 0; q < 5; ++q) blur_column_row(w, b.blurred[q], y, &stats[q * size_t(W)], W, H);
      const size_t o = size_t(y) * W;
      sum += gradient ? ssim_row<true>(stats.data(), W, &b.d_stats[0][o], &b.d_stats[1][o],
                                       &b.d_stats[2][o])
                      : ssim_row<false>(stats.data(), W, nullptr, nullptr, nullptr);
    }
    b.band_sums[band] = sum;
  });
  double sum = 0;
  for (int band = 0; band < bands_of(H); ++band) sum += b.band_sums[band];
  return sum;
}

// Adds scale * d(SSIM map sum)/dx to channel c of grad: the window is
// symmetric, so the adjoint of the blur is the blur itself.
void add_ssim_gradient(const Window& w, ImageLossBuffers& b, int W, int H, int c, float scale,
                       std::vector<float>& grad) {
  for_each_band(H, [&](int, int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int q = 0; q < 3; ++q) {
        const size_t o = size_t(y) * W;
        blur_row(w, &b.d_stats[q][o], &b.blurred[q][o], W);
      }
  });
  for_each_band(H, [&](int, int y0, int y1) {
    std::vector<float> g(3 * size_t(W));
    for (int y = y0; y < y1; ++y) {
      for (int q = 0; q < 3; ++q) blur_column_row(w, b.blurred[q], y, &g[q * size_t(W)], W, H);
      const size_t o = size_t(y) * W;
      for (int i = 0; i < W; ++i) {
        const float d = g[i] + 2 * b.x[o + i] * g[W + i] + b.y[o + i] * g[2 * W + i];
        grad[3 * (o + i) + c] += scale * d;
      }
    }
  });
}

// The sums of absolute and squared differences and, with grad, the L1's
// gradient (which starts grad).
std::pair<double, double> difference_sums(std::span<const float> rendered, const ImageRGB& target,
                                          float g, std::vector<float>* grad, ImageLossBuffers& b) {
  const int W = target.width, H = target.height;
  if (grad) grad->resize(rendered.size());
  const float* x = rendered.data();
  const float* t = target.data.data();
  float* dx = grad ? grad->data() : nullptr;
  for_each_band(H, [&](int band, int y0, int y1) {
    // Partial sums per lane, as in ssim_from_statistics; the sign as the
    // difference of two comparisons keeps the loop free of branches.
    double abs_sums[kLanes] = {}, square_sums[kLanes] = {};
    const auto element = [&](size_t i, int lane) {
      const double e = double(x[i]) - t[i];
      abs_sums[lane] += std::abs(e);
      square_sums[lane] += e * e;
      const float d = x[i] - t[i];
      if (dx) dx[i] = g * (float(d > 0) - float(d < 0));  // torch's sign(0) = 0
    };
    const size_t end = size_t(y1) * W * 3;
    size_t i = size_t(y0) * W * 3;
    for (; i + kLanes <= end; i += kLanes)
      for (int l = 0; l < kLanes; ++l) element(i + l, l);
    for (; i < end; ++i) element(i, 0);
    double abs_sum = 0, square_sum = 0;
    for (int l = 0; l < kLanes; ++l) abs_sum += abs_sums[l], square_sum += square_sums[l];
    b.band_sums[band] = abs_sum;
    b.band_sums[bands_of(H) + band] = square_sum;
  });
  double abs_sum = 0, square_sum = 0;
  for (int band = 0; band < bands_of(H); ++band)
    abs_sum += b.band_sums[band], square_sum += b.band_sums[bands_of(H) + band];
  return {abs_sum, square_sum};
}

void prepare(ImageLossBuffers& b, int W, int H, bool gradient) {
  const size_t n = size_t(W) * H;
  for (auto* v :
       {&b.x, &b.y, &b.blurred[0], &b.blurred[1], &b.blurred[2], &b.blurred[3], &b.blurred[4]})
    v->resize(n);
  for (auto& d : b.d_stats) d.resize(gradient ? n : 0);
  b.band_sums.resize(2 * bands_of(H));
}

}  // namespace

ImageLoss image_loss(std::span<const float> rendered, const ImageRGB& target,
                     const ImageLossOptions& options, std::vector<float>* grad,
                     ImageLossBuffers* buffers) {
  static const Window w = gaussian_window();  // a constant, computed once
  ImageLossBuffers local;
  ImageLossBuffers& b = buffers ? *buffers : local;
  const int W = target.width, H = target.height;
  const size_t n = target.data.size();
  prepare(b, W, H, grad != nullptr);
  ImageLoss loss;
  const auto [abs_sum, square_sum] =
      difference_sums(rendered, target, (1 - options.lambda_ssim) / float(n), grad, b);
  loss.l1 = abs_sum / n;
  loss.mse = square_sum / n;
  double ssim_sum = 0;
  for (int c = 0; c < 3; ++c) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, size_t(W) * H), [&](const auto& r) {
      for (size_t i = r.begin(); i < r.end(); ++i)
        b.x[i] = rendered[3 * i + c], b.y[i] = target.data[3 * i + c];
    });
    blur_statistics_horizontally(w, b, W, H);
    ssim_sum += ssim_from_statistics(w, b, W, H, grad != nullptr);
    // loss term lambda * (1 - mean SSIM): d/dx = -lambda / n * d(sum)/dx.
    if (grad) add_ssim_gradient(w, b, W, H, c, -options.lambda_ssim / float(n), *grad);
  }
  loss.ssim = ssim_sum / n;
  loss.total = (1 - options.lambda_ssim) * loss.l1 + options.lambda_ssim * (1 - loss.ssim);
  return loss;
}

}  // namespace splat
