#pragma once
// What op2gs-sfm checks of the user's photos before COLMAP sees them.

#include <filesystem>
#include <string>
#include <vector>

namespace splat {

// The photos of a folder (PNG, JPEG, TIFF), sorted by name. Throws InputError
// when there is no such folder or fewer than two photos.
std::vector<std::string> photo_names(const std::filesystem::path& images);

struct PhotoHeaders {
  size_t sizes = 0;  // distinct width x height (portrait and landscape mixed: 2)
  bool deeper_than_8_bits = false;
};

// Reads every photo's header. Throws InputError for a photo stored turned or
// mirrored (EXIF orientation): COLMAP, the segmenter and the trainer would not
// agree on which way is up.
PhotoHeaders check_photo_headers(const std::filesystem::path& images,
                                 const std::vector<std::string>& names);

// COLMAP 3.8 cannot read 16-bit PNGs: 8-bit copies of the photos in `copies`,
// remade only where a photo is newer than its copy. Returns how many were
// made.
size_t make_eight_bit_copies(const std::filesystem::path& images,
                             const std::vector<std::string>& names,
                             const std::filesystem::path& copies);

}  // namespace splat
