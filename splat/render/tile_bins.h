#pragma once
// Step 2 of rendering: bin projected Gaussians into 16x16 tiles and sort each
// tile's list front to back by depth (ties by Gaussian index, so the order is
// fully determined).
//
// Each (Gaussian, tile) pair is an "entry" and has a "slot" in its tile's list.

#include <cstdint>
#include <vector>

#include "splat/render/project.h"

namespace splat {

struct TileBins {
  int tiles_x = 0, tiles_y = 0;
  std::vector<uint32_t> tile_start;     // tiles + 1: slots of tile t are [start[t], start[t+1])
  std::vector<uint32_t> slot_gaussian;  // per slot (sorted within its tile): Gaussian index
  // Scratch, one per visible Gaussian, reused from view to view.
  std::vector<uint64_t> sort_keys, sort_scratch;

  size_t num_entries() const { return slot_gaussian.size(); }
};

void bin_gaussians(const ProjectedGaussians& projected, TileBins& bins);

}  // namespace splat
