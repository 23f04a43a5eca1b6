#pragma once
// The scene folder op2gs-sfm leaves for the later stages, <out>/scene/: the
// kept model with pinhole cameras in sparse/0/, the views in images/, the
// photos' own cameras in photo_cameras/ when COLMAP undistorted them, and
// everything else of the user's folder (ID maps, benchmark files) linked in.

#include <filesystem>
#include <string>
#include <vector>

#include "splat/colmap_model.h"

namespace splat {

// A model whose cameras are pinholes already: the model as it is, and the
// photos linked as the views.
void write_pinhole_scene(const ColmapModel& model, const std::filesystem::path& photos,
                         const std::filesystem::path& scene);

// From COLMAP's image_undistorter output (`undistorted`: images/, sparse/)
// for the photos' model `distorted`, whose cameras are kept in
// photo_cameras/ (op2gs-eval maps renders back onto the photos with them).
void write_undistorted_scene(const std::filesystem::path& undistorted, const ColmapModel& distorted,
                             const std::filesystem::path& scene);

// The ID maps of the user's photos (each folder of `id_map_dirs` it holds),
// resampled as COLMAP undistorted the photos. Always redone: it is quick,
// and the user may have replaced the maps since the last run.
void undistort_user_id_maps(const std::filesystem::path& user, const std::filesystem::path& scene,
                            const ColmapModel& distorted,
                            const std::vector<std::string>& id_map_dirs);

// Links everything else the user's folder holds (ID maps, the LERF-Mask and
// 3DOVS benchmark files) into the scene. The user's downscaled copies
// (images_2/ ...) only when the views were not undistorted: they have the
// photos' geometry.
void link_user_files(const std::filesystem::path& user, const std::filesystem::path& scene,
                     const std::string& images, bool undistorted);

}  // namespace splat
