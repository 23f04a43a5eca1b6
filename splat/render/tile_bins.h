#pragma once
// Step 2 of rendering: bin projected Gaussians into 16x16 tiles and sort each
// tile's list front to back by depth (ties by Gaussian index, so the order is
// fully determined).
//
// Each (Gaussian, tile) pair is an "entry". Entries are numbered Gaussian by
// Gaussian (entries of Gaussian i are gaussian_entries[i] .. [i+1]); the
// backward pass writes one gradient per entry and sums each Gaussian's entries
// in that order, which needs no locks and gives the same result for any thread
// count.

#include <cstdint>
#include <vector>

#include "splat/render/project.h"

namespace splat {

struct TileBins {
  int tiles_x = 0, tiles_y = 0;
  std::vector<uint32_t> tile_start;        // tiles + 1: slots of tile t are [start[t], start[t+1])
  std::vector<uint32_t> slot_gaussian;     // per slot (sorted within its tile): Gaussian index
  std::vector<uint32_t> slot_entry;        // per slot: entry number (gradient slot)
  std::vector<uint32_t> gaussian_entries;  // N + 1: entries of Gaussian i

  size_t num_entries() const { return slot_gaussian.size(); }
};

void bin_gaussians(const ProjectedGaussians& projected, TileBins& bins);

}  // namespace splat
