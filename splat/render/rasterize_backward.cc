#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "splat/render/fast_exp.h"
#include "splat/render/rasterize.h"
#include "splat/render/tile_gaussians.h"

namespace splat {
namespace {

constexpr int kLanes = kTileSize;
constexpr int kRows = kTileSize;

// Gradient of one entry (Gaussian in one tile), summed over its pixels.
enum EntryGrad { kMeanX, kMeanY, kConicA, kConicB, kConicC, kRed, kGreen, kBlue, kDepth,
                 kOpacity, kInstanceOpacity, kEntryGrads };
static_assert(kEntryGrads == kRasterEntryGradients);

// Per-pixel state of one tile, going back to front: [row][lane].
struct TileBackState {
  alignas(64) float T[kRows][kLanes];  // transmittance after the current Gaussian
  alignas(64) float T_final[kRows][kLanes];
  alignas(64) int32_t last[kRows][kLanes];
  alignas(64) float g_color[3][kRows][kLanes];  // dL/d(output colour)
  alignas(64) float g_alpha[kRows][kLanes];
  alignas(64) float g_depth[kRows][kLanes];
  alignas(64) float behind[3][kRows][kLanes];  // sum of w_k c_k over Gaussians behind
  alignas(64) float behind_depth[kRows][kLanes];
  alignas(64) float bg_dot[3][kRows][kLanes];  // T_final * background
  int32_t row_last[kRows];                     // largest `last` of each row
  std::vector<float> g_planes;                 // dL/dS: [plane][row][lane]
  alignas(64) float zeros[kRows][kLanes] = {};  // dL/dS of labels without a map
};

// One Gaussian on one row: adds its pixels' gradient terms to acc.
template <bool kColor, bool kInstance>
inline void back_row(const TileGaussians& tg, size_t k, float px0, float py, int row,
                     const float* g_plane, TileBackState& s, float (&acc)[kEntryGrads][kLanes]) {
  const float mx = tg.mx[k], dy = tg.my[k] - py, A = tg.A[k], B = tg.B[k], C = tg.C[k];
  const float op = tg.opacity[k], op_star = tg.instance_opacity[k], z = tg.depth[k];
  const int32_t position = int32_t(k);
  float c[3] = {0, 0, 0};
  if constexpr (kColor) c[0] = tg.r[k], c[1] = tg.g[k], c[2] = tg.b[k];
  float* T = s.T[row];
#pragma GCC ivdep
  for (int l = 0; l < kLanes; ++l) {
    const float dx = mx - (px0 + float(l));
    const float power = -0.5f * (A * dx * dx + C * dy * dy) - B * dx * dy;
    const float G = fast_exp(std::min(power, 0.f));
    const float raw_alpha = op * G;
    const float alpha = std::min(kMaxAlpha, raw_alpha);
    // Float 0/1 masks and selects on them keep the lanes vectorised.
    const float m_valid = (position < s.last[row][l] ? 1.f : 0.f) * (power <= 0.f ? 1.f : 0.f) *
                          (alpha >= kMinAlpha ? 1.f : 0.f);
    const float inv_one_minus = 1.f / (1.f - alpha);
    const float T_i = m_valid > 0.f ? T[l] * inv_one_minus : T[l];
    const float w = m_valid * alpha * T_i;

    float g_alpha = s.g_alpha[row][l] * s.T_final[row][l] * inv_one_minus;
    g_alpha += s.g_depth[row][l] * (z * T_i - s.behind_depth[row][l] * inv_one_minus);
    acc[kDepth][l] += s.g_depth[row][l] * w;
    s.behind_depth[row][l] += w * z;
    if constexpr (kColor) {
      for (int ch = 0; ch < 3; ++ch) {
        g_alpha += s.g_color[ch][row][l] *
                   (c[ch] * T_i - (s.behind[ch][row][l] + s.bg_dot[ch][row][l]) * inv_one_minus);
        acc[kRed + ch][l] += s.g_color[ch][row][l] * w;
        s.behind[ch][row][l] += w * c[ch];
      }
    }
    // The alpha clamp at 0.99 has zero derivative, in both branches.
    g_alpha *= m_valid * (raw_alpha < kMaxAlpha ? 1.f : 0.f);
    float g_G = g_alpha * op;
    acc[kOpacity][l] += g_alpha * G;
    if constexpr (kInstance) {
      // S_j = sum alpha*_i T_i with T_i held constant: the object loss reaches
      // sigma* and the geometry (through G), never sigma or colour.
      const float g_star = m_valid * (op_star * G < kMaxAlpha ? 1.f : 0.f) * g_plane[l] * T_i;
      acc[kInstanceOpacity][l] += g_star * G;
      g_G += g_star * op_star;
    }
    const float g_power = g_G * G;
    acc[kMeanX][l] -= g_power * (A * dx + B * dy);
    acc[kMeanY][l] -= g_power * (C * dy + B * dx);
    acc[kConicA][l] -= 0.5f * g_power * dx * dx;
    acc[kConicB][l] -= g_power * dx * dy;
    acc[kConicC][l] -= 0.5f * g_power * dy * dy;
    T[l] = T_i;
  }
}

// All rows of one tile, Gaussians back to front; each Gaussian's gradient is
// summed over the rows it reaches, then over lanes, once.
template <bool kColor, bool kInstance>
void backward_tile(const TileGaussians& tg, const uint32_t* entries, float px0, int y0, int rows,
                   TileBackState& s, std::vector<float>& entry_grads) {
  int32_t last = 0;
  for (int r = 0; r < rows; ++r) last = std::max(last, s.row_last[r]);
  for (int32_t k = last - 1; k >= 0; --k) {
    // Rows whose pixel centres lie within the Gaussian's reach.
    const int r0 = std::max(0, int(std::ceil(tg.y_lo[k] - 0.5f)) - y0);
    const int r1 = std::min(rows - 1, int(std::floor(tg.y_hi[k] - 0.5f)) - y0);
    if (r0 > r1) continue;
    const float* g_planes = nullptr;
    if constexpr (kInstance) g_planes = tg.plane[k] >= 0 ? &s.g_planes[size_t(tg.plane[k]) * kRows * kLanes] : &s.zeros[0][0];
    alignas(64) float acc[kEntryGrads][kLanes] = {};
    for (int r = r0; r <= r1; ++r) {
      if (k >= s.row_last[r]) continue;
      back_row<kColor, kInstance>(tg, size_t(k), px0, float(y0 + r) + 0.5f, r,
                                  kInstance ? g_planes + r * kLanes : nullptr, s, acc);
    }
    float* entry = &entry_grads[size_t(entries[k]) * kEntryGrads];
    for (int j = 0; j < kEntryGrads; ++j) {
      float sum = 0.f;
      for (int l = 0; l < kLanes; ++l) sum += acc[j][l];
      entry[j] = sum;
    }
  }
}

void load_tile_state(const RenderSettings& settings, const RasterState& st,
                     const RenderOutputGradients& grads, bool color, size_t planes, int x0, int y0,
                     int lanes, int rows, TileBackState& s) {
  const size_t pixels = size_t(st.width) * st.height;
  for (int r = 0; r < kRows; ++r) {
    s.row_last[r] = 0;
    for (int l = 0; l < kLanes; ++l) {
      const bool in = l < lanes && r < rows;
      const size_t pix = in ? size_t(y0 + r) * st.width + x0 + l : 0;
      s.T[r][l] = s.T_final[r][l] = in ? st.final_transmittance[pix] : 1.f;
      s.last[r][l] = in ? int32_t(st.n_contrib[pix]) : 0;
      s.row_last[r] = std::max(s.row_last[r], s.last[r][l]);
      s.g_alpha[r][l] = in && !grads.alpha.empty() ? grads.alpha[pix] : 0.f;
      s.g_depth[r][l] = in && !grads.depth.empty() ? grads.depth[pix] : 0.f;
      s.behind_depth[r][l] = 0.f;
      for (int c = 0; c < 3; ++c) {
        s.g_color[c][r][l] = in && color ? grads.color[3 * pix + c] : 0.f;
        s.behind[c][r][l] = 0.f;
        s.bg_dot[c][r][l] = s.T_final[r][l] * settings.background[c];
      }
      for (size_t m = 0; m < planes; ++m)
        s.g_planes[(m * kRows + r) * kLanes + l] = in ? grads.instance_maps[m * pixels + pix] : 0.f;
    }
  }
}

}  // namespace

void rasterize_backward(const RenderSettings& settings, RasterState& st,
                        const RenderOutputGradients& grads, ProjectedGradients& out) {
  const int W = st.width, H = st.height;
  const size_t pixels = size_t(W) * H;
  const size_t planes = pixels ? grads.instance_maps.size() / pixels : 0;
  const bool color = settings.color && !grads.color.empty();
  const bool instance = planes > 0;
  auto tile_fn = color ? (instance ? backward_tile<true, true> : backward_tile<true, false>)
                       : (instance ? backward_tile<false, true> : backward_tile<false, false>);
  // Entries no pixel reaches keep zero: every entry is written or zeroed here.
  std::vector<float>& entry_grads = st.entry_grads;
  entry_grads.assign(st.bins.num_entries() * kEntryGrads, 0.f);

  const size_t tiles = size_t(st.bins.tiles_x) * st.bins.tiles_y;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles, 1), [&](const auto& range) {
    TileGaussians tg;
    auto s = std::make_unique<TileBackState>();
    s->g_planes.assign(planes * kRows * kLanes, 0.f);
    for (size_t t = range.begin(); t < range.end(); ++t) {
      const uint32_t lo = st.bins.tile_start[t], hi = st.bins.tile_start[t + 1];
      if (lo == hi) continue;
      const int tx = int(t % st.bins.tiles_x), ty = int(t / st.bins.tiles_x);
      const int x0 = tx * kTileSize, y0 = ty * kTileSize;
      const int lanes = std::min(kTileSize, W - x0), rows = std::min(kTileSize, H - y0);
      tg.gather(st, lo, hi, color);
      load_tile_state(settings, st, grads, color, planes, x0, y0, lanes, rows, *s);
      tile_fn(tg, &st.bins.slot_entry[lo], float(x0) + 0.5f, y0, rows, *s, entry_grads);
    }
  });

  // Each Gaussian's entries, summed in entry order.
  const size_t n = st.projected.size();
  out.resize(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const auto& range) {
    for (size_t i = range.begin(); i < range.end(); ++i) {
      float sum[kEntryGrads] = {};
      for (uint32_t e = st.bins.gaussian_entries[i]; e < st.bins.gaussian_entries[i + 1]; ++e)
        for (int j = 0; j < kEntryGrads; ++j) sum[j] += entry_grads[size_t(e) * kEntryGrads + j];
      out.mean2d[2 * i] = sum[kMeanX];
      out.mean2d[2 * i + 1] = sum[kMeanY];
      out.conic[3 * i] = sum[kConicA];
      out.conic[3 * i + 1] = sum[kConicB];
      out.conic[3 * i + 2] = sum[kConicC];
      out.color[3 * i] = sum[kRed];
      out.color[3 * i + 1] = sum[kGreen];
      out.color[3 * i + 2] = sum[kBlue];
      out.depth[i] = sum[kDepth];
      out.opacity[i] = sum[kOpacity];
      out.instance_opacity[i] = sum[kInstanceOpacity];
    }
  });
}

}  // namespace splat
