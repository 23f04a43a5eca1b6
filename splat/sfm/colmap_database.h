#pragma once
// What op2gs reads of a COLMAP database (SQLite): the IDs COLMAP gave the
// images, which a model of known poses must use to be triangulated.

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include "splat/colmap_model.h"

namespace splat {

struct DatabaseImage {
  uint32_t image_id = 0;
  uint32_t camera_id = 0;
};

// Image name -> IDs. Throws InputError naming the file if it cannot be read.
std::map<std::string, DatabaseImage> read_database_images(const std::filesystem::path& database);

// The number of feature matches that passed geometric verification, over
// all image pairs (COLMAP's two_view_geometries). Throws InputError naming
// the file if it cannot be read.
uint64_t count_verified_matches(const std::filesystem::path& database);

// The model with the image and camera IDs the database gave its images (the
// feature extractor numbers them in the order its threads finish), as
// COLMAP's point_triangulator needs them. Throws InputError naming the
// database when it lacks one of the model's images.
ColmapModel with_database_ids(const ColmapModel& model, const std::filesystem::path& database);

}  // namespace splat
