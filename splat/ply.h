#pragma once
// Gaussian models as PLY files in the layout every 3DGS viewer reads
// (docs/gaussian-splatting.md): a binary little-endian "vertex"
// element with float properties
//   x y z nx ny nz f_dc_0..2 f_rest_0..44 opacity scale_0..2 rot_0..3
// followed, for OP2GS models, by
//   float instance_opacity   (logit of sigma*)
//   int   label              (object ID, 0 = background)
//
// Reading accepts binary little-endian and ASCII files with the properties in
// any order and of any scalar type, extra properties (ignored), fewer f_rest
// coefficients (lower SH degrees; the rest are zero), and files without the
// OP2GS properties. Malformed or truncated files throw InputError naming the
// file.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "splat/gaussians.h"

namespace splat {

GaussianModel read_gaussian_ply(const std::filesystem::path& file);

// Writes binary little-endian, atomically. The OP2GS properties are written
// when the model has them (has_instance_opacity / has_labels).
void write_gaussian_ply(const std::filesystem::path& file, const GaussianModel& model);

// A coloured point cloud (the sparse points of a capture).
struct PointCloud {
  std::vector<Eigen::Vector3d> xyz;
  std::vector<std::array<uint8_t, 3>> rgb;  // grey where the file has no colour
};

// The vertices of any PLY point cloud (nerfstudio's sparse_pc.ply, Open3D's
// and COLMAP's exports): x y z of any scalar type, and red green blue (or
// diffuse_red ...) when present. ASCII or binary little-endian; errors as
// read_gaussian_ply's.
PointCloud read_point_ply(const std::filesystem::path& file);

}  // namespace splat
