#pragma once
// LLFF cameras (poses_bounds.npy, as 3DOVS ships them): per image, in the
// order of the sorted image names, a 3x5 matrix [R | t | (H, W, f)] of the
// camera-to-world pose with columns (down, right, backwards), then the near
// and far bounds.

#include <filesystem>
#include <string>
#include <vector>

#include "splat/colmap_model.h"

namespace splat {

// The cameras as a COLMAP model without points: one PINHOLE camera per image
// size (id 1 for all when they share it), images numbered 1.. in name order
// (as COLMAP's feature extractor numbers a fresh database). The focal length
// is scaled from the stored H, W to the actual image size width x height.
ColmapModel llff_to_colmap(const std::filesystem::path& poses_bounds,
                           const std::vector<std::string>& image_names, int width, int height);

}  // namespace splat
