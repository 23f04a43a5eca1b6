#pragma once
// ID map folders follow their images through COLMAP's undistorter (see
// splat/camera_distortion.h for the per-map resampling and its conventions).

#include <cstddef>
#include <filesystem>

#include "splat/colmap_model.h"

namespace splat {

// Replaces the folder <to> (its old content is removed). For every image of
// the undistorted model: reads <from>/<stem>.png, writes the undistorted map
// to <to>/<stem>.png (8-bit, or 16-bit when an ID needs
// it). Images without a map are skipped (the stages that read the maps report
// them); other files of <from> (objects.json) are linked. Returns the number of
// maps written. Throws InputError naming a map that cannot be read or whose
// camera model cannot be undistorted.
size_t undistort_id_map_folder(const std::filesystem::path& from, const std::filesystem::path& to,
                               const ColmapModel& distorted, const ColmapModel& undistorted);

}  // namespace splat
