#pragma once
// Indexed-colour (palette) PNGs as ID maps. SAM2's video tools, and the
// DAVIS / YouTube-VOS tooling around them, save one PNG per frame in palette
// mode: the stored index of a pixel is its object ID, the palette only a
// colouring. General image readers (OpenImageIO, OpenCV) expand the palette
// to RGB and lose the IDs, so these files are decoded with libpng.

#include <filesystem>
#include <optional>

#include "splat/image.h"

namespace splat {

// The palette indices of an indexed-colour PNG (bit depth 1 to 8), or
// nothing when the file is not a PNG in palette mode. Throws InputError
// naming the file when it is one but cannot be decoded.
std::optional<IdMap> read_png_palette_indices(const std::filesystem::path& file);

}  // namespace splat
