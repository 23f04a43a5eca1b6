#include "splat/train/image_loss.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <utility>

namespace splat {
namespace {

constexpr int kRadius = 5;   // 11x11 window, sigma 1.5
constexpr int kMargin = 16;  // zeros before a row's column 0: at least kRadius
static_assert(kMargin >= kRadius && kMargin % 16 == 0);
constexpr float kC1 = 0.01f * 0.01f, kC2 = 0.03f * 0.03f;
// Rows are processed in bands of this many, in parallel; each band's sum is
// kept apart and the bands are added in order, so the result is the same
// whatever the number of threads.
constexpr int kBandRows = 8;
// Pixels per vector: 16 floats, one register, with AVX-512; 8, one AVX
// register, on other targets. GCC 12 split a 16-float vector badly on AVX2:
// a vector times a scalar went through the stack lane by lane, and the
// blurs ran several times slower than with 8 floats.
#ifdef __AVX512F__
constexpr int kLanes = 16;
#else
constexpr int kLanes = 8;
#endif

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

// The planes' rows start on a cache line: each row is padded to a
// multiple of 16 floats (64 bytes), so that the vertical pass's loads, one
// vector from each of 11 rows, do not straddle two lines (at 1440x1080 the
// loss took 1.2 times as long with rows wherever the width put them).
size_t row_stride(int W) { return (size_t(W) + 15) / 16 * 16; }

// The planes the horizontal pass reads (the render's and the photo's
// channels and the SSIM map's derivatives) have each row between zeros, a
// margin of kMargin floats before column 0 (which keeps it on a cache line)
// and the row's padding after column W, then the next row's margin (the
// last row's is one more at the end of the plane): the pass reads them at
// every output column in vectors, borders included. Column 0 of row y:
size_t margin_stride(int W) { return row_stride(W) + kMargin; }
size_t margin_row(int y, int W) { return size_t(y) * margin_stride(W) + kMargin; }
size_t margin_plane_size(int W, int H) { return size_t(H) * margin_stride(W) + kMargin; }

// Writes the zeros around the rows of a margin plane; its rows' W values
// are written by the loss, which leaves the zeros as they are.
void clear_margins(ImageBuffer<float>& plane, int W, int H) {
  for (int y = 0; y < H; ++y) {
    float* row = &plane[margin_row(y, W)];
    std::fill(row - kMargin, row, 0.f);
    std::fill(row + W, row + row_stride(W), 0.f);
  }
  std::fill(plane.end() - kMargin, plane.end(), 0.f);
}

// A band's scratch rows, cache-line aligned and left uninitialised: every
// element is written before it is read (clearing them was a few per cent
// of the loss).
ImageBuffer<float> scratch(size_t n) { return ImageBuffer<float>(n); }

// kLanes floats as one vector (GCC's vector extension); unaligned loads
// through memcpy.
using Lanes = float __attribute__((vector_size(kLanes * sizeof(float))));
inline Lanes load_lanes(const float* p) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
// An unaligned store through a vector type of float alignment (and
// allowed to alias floats): GCC 12 copied a memcpy of a whole vector
// through the stack, as 32-byte halves.
using UnalignedLanes =
    float __attribute__((vector_size(kLanes * sizeof(float)), aligned(4), may_alias));
inline void store_lanes(float* p, Lanes v) { *reinterpret_cast<UnalignedLanes*>(p) = v; }

// out[i] = sum over taps t of weight[t] * rows[t][i] for i in [0, n), n a
// multiple of kLanes (rows padded to row_stride), the taps of each pixel
// added in order. Chunks of kLanes pixels keep their sums in registers and
// are stored once (adding tap by tap into the output row cost a load and a
// store per tap and pixel, which bound the blurs), four chunks at a time so
// that their chains of multiply-adds overlap. kFixedTaps: the tap count as a
// constant (0: `taps`), which lets the compiler keep the weights and rows in
// registers for the whole row (the vertical pass's rows away from the
// image's top and bottom).
template <int kFixedTaps>
void weighted_rows_of(const float* const* rows, const float* weight, int taps, int n, float* out) {
  if constexpr (kFixedTaps > 0) taps = kFixedTaps;
  constexpr int kChunks = 4;
  int i = 0;
  for (; i + kChunks * kLanes <= n; i += kChunks * kLanes) {
    Lanes acc[kChunks] = {};
    for (int t = 0; t < taps; ++t)
      for (int c = 0; c < kChunks; ++c) acc[c] += weight[t] * load_lanes(rows[t] + i + c * kLanes);
    for (int c = 0; c < kChunks; ++c) store_lanes(out + i + c * kLanes, acc[c]);
  }
  for (; i < n; i += kLanes) {
    Lanes acc = {};
    for (int t = 0; t < taps; ++t) acc += weight[t] * load_lanes(rows[t] + i);
    store_lanes(out + i, acc);
  }
}
void weighted_rows(const float* const* rows, const float* weight, int taps, int n, float* out) {
  if (taps == 2 * kRadius + 1) return weighted_rows_of<2 * kRadius + 1>(rows, weight, taps, n, out);
  weighted_rows_of<0>(rows, weight, taps, n, out);
}

// One row of the horizontal pass (zero padding): out[x] = sum_k w[k] in[x+k]
// over the row's stride, the columns past W included (which the vertical
// pass reads in vectors; they come out finite). `in` is column 0 of a
// margin plane's row. Taps are added in the
// same order at every pixel; a tap on a zero adds +0 to a sum that started
// at +0 (and so is never -0), so a border pixel comes out as the sum of its
// taps inside the image, the reference's zero padding, to the bit.
void blur_row(const Window& w, const float* in, float* out, int W) {
  std::array<const float*, 2 * kRadius + 1> taps;
  for (int k = 0; k <= 2 * kRadius; ++k) taps[k] = in + k - kRadius;
  weighted_rows(taps.data(), w.data(), 2 * kRadius + 1, int(row_stride(W)), out);
}

// Rows [y0, y1) of the vertical pass over a horizontally blurred plane,
// output row y to out(y - y0) over the row's stride (whole vectors); rows
// off the image are left out (zero padding).
template <typename OutRow>
void blur_columns(const Window& w, const ImageBuffer<float>& in, int y0, int y1, int W, int H,
                  const OutRow& out) {
  const size_t S = row_stride(W);
  for (int y = y0; y < y1; ++y) {
    std::array<const float*, 2 * kRadius + 1> rows;
    std::array<float, 2 * kRadius + 1> weights;
    int taps = 0;
    for (int k = -kRadius; k <= kRadius; ++k) {
      if (y + k < 0 || y + k >= H) continue;
      rows[taps] = &in[size_t(y + k) * S];
      weights[taps++] = w[k + kRadius];
    }
    weighted_rows(rows.data(), weights.data(), taps, int(S), out(y - y0));
  }
}

// The horizontal pass of x, y, x^2, y^2 and xy of channel c.
void blur_statistics_horizontally(const Window& w, ImageLossBuffers& b, int W, int H, int c) {
  const size_t S = row_stride(W);
  for_each_band(H, [&](int, int y0, int y1) {
    // The products, in a margin plane of one row (zeros but for its W values).
    ImageBuffer<float> product(margin_plane_size(W, 1), 0.f);
    float* row = &product[margin_row(0, W)];
    for (int y = y0; y < y1; ++y) {
      const size_t o = size_t(y) * S;
      const float *x = &b.x[c][margin_row(y, W)], *t = &b.y[c][margin_row(y, W)];
      blur_row(w, x, &b.blurred[0][o], W);
      blur_row(w, t, &b.blurred[1][o], W);
      for (int i = 0; i < W; ++i) row[i] = x[i] * x[i];
      blur_row(w, row, &b.blurred[2][o], W);
      for (int i = 0; i < W; ++i) row[i] = t[i] * t[i];
      blur_row(w, row, &b.blurred[3][o], W);
      for (int i = 0; i < W; ++i) row[i] = x[i] * t[i];
      blur_row(w, row, &b.blurred[4][o], W);
    }
  });
}

// SSIM of pixels with the given blurred statistics and, with kGradient, its
// derivatives with respect to the render's statistics (mu_x, E[x^2], E[xy]),
// the y statistics fixed. V is float or Lanes: the same formulas, one pixel
// or kLanes at a time. In float, as the reference computes SSIM (float32
// tensors).
template <bool kGradient, typename V>
struct SsimTerms {
  V S, d_mu, d_exx, d_exy;
  SsimTerms(V mux, V muy, V exx, V eyy, V exy) {
    const V sxx = exx - mux * mux, syy = eyy - muy * muy, sxy = exy - mux * muy;
    const V A1 = 2 * mux * muy + kC1, A2 = 2 * sxy + kC2;
    const V B1 = mux * mux + muy * muy + kC1, B2 = sxx + syy + kC2;
    const V inv_B = 1 / (B1 * B2);
    S = A1 * A2 * inv_B;
    if constexpr (kGradient) {
      d_mu = (2 * muy * A2 - 2 * muy * A1) * inv_B - S * (2 * mux / B1 - 2 * mux / B2);
      d_exx = -S / B2;
      d_exy = 2 * A1 * inv_B;
    }
  }
};

// The SSIM map of one row from its five blurred statistics (rows of W,
// `stride` apart, in `stats`) and, with kGradient, its derivatives
// (SsimTerms). Returns the row's sum; one partial sum per vector lane,
// since a single running sum would chain every pixel to the one before.
template <bool kGradient>
double ssim_row(const float* stats, size_t stride, int W, float* d_mu, float* d_exx, float* d_exy) {
  const float *mx = stats, *my = stats + stride, *exx = stats + 2 * stride,
              *eyy = stats + 3 * stride, *exy = stats + 4 * stride;
  Lanes lane_sums = {};
  int i = 0;
  for (; i + kLanes <= W; i += kLanes) {
    const SsimTerms<kGradient, Lanes> t(load_lanes(mx + i), load_lanes(my + i), load_lanes(exx + i),
                                        load_lanes(eyy + i), load_lanes(exy + i));
    lane_sums += t.S;
    if constexpr (kGradient) {
      std::memcpy(d_mu + i, &t.d_mu, sizeof(Lanes));
      std::memcpy(d_exx + i, &t.d_exx, sizeof(Lanes));
      std::memcpy(d_exy + i, &t.d_exy, sizeof(Lanes));
    }
  }
  for (; i < W; ++i) {
    const SsimTerms<kGradient, float> t(mx[i], my[i], exx[i], eyy[i], exy[i]);
    lane_sums[0] += t.S;
    if constexpr (kGradient) d_mu[i] = t.d_mu, d_exx[i] = t.d_exx, d_exy[i] = t.d_exy;
  }
  double sum = 0;
  for (int l = 0; l < kLanes; ++l) sum += lane_sums[l];
  return sum;
}

// The vertical pass, then the SSIM map and, with `gradient`, its derivatives
// (b.d_stats). Returns the map's sum.
double ssim_from_statistics(const Window& w, ImageLossBuffers& b, int W, int H, bool gradient) {
  const size_t S = row_stride(W);
  for_each_band(H, [&](int band, int y0, int y1) {
    // [row][statistic][column]: ssim_row reads a row's five statistics.
    auto stats = scratch(size_t(kBandRows) * 5 * S);
    for (int q = 0; q < 5; ++q)
      blur_columns(w, b.blurred[q], y0, y1, W, H,
                   [&](int r) { return &stats[(size_t(r) * 5 + q) * S]; });
    double sum = 0;
    for (int y = y0; y < y1; ++y) {
      const float* row = &stats[size_t(y - y0) * 5 * S];
      const size_t o = margin_row(y, W);
      sum += gradient
                 ? ssim_row<true>(row, S, W, &b.d_stats[0][o], &b.d_stats[1][o], &b.d_stats[2][o])
                 : ssim_row<false>(row, S, W, nullptr, nullptr, nullptr);
    }
    b.band_sums[band] = sum;
  });
  double sum = 0;
  for (int band = 0; band < bands_of(H); ++band) sum += b.band_sums[band];
  return sum;
}

// d(SSIM map sum)/dx of channel c, into b.d_ssim[c]: the window is
// symmetric, so the adjoint of the blur is the blur itself.
void ssim_gradient(const Window& w, ImageLossBuffers& b, int W, int H, int c) {
  const size_t S = row_stride(W);
  for_each_band(H, [&](int, int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int q = 0; q < 3; ++q)
        blur_row(w, &b.d_stats[q][margin_row(y, W)], &b.blurred[q][size_t(y) * S], W);
  });
  for_each_band(H, [&](int, int y0, int y1) {
    auto rows = scratch(size_t(kBandRows) * 3 * S);  // [row][statistic][column]
    for (int q = 0; q < 3; ++q)
      blur_columns(w, b.blurred[q], y0, y1, W, H,
                   [&](int r) { return &rows[(size_t(r) * 3 + q) * S]; });
    for (int y = y0; y < y1; ++y) {
      const float* g = &rows[size_t(y - y0) * 3 * S];
      const size_t o = size_t(y) * S;
      const float *x = &b.x[c][margin_row(y, W)], *t = &b.y[c][margin_row(y, W)];
      float* d = &b.d_ssim[c][o];
      for (int i = 0; i < W; ++i) d[i] = g[i] + 2 * x[i] * g[S + i] + t[i] * g[2 * S + i];
    }
  });
}

// Absolute and squared differences of n interleaved values, summed into
// one partial sum per vector lane (element j into lane j % kLanes, the tail
// into lane 0), as ssim_row's; and, with kGradient, the L1's gradient g
// sign(x - t) into dx (torch's sign(0) = 0). The sign is the difference of
// two comparisons, so the loop has no branch; restrict pointers and no
// test inside let GCC vectorise it (the loop with a test per element for
// dx ran a value at a time).
template <bool kGradient>
inline void add_difference(const float* __restrict x, const float* __restrict t,
                           float* __restrict dx, float g, size_t i, double& abs_sum,
                           double& square_sum) {
  const double e = double(x[i]) - t[i];
  abs_sum += std::abs(e);
  square_sum += e * e;
  if constexpr (kGradient) {
    const float d = x[i] - t[i];
    dx[i] = g * (float(d > 0) - float(d < 0));
  }
}

template <bool kGradient>
void difference_lanes(const float* __restrict x, const float* __restrict t, float* __restrict dx,
                      float g, size_t n, double* __restrict abs_sums,
                      double* __restrict square_sums) {
  size_t i = 0;
  for (; i + kLanes <= n; i += kLanes)
    for (int l = 0; l < kLanes; ++l)
      add_difference<kGradient>(x, t, dx, g, i + l, abs_sums[l], square_sums[l]);
  for (; i < n; ++i) add_difference<kGradient>(x, t, dx, g, i, abs_sums[0], square_sums[0]);
}

// One row of interleaved RGB into three planes.
void split_row(const float* __restrict rgb, float* __restrict r, float* __restrict g,
               float* __restrict b, int W) {
  for (int x = 0; x < W; ++x) r[x] = rgb[3 * x], g[x] = rgb[3 * x + 1], b[x] = rgb[3 * x + 2];
}

// Reads the render and the photo once, band by band: the sums of absolute
// and squared differences, with grad the L1's gradient (which starts grad),
// and both images split into channels while the band is in the cache.
std::pair<double, double> read_images(std::span<const float> rendered, const ImageRGB& target,
                                      float g, std::vector<float>* grad, ImageLossBuffers& b) {
  const int W = target.width, H = target.height;
  if (grad) grad->resize(rendered.size());
  const float* x = rendered.data();
  const float* t = target.data.data();
  float* dx = grad ? grad->data() : nullptr;
  for_each_band(H, [&](int band, int y0, int y1) {
    double abs_sums[kLanes] = {}, square_sums[kLanes] = {};
    const size_t first = size_t(y0) * W * 3, n = size_t(y1 - y0) * W * 3;
    if (dx)
      difference_lanes<true>(x + first, t + first, dx + first, g, n, abs_sums, square_sums);
    else
      difference_lanes<false>(x + first, t + first, nullptr, g, n, abs_sums, square_sums);
    double abs_sum = 0, square_sum = 0;
    for (int l = 0; l < kLanes; ++l) abs_sum += abs_sums[l], square_sum += square_sums[l];
    b.band_sums[band] = abs_sum;
    b.band_sums[bands_of(H) + band] = square_sum;
    for (int y = y0; y < y1; ++y) {
      const size_t o = margin_row(y, W), i = size_t(y) * W * 3;
      split_row(x + i, &b.x[0][o], &b.x[1][o], &b.x[2][o], W);
      split_row(t + i, &b.y[0][o], &b.y[1][o], &b.y[2][o], W);
    }
  });
  double abs_sum = 0, square_sum = 0;
  for (int band = 0; band < bands_of(H); ++band)
    abs_sum += b.band_sums[band], square_sum += b.band_sums[bands_of(H) + band];
  return {abs_sum, square_sum};
}

// rgb += scale * (r, g, b) over one row, the planes interleaved again.
void add_row(float* __restrict rgb, const float* __restrict r, const float* __restrict g,
             const float* __restrict b, float scale, int W) {
  for (int x = 0; x < W; ++x) {
    rgb[3 * x] += scale * r[x];
    rgb[3 * x + 1] += scale * g[x];
    rgb[3 * x + 2] += scale * b[x];
  }
}

// grad += scale * d_ssim, the channels interleaved again in one pass.
void add_ssim_gradient(const ImageLossBuffers& b, int W, int H, float scale,
                       std::vector<float>& grad) {
  const size_t S = row_stride(W);
  for_each_band(H, [&](int, int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const size_t o = size_t(y) * S;
      add_row(&grad[size_t(y) * W * 3], &b.d_ssim[0][o], &b.d_ssim[1][o], &b.d_ssim[2][o], scale,
              W);
    }
  });
}

void prepare(ImageLossBuffers& b, int W, int H, bool gradient) {
  const size_t n = row_stride(W) * H;  // planes of padded rows
  const size_t m = margin_plane_size(W, H);
  for (int c = 0; c < 3; ++c) b.x[c].resize(m), b.y[c].resize(m);
  for (auto& v : b.blurred) v.resize(n);
  for (auto& d : b.d_stats) d.resize(gradient ? m : 0);
  for (auto& d : b.d_ssim) d.resize(gradient ? n : 0);
  b.band_sums.resize(2 * bands_of(H));
  // The margins' zeros stay from call to call: they are written only for a
  // new layout.
  const std::array<int, 3> layout = {W, H, gradient ? 1 : 0};
  if (b.margin_layout == layout) return;
  for (int c = 0; c < 3; ++c) clear_margins(b.x[c], W, H), clear_margins(b.y[c], W, H);
  if (gradient)
    for (auto& d : b.d_stats) clear_margins(d, W, H);
  b.margin_layout = layout;
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
      read_images(rendered, target, (1 - options.lambda_ssim) / float(n), grad, b);
  loss.l1 = abs_sum / n;
  loss.mse = square_sum / n;
  double ssim_sum = 0;
  for (int c = 0; c < 3; ++c) {
    blur_statistics_horizontally(w, b, W, H, c);
    ssim_sum += ssim_from_statistics(w, b, W, H, grad != nullptr);
    if (grad) ssim_gradient(w, b, W, H, c);
  }
  // loss term lambda * (1 - mean SSIM): d/dx = -lambda / n * d(sum)/dx.
  if (grad) add_ssim_gradient(b, W, H, -options.lambda_ssim / float(n), *grad);
  loss.ssim = ssim_sum / n;
  loss.total = (1 - options.lambda_ssim) * loss.l1 + options.lambda_ssim * (1 - loss.ssim);
  return loss;
}

}  // namespace splat
