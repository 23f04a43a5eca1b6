#pragma once
// What op2gs reads of a COLMAP database (SQLite): the IDs COLMAP gave the
// images, which a model of known poses must use to be triangulated.

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

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

}  // namespace splat
