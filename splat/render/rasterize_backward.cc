#include <tbb/parallel_for.h>

#include <algorithm>

#include "splat/render/fast_exp.h"
#include "splat/render/rasterize.h"
#include "splat/render/tile_gaussians.h"

namespace splat {
namespace {

constexpr int kLanes = kTileSize;

// Gradient of one entry (Gaussian in one tile), summed over its pixels.
enum EntryGrad { kMeanX, kMeanY, kConicA, kConicB, kConicC, kRed, kGreen, kBlue, kDepth,
                 kOpacity, kInstanceOpacity, kEntryGrads };

// Output gradients and running sums of one row, going back to front.
struct RowBackState {
  alignas(64) float T[kLanes];           // transmittance after the current Gaussian
  alignas(64) float T_final[kLanes];
  alignas(64) int32_t last[kLanes];
  alignas(64) float g_color[3][kLanes];  // dL/d(output colour)
  alignas(64) float g_alpha[kLanes];
  alignas(64) float g_depth[kLanes];
  alignas(64) float behind[3][kLanes];   // sum of w_k c_k over Gaussians behind
  alignas(64) float behind_depth[kLanes];
  alignas(64) float bg_dot[3][kLanes];   // T_final * background, per channel
  std::vector<float> g_planes;           // dL/dS per instance map plane, kLanes each
};

template <bool kColor, bool kInstance>
inline void blend_back(const TileGaussians& tg, size_t k, float px0, float py, RowBackState& s,
                       float* entry) {
  const float mx = tg.mx[k], dy = tg.my[k] - py, A = tg.A[k], B = tg.B[k], C = tg.C[k];
  const float op = tg.opacity[k], op_star = tg.instance_opacity[k], z = tg.depth[k];
  const int32_t position = int32_t(k);
  const float* g_plane = (kInstance && tg.plane[k] >= 0) ? &s.g_planes[size_t(tg.plane[k]) * kLanes] : nullptr;
  float c[3] = {0, 0, 0};
  if constexpr (kColor) c[0] = tg.r[k], c[1] = tg.g[k], c[2] = tg.b[k];
  alignas(64) float acc[kEntryGrads][kLanes];
#pragma GCC ivdep
  for (int l = 0; l < kLanes; ++l) {
    const float dx = mx - (px0 + float(l));
    const float power = -0.5f * (A * dx * dx + C * dy * dy) - B * dx * dy;
    const float G = fast_exp(std::min(power, 0.f));
    const float raw_alpha = op * G;
    const float alpha = std::min(kMaxAlpha, raw_alpha);
    const bool valid = position < s.last[l] && power <= 0.f && alpha >= kMinAlpha;
    const float inv_one_minus = 1.f / (1.f - alpha);
    const float T_i = valid ? s.T[l] * inv_one_minus : s.T[l];
    const float w = valid ? alpha * T_i : 0.f;

    float g_alpha = s.g_alpha[l] * s.T_final[l] * inv_one_minus;
    g_alpha += s.g_depth[l] * (z * T_i - s.behind_depth[l] * inv_one_minus);
    acc[kDepth][l] = s.g_depth[l] * w;
    s.behind_depth[l] += w * z;
    if constexpr (kColor) {
      for (int ch = 0; ch < 3; ++ch) {
        g_alpha += s.g_color[ch][l] * (c[ch] * T_i - (s.behind[ch][l] + s.bg_dot[ch][l]) * inv_one_minus);
        acc[kRed + ch][l] = s.g_color[ch][l] * w;
        s.behind[ch][l] += w * c[ch];
      }
    } else {
      acc[kRed][l] = acc[kGreen][l] = acc[kBlue][l] = 0.f;
    }
    g_alpha = valid ? g_alpha : 0.f;
    // The alpha clamp at 0.99 has zero derivative, in both branches.
    const bool open = raw_alpha < kMaxAlpha;
    float g_G = open ? g_alpha * op : 0.f;
    acc[kOpacity][l] = open ? g_alpha * G : 0.f;
    acc[kInstanceOpacity][l] = 0.f;
    if constexpr (kInstance) {
      // S_j = sum alpha*_i T_i with T_i held constant: the object loss reaches
      // sigma* and the geometry (through G), never sigma or colour.
      const float g_star = (valid && g_plane) ? g_plane[l] * T_i : 0.f;
      const bool open_star = op_star * G < kMaxAlpha;
      acc[kInstanceOpacity][l] = open_star ? g_star * G : 0.f;
      g_G += open_star ? g_star * op_star : 0.f;
    }
    const float g_power = g_G * G;
    acc[kMeanX][l] = -g_power * (A * dx + B * dy);
    acc[kMeanY][l] = -g_power * (C * dy + B * dx);
    acc[kConicA][l] = -0.5f * g_power * dx * dx;
    acc[kConicB][l] = -g_power * dx * dy;
    acc[kConicC][l] = -0.5f * g_power * dy * dy;
    s.T[l] = T_i;
  }
  for (int j = 0; j < kEntryGrads; ++j) {
    float sum = 0.f;
    for (int l = 0; l < kLanes; ++l) sum += acc[j][l];
    entry[j] += sum;
  }
}

template <bool kColor, bool kInstance>
void backward_row(const TileGaussians& tg, const uint32_t* entries, float px0, float py,
                  RowBackState& s, std::vector<float>& entry_grads) {
  int32_t last = 0;
  for (int l = 0; l < kLanes; ++l) last = std::max(last, s.last[l]);
  for (int32_t k = last - 1; k >= 0; --k) {
    if (py < tg.y_lo[k] || py > tg.y_hi[k]) continue;
    blend_back<kColor, kInstance>(tg, size_t(k), px0, py, s, &entry_grads[size_t(entries[k]) * kEntryGrads]);
  }
}

}  // namespace

void rasterize_backward(const RenderSettings& settings, const RasterState& st,
                        const RenderOutputGradients& grads, ProjectedGradients& out) {
  const int W = st.width, H = st.height;
  const size_t pixels = size_t(W) * H;
  const size_t planes = st.map_of_label.empty() ? 0 : grads.instance_maps.size() / std::max<size_t>(pixels, 1);
  const bool color = settings.color && !grads.color.empty();
  const bool instance = planes > 0;
  auto row_fn = color ? (instance ? backward_row<true, true> : backward_row<true, false>)
                      : (instance ? backward_row<false, true> : backward_row<false, false>);
  std::vector<float> entry_grads(st.bins.num_entries() * kEntryGrads, 0.f);

  const size_t tiles = size_t(st.bins.tiles_x) * st.bins.tiles_y;
  tbb::parallel_for(size_t(0), tiles, [&](size_t t) {
    const uint32_t lo = st.bins.tile_start[t], hi = st.bins.tile_start[t + 1];
    if (lo == hi) return;
    const int tx = int(t % st.bins.tiles_x), ty = int(t / st.bins.tiles_x);
    TileGaussians tg;
    tg.gather(st, lo, hi, color);
    RowBackState s;
    s.g_planes.assign(planes * kLanes, 0.f);
    const int x0 = tx * kTileSize, lanes = std::min(kTileSize, W - x0);
    for (int y = ty * kTileSize; y < std::min(H, (ty + 1) * kTileSize); ++y) {
      for (int l = 0; l < kLanes; ++l) {
        const bool in = l < lanes;
        const size_t pix = size_t(y) * W + x0 + (in ? l : 0);
        s.T[l] = s.T_final[l] = in ? st.final_transmittance[pix] : 1.f;
        s.last[l] = in ? int32_t(st.n_contrib[pix]) : 0;
        s.g_alpha[l] = in && !grads.alpha.empty() ? grads.alpha[pix] : 0.f;
        s.g_depth[l] = in && !grads.depth.empty() ? grads.depth[pix] : 0.f;
        s.behind_depth[l] = 0.f;
        for (int c = 0; c < 3; ++c) {
          s.g_color[c][l] = in && color ? grads.color[3 * pix + c] : 0.f;
          s.behind[c][l] = 0.f;
          s.bg_dot[c][l] = s.T_final[l] * settings.background[c];
        }
        for (size_t m = 0; m < planes; ++m)
          s.g_planes[m * kLanes + l] = in ? grads.instance_maps[m * pixels + pix] : 0.f;
      }
      row_fn(tg, &st.bins.slot_entry[lo], float(x0) + 0.5f, float(y) + 0.5f, s, entry_grads);
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
