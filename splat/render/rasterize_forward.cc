#include <tbb/parallel_for.h>

#include <algorithm>

#include "splat/render/fast_exp.h"
#include "splat/render/rasterize.h"
#include "splat/render/tile_gaussians.h"

namespace splat {
namespace {

constexpr int kLanes = kTileSize;  // one tile row

// Per-pixel blending state of one row of a tile.
struct RowState {
  alignas(64) float T[kLanes];
  alignas(64) float color[3][kLanes];
  alignas(64) float depth[kLanes];
  alignas(64) float done[kLanes];  // 1 once the ray has terminated (or lies off the image)
  alignas(64) int32_t last[kLanes];
  alignas(64) int32_t blended[kLanes];
  alignas(64) float best_instance_alpha[kLanes];
  alignas(64) int32_t instance_label[kLanes];
  alignas(64) float best_weight[kLanes];
  alignas(64) int32_t baseline_label[kLanes];
  std::vector<float> planes;  // instance maps, plane-major, kLanes each

  void reset(int lanes, size_t num_planes) {
    for (int l = 0; l < kLanes; ++l) {
      T[l] = 1.f;
      color[0][l] = color[1][l] = color[2][l] = depth[l] = 0.f;
      done[l] = l < lanes ? 0.f : 1.f;
      last[l] = 0;
      blended[l] = 0;
      best_instance_alpha[l] = 0.f;
      instance_label[l] = 0;
      best_weight[l] = 0.f;
      baseline_label[l] = 0;
    }
    planes.assign(num_planes * kLanes, 0.f);
  }
  bool all_done() const {
    float d = 1.f;
    for (int l = 0; l < kLanes; ++l) d = std::min(d, done[l]);
    return d > 0.f;
  }
};

// Blends Gaussian k of the tile into the row at pixel-centre height py.
template <bool kColor, bool kInstance, bool kLabels>
inline void blend(const TileGaussians& tg, size_t k, float px0, float py, RowState& s) {
  const float mx = tg.mx[k], dy = tg.my[k] - py, A = tg.A[k], B = tg.B[k], C = tg.C[k];
  const float op = tg.opacity[k], op_star = tg.instance_opacity[k];
  const int32_t position = int32_t(k) + 1, label = tg.label[k];
  float* plane = kInstance ? &s.planes[size_t(tg.plane[k]) * kLanes] : nullptr;
  float cr = 0, cg = 0, cb = 0;
  if constexpr (kColor) cr = tg.r[k], cg = tg.g[k], cb = tg.b[k];
  const float z = tg.depth[k];
#pragma GCC ivdep
  for (int l = 0; l < kLanes; ++l) {
    const float dx = mx - (px0 + float(l));
    const float power = -0.5f * (A * dx * dx + C * dy * dy) - B * dx * dy;
    const float G = fast_exp(std::min(power, 0.f));
    const float alpha = std::min(kMaxAlpha, op * G);
    // Conditions as float 0/1 masks and selects on them: GCC if-converts
    // these, so the lanes vectorise (bool & bool ? a : b it does not).
    const float m_valid = (s.done[l] == 0.f ? 1.f : 0.f) * (power <= 0.f ? 1.f : 0.f) *
                          (alpha >= kMinAlpha ? 1.f : 0.f);
    const float next_T = s.T[l] * (1.f - alpha);
    const float m_terminate = next_T < kMinTransmittance ? m_valid : 0.f;
    const float m_contribute = m_valid - m_terminate;
    const float w = m_contribute * alpha * s.T[l];
    if constexpr (kColor) {
      s.color[0][l] += w * cr;
      s.color[1][l] += w * cg;
      s.color[2][l] += w * cb;
    }
    s.depth[l] += w * z;
    if constexpr (kInstance || kLabels) {
      const float alpha_star = std::min(kMaxAlpha, op_star * G);
      if constexpr (kInstance) plane[l] += m_contribute * alpha_star * s.T[l];
      if constexpr (kLabels) {
        const float m_better = m_contribute * (alpha_star >= kMinAlpha ? 1.f : 0.f) *
                               (alpha_star > s.best_instance_alpha[l] ? 1.f : 0.f);
        s.best_instance_alpha[l] = m_better > 0.f ? alpha_star : s.best_instance_alpha[l];
        s.instance_label[l] = m_better > 0.f ? label : s.instance_label[l];
        // w > 0 only where the Gaussian contributes.
        const float m_heavier = w > s.best_weight[l] ? 1.f : 0.f;
        s.best_weight[l] = m_heavier > 0.f ? w : s.best_weight[l];
        s.baseline_label[l] = m_heavier > 0.f ? label : s.baseline_label[l];
      }
    }
    s.last[l] = m_contribute > 0.f ? position : s.last[l];
    s.blended[l] += m_contribute > 0.f ? 1 : 0;
    s.T[l] = m_contribute > 0.f ? next_T : s.T[l];
    s.done[l] = std::max(s.done[l], m_terminate);
  }
}

template <bool kColor, bool kInstance, bool kLabels>
void blend_row(const TileGaussians& tg, float px0, float py, RowState& s) {
  const size_t n = tg.size();
  for (size_t k = 0; k < n; ++k) {
    if (py < tg.y_lo[k] || py > tg.y_hi[k]) continue;  // out of reach for the whole row
    // Only Gaussians whose label has a map pay for the instance branch.
    if (kInstance && tg.plane[k] >= 0)
      blend<kColor, kInstance, kLabels>(tg, k, px0, py, s);
    else
      blend<kColor, false, kLabels>(tg, k, px0, py, s);
    if ((k & 15) == 15 && s.all_done()) break;
  }
}

using RowFunction = void (*)(const TileGaussians&, float, float, RowState&);

RowFunction pick_row_function(bool color, bool instance, bool labels) {
  static constexpr RowFunction table[8] = {
      blend_row<false, false, false>, blend_row<false, false, true>,
      blend_row<false, true, false>,  blend_row<false, true, true>,
      blend_row<true, false, false>,  blend_row<true, false, true>,
      blend_row<true, true, false>,   blend_row<true, true, true>};
  return table[(color ? 4 : 0) + (instance ? 2 : 0) + (labels ? 1 : 0)];
}

}  // namespace

void rasterize_forward(const RenderSettings& settings, RasterState& st, RenderOutput& out) {
  const int W = st.width, H = st.height;
  const size_t pixels = size_t(W) * H;
  const size_t planes = out.instance_map_labels.size();
  const bool labels = settings.instance_label_map || settings.baseline_label_map;
  out.width = W;
  out.height = H;
  out.color.assign(settings.color ? 3 * pixels : 0, 0.f);
  out.alpha.assign(pixels, 0.f);
  out.depth.assign(pixels, 0.f);
  out.contributors.assign(pixels, 0);
  out.instance_maps.assign(planes * pixels, 0.f);
  out.instance_label.assign(settings.instance_label_map ? pixels : 0, 0);
  out.baseline_label.assign(settings.baseline_label_map ? pixels : 0, 0);
  st.final_transmittance.assign(pixels, 1.f);
  st.n_contrib.assign(pixels, 0);
  const RowFunction row_fn = pick_row_function(settings.color, planes > 0, labels);

  const size_t tiles = size_t(st.bins.tiles_x) * st.bins.tiles_y;
  tbb::parallel_for(size_t(0), tiles, [&](size_t t) {
    const int tx = int(t % st.bins.tiles_x), ty = int(t / st.bins.tiles_x);
    TileGaussians tg;
    tg.gather(st, st.bins.tile_start[t], st.bins.tile_start[t + 1], settings.color);
    RowState s;
    const int x0 = tx * kTileSize, lanes = std::min(kTileSize, W - x0);
    for (int y = ty * kTileSize; y < std::min(H, (ty + 1) * kTileSize); ++y) {
      s.reset(lanes, planes);
      row_fn(tg, float(x0) + 0.5f, float(y) + 0.5f, s);
      for (int l = 0; l < lanes; ++l) {
        const size_t pix = size_t(y) * W + x0 + l;
        if (settings.color)
          for (int c = 0; c < 3; ++c) out.color[3 * pix + c] = s.color[c][l] + s.T[l] * settings.background[c];
        out.alpha[pix] = 1.f - s.T[l];
        out.depth[pix] = s.depth[l];
        out.contributors[pix] = uint32_t(s.blended[l]);
        st.final_transmittance[pix] = s.T[l];
        st.n_contrib[pix] = uint32_t(s.last[l]);
        for (size_t m = 0; m < planes; ++m) out.instance_maps[m * pixels + pix] = s.planes[m * kLanes + l];
        if (settings.instance_label_map) out.instance_label[pix] = s.instance_label[l];
        if (settings.baseline_label_map) out.baseline_label[pix] = s.baseline_label[l];
      }
    }
  });
}

}  // namespace splat
