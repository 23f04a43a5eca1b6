#pragma once
// Fixed seeded Gaussian scenes for the benchmarks (described at the top of
// render_bench.cc): a camera at the origin looking along +z, a "volume" of
// Gaussians spread through space, and a "surface" scene of flattened
// Gaussians on patches, as training leaves them.

#include <cstddef>

#include "splat/camera.h"
#include "splat/gaussians.h"

namespace bench {

splat::Camera bench_camera(int width, int height);
splat::GaussianModel bench_scene(size_t n, int width, int height);
splat::GaussianModel surface_scene(size_t n, int width, int height);

}  // namespace bench
