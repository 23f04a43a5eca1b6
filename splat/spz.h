#pragma once
// Gaussian models as SPZ files (Niantic's "splat zip", version 2): the
// compressed format web viewers read (Spark, the report's 3D viewer), about
// 10x smaller than the PLY. A gzip stream of a 16-byte header
//   uint32 magic 0x5053474e, uint32 version 2, uint32 count,
//   uint8 SH degree, uint8 fractional bits, uint8 flags, uint8 reserved
// followed by one array per attribute: positions (24-bit fixed point),
// opacities (8 bits, sigma), DC colours, log scales and rotations (8 bits
// each), SH coefficients (8 bits, coefficient-major with the colour channel
// inner, as GaussianModel::sh_rest). Coordinates are stored as given (no
// axis change): the viewer uses the model's own frame.
//
// Quantised: a model read back differs from the written one by at most the
// step of each encoding (tested). Labels and sigma* are not part of the format.

#include <cstdint>
#include <filesystem>
#include <string>

#include "splat/gaussians.h"

namespace splat {

// The encoded file's bytes (gzip-compressed).
std::string encode_spz(const GaussianModel& model);

// Writes encode_spz(model) atomically.
void write_spz(const std::filesystem::path& file, const GaussianModel& model);

// Decodes an SPZ file of version 2 (what write_spz writes); throws InputError
// naming the file when it is malformed or of another version.
GaussianModel read_spz(const std::filesystem::path& file);

}  // namespace splat
