#pragma once
// Camera distortion as COLMAP models it: where a pixel of the undistorted
// PINHOLE view falls in the distorted photo and back, and ID maps resampled
// through it.
//
// ID maps follow their images through COLMAP's undistorter. SAM2 runs on the
// user's photos, so its ID maps have the photos' geometry; once COLMAP has
// undistorted the photos into PINHOLE views (cropped and re-centred), every
// map must be resampled the same way, or the labels of the voting and the
// object loss land beside their objects. COLMAP's own undistorter blends
// neighbouring pixels, which would invent IDs at object boundaries: here
// each undistorted pixel takes the ID of the nearest distorted one.
//
// Conventions are COLMAP's: the centre of the top-left pixel is (0.5, 0.5),
// and the distortion models map undistorted normalised coordinates to
// distorted ones (COLMAP's src/base/camera_models.h).

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "splat/colmap_model.h"
#include "splat/image.h"

namespace splat {

// Where the pixel position (x, y) of the undistorted PINHOLE camera falls in
// the distorted camera, in the same continuous pixel coordinates. Throws
// std::invalid_argument for a camera model without a closed-form distortion
// (FOV, THIN_PRISM_FISHEYE).
Eigen::Vector2d distorted_position(const ColmapCamera& distorted, const ColmapCamera& pinhole,
                                   double x, double y);

// The inverse of distorted_position: the position in the undistorted PINHOLE
// camera of the distorted camera's pixel position (x, y). NaN where the
// distortion cannot be inverted there (far outside a fisheye's image).
Eigen::Vector2d undistorted_position(const ColmapCamera& distorted, const ColmapCamera& pinhole,
                                     double x, double y);

// The way back, for scoring undistorted renders against ground truth drawn on
// the photos: for every pixel of the `distorted` camera (row-major), the
// index of the nearest pixel of an image of the `pinhole` view at
// source_width x source_height (the view's size or a downscaled one), or -1
// where the photo sees what the undistorted view cropped away.
std::vector<int64_t> photo_pixel_sources(const ColmapCamera& distorted, const ColmapCamera& pinhole,
                                         int source_width, int source_height);

// The ID map of a view of `distorted` (the map may be of another size with
// the same aspect ratio), resampled to the view of `pinhole` with
// nearest-neighbour sampling; pixels that fall outside the map get 0.
IdMap undistort_id_map(const IdMap& map, const ColmapCamera& distorted,
                       const ColmapCamera& pinhole);

}  // namespace splat
