#pragma once
// Steps 3 and 4 of rendering: blend each tile's depth-sorted Gaussians front
// to back for every pixel (forward), and send the output gradients back to
// the projected quantities (backward).
//
// Work is split into rows of 16 pixels inside each tile; a row's pixels are
// lanes that the compiler vectorises. Rows of Gaussians' reach (alpha >= 1/255)
// that miss a row are skipped; this changes no pixel.

#include <cstdint>
#include <vector>

#include "splat/render/project.h"
#include "splat/render/render_types.h"
#include "splat/render/tile_bins.h"

namespace splat {

// Floats of gradient the backward pass keeps per (Gaussian, tile) entry.
inline constexpr int kRasterEntryGradients = 11;

// Everything the backward pass needs from the forward pass.
struct RasterState {
  int width = 0, height = 0;
  ProjectedGaussians projected;
  TileBins bins;
  std::vector<float> final_transmittance;  // W * H
  std::vector<uint32_t> n_contrib;         // W * H: tile-list position of the last contributor + 1
  std::vector<int32_t> map_of_label;       // label -> instance map plane, -1 if none
  std::vector<int32_t> labels;             // per Gaussian (copied from the model, 0 if none)
  std::vector<float> entry_grads;          // backward scratch: gradient per (Gaussian, tile) entry
};

// Fills out (colour, alpha, depth, contributors, and what settings ask of
// the instance branch). state.projected and state.bins must be filled.
void rasterize_forward(const RenderSettings& settings, RasterState& state, RenderOutput& out);

// Accumulates dLoss/d(projected quantities) from the output gradients.
void rasterize_backward(const RenderSettings& settings, RasterState& state,
                        const RenderOutputGradients& grads, ProjectedGradients& out);

}  // namespace splat
