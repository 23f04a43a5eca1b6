#pragma once
// OpenImageIO helpers shared by the readers and writers of RGB images
// (image.cc) and ID maps (id_maps.cc). Internal to the core library.

#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <memory>
#include <vector>

#include "splat/error.h"

namespace splat {

// Opens an image for reading, keeping colour values as stored. Throws
// InputError naming the file when it is missing, unreadable or empty.
std::unique_ptr<OIIO::ImageInput> open_image_input(const std::filesystem::path& file);

// All pixels of the first subimage in `type`. Throws InputError naming the file.
template <typename T>
std::vector<T> read_pixels(OIIO::ImageInput& in, OIIO::TypeDesc type,
                           const std::filesystem::path& file) {
  const auto& spec = in.spec();
  std::vector<T> pixels(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in.read_image(0, 0, 0, spec.nchannels, type, pixels.data()))
    throw InputError(file, "cannot decode image: " + in.geterror());
  return pixels;
}

// Writes atomically (a temporary name, then renamed into place); the
// extension picks the format.
void write_image_with_oiio(const std::filesystem::path& file, const OIIO::ImageSpec& spec,
                           OIIO::TypeDesc src_type, const void* pixels);

}  // namespace splat
