#include "splat/sfm/photo_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <set>

#include "splat/error.h"
#include "splat/image.h"

namespace splat {
namespace fs = std::filesystem;

namespace {
bool is_photo(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff";
}
}  // namespace

std::vector<std::string> photo_names(const fs::path& images) {
  if (!fs::is_directory(images)) throw InputError(images, "no image folder");
  std::vector<std::string> names;
  for (const auto& f : fs::directory_iterator(images))
    if (f.is_regular_file() && is_photo(f.path())) names.push_back(f.path().filename().string());
  std::sort(names.begin(), names.end());
  if (names.size() < 2) throw InputError(images, "SfM needs at least two images");
  return names;
}

PhotoHeaders check_photo_headers(const fs::path& images, const std::vector<std::string>& names) {
  std::set<std::pair<int, int>> sizes;
  PhotoHeaders h;
  for (const std::string& name : names) {
    const ImageInfo info = read_image_info(images / name);
    h.deeper_than_8_bits |= info.bits > 8;
    if (info.orientation != 1)
      throw InputError(images / name,
                       fmt::format("EXIF orientation {} (the photo is stored turned or "
                                   "mirrored): store the photos upright first, e.g. `exiftran "
                                   "-ai *.jpg` or `mogrify -auto-orient *.jpg`, and make the ID "
                                   "maps from the upright photos",
                                   info.orientation));
    sizes.insert({info.width, info.height});
  }
  h.sizes = sizes.size();
  return h;
}

size_t make_eight_bit_copies(const fs::path& images, const std::vector<std::string>& names,
                             const fs::path& copies) {
  fs::create_directories(copies);
  size_t made = 0;
  for (const std::string& name : names) {
    const fs::path from = images / name, to = copies / name;
    if (fs::exists(to) && fs::last_write_time(to) >= fs::last_write_time(from)) continue;
    write_image_rgb(to, read_image_rgb(from));
    ++made;
  }
  return made;
}

}  // namespace splat
