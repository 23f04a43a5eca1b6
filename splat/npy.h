#pragma once
// NumPy .npy files (format versions 1.0 to 3.0) of float64 arrays, as LLFF's
// poses_bounds.npy (3DOVS) stores its cameras.

#include <filesystem>
#include <vector>

namespace splat {

// Writes a C-order float64 array of the given shape, atomically.
void write_npy_f64(const std::filesystem::path& file, const std::vector<double>& values,
                   const std::vector<size_t>& shape);

// Reads a C-order array of little-endian float64 or float32 values (as
// double), with its shape. Throws InputError naming the file for anything else.
std::vector<double> read_npy(const std::filesystem::path& file, std::vector<size_t>* shape);

}  // namespace splat
