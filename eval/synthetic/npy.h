#pragma once
// Writing NumPy .npy files (format version 1.0), for LLFF poses_bounds.npy.

#include <filesystem>
#include <vector>

namespace synth {

// Writes a C-order float64 array of the given shape, atomically.
void write_npy_f64(const std::filesystem::path& file, const std::vector<double>& values,
                   const std::vector<size_t>& shape);

}  // namespace synth
