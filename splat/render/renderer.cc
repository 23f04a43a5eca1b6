#include "splat/render/renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "splat/parallel_fill.h"
#include "splat/render/project.h"
#include "splat/render/rasterize.h"
#include "splat/render/tile_bins.h"

namespace splat {
namespace {

template <typename T, typename Allocator>
size_t bytes_of(const std::vector<T, Allocator>& v) {
  return v.capacity() * sizeof(T);
}

struct CpuRenderState : RenderState {
  RasterState raster;
  ProjectedGradients projected_grads;  // backward scratch, reused

  size_t bytes() const override {
    const ProjectedGaussians& p = raster.projected;
    const TileBins& b = raster.bins;
    return bytes_of(p.mean2d) + bytes_of(p.conic) + bytes_of(p.depth) + bytes_of(p.radius) +
           bytes_of(p.tile_rect) + bytes_of(p.reach) + bytes_of(p.color) +
           bytes_of(p.color_clamped) + bytes_of(p.opacity) + bytes_of(p.instance_opacity) +
           bytes_of(b.tile_start) + bytes_of(b.slot_gaussian) + bytes_of(b.sort_keys) +
           bytes_of(b.sort_scratch) + bytes_of(raster.final_transmittance) +
           bytes_of(raster.n_contrib) + bytes_of(raster.map_of_label) + bytes_of(raster.labels) +
           bytes_of(raster.records) + bytes_of(raster.slot_blocks);
  }
  size_t backward_bytes() const override {
    const ProjectedGradients& g = projected_grads;
    return bytes_of(raster.entry_grads) + bytes_of(raster.band_entries) +
           bytes_of(raster.band_index) + bytes_of(g.mean2d) + bytes_of(g.conic) +
           bytes_of(g.depth) + bytes_of(g.color) + bytes_of(g.opacity) +
           bytes_of(g.instance_opacity);
  }
};

void check_settings(const RenderSettings& s, const Camera& camera) {
  if (s.sh_degree < 0 || s.sh_degree > kMaxShDegree)
    throw std::invalid_argument(fmt::format("SH degree must be 0..3, not {}", s.sh_degree));
  if (camera.width <= 0 || camera.height <= 0)
    throw std::invalid_argument(fmt::format("camera size {}x{}", camera.width, camera.height));
  std::vector<int32_t> sorted = s.instance_labels;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    throw std::invalid_argument("instance_labels lists a label twice");
  if (!sorted.empty() && sorted.front() < 0) throw std::invalid_argument("labels must be >= 0");
}

void check_labels(const RenderSettings& s, const GaussianModel& m) {
  if (!s.labels.empty() && s.labels.size() != m.size())
    throw std::invalid_argument(
        fmt::format("{} labels given for {} Gaussians", s.labels.size(), m.size()));
}

// Which labels get an occupancy map, and the plane of each label.
void plan_instance_maps(const GaussianModel& m, const RenderSettings& s, RasterState& st,
                        RenderOutput& out) {
  if (!s.labels.empty())
    st.labels.assign(s.labels.begin(), s.labels.end());
  else if (m.has_labels)
    st.labels.assign(m.labels.begin(), m.labels.end());
  else
    parallel_assign(st.labels, m.size(), 0);
  out.instance_map_labels.clear();
  if (s.all_instance_labels) {
    std::vector<bool> present;
    for (int32_t l : st.labels) {
      if (size_t(l) >= present.size()) present.resize(size_t(l) + 1, false);
      present[l] = true;
    }
    for (int32_t l = 1; l < int32_t(present.size()); ++l)
      if (present[l]) out.instance_map_labels.push_back(l);
  } else {
    out.instance_map_labels = s.instance_labels;
  }
  st.map_of_label.clear();
  for (size_t k = 0; k < out.instance_map_labels.size(); ++k) {
    const int32_t l = out.instance_map_labels[k];
    if (size_t(l) >= st.map_of_label.size()) st.map_of_label.resize(size_t(l) + 1, -1);
    st.map_of_label[l] = int32_t(k);
  }
}

}  // namespace

void CpuRenderer::render(const GaussianModel& model, const Camera& camera,
                         const RenderSettings& settings, RenderOutput& out,
                         std::unique_ptr<RenderState>* state) const {
  check_settings(settings, camera);
  check_labels(settings, model);
  // Reuse the caller's state (and its buffers) when it is one of ours.
  std::unique_ptr<CpuRenderState> own;
  CpuRenderState* cpu_state = state ? dynamic_cast<CpuRenderState*>(state->get()) : nullptr;
  if (!cpu_state) {
    own = std::make_unique<CpuRenderState>();
    cpu_state = own.get();
  }
  RasterState& st = cpu_state->raster;
  st.width = camera.width;
  st.height = camera.height;
  plan_instance_maps(model, settings, st, out);
  project_gaussians(model, camera, settings, st.projected);
  bin_gaussians(st.projected, st.bins);
  rasterize_forward(settings, st, out);
  out.radii = st.projected.radius;
  if (state && own) *state = std::move(own);
}

void CpuRenderer::backward(const GaussianModel& model, const Camera& camera,
                           const RenderSettings& settings,
                           const BackwardSettings& backward_settings, RenderState& state,
                           const RenderOutputGradients& grads, GaussianGradients& out) const {
  if (backward_settings.maps_without_geometry_gradient < 0)
    throw std::invalid_argument("maps without geometry gradient must be >= 0");
  auto* cpu_state = dynamic_cast<CpuRenderState*>(&state);
  if (!cpu_state) throw std::invalid_argument("CpuRenderer::backward needs a CPU render state");
  RasterState& st = cpu_state->raster;
  const size_t pixels = size_t(st.width) * st.height;
  if ((!grads.color.empty() && grads.color.size() != 3 * pixels) ||
      (!grads.alpha.empty() && grads.alpha.size() != pixels) ||
      (!grads.depth.empty() && grads.depth.size() != pixels) ||
      (!grads.instance_maps.empty() &&
       grads.instance_maps.size() != pixels * std::count_if(st.map_of_label.begin(),
                                                            st.map_of_label.end(),
                                                            [](int32_t p) { return p >= 0; })))
    throw std::invalid_argument("output gradients do not match the render's sizes");
  rasterize_backward(settings, backward_settings, st, grads, cpu_state->projected_grads);
  project_gaussians_backward(model, camera, settings, backward_settings, st.projected,
                             cpu_state->projected_grads, out);
}

}  // namespace splat
