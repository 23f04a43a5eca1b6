#pragma once
// A decoded view as the view cache holds it. A photo of 8 bits per channel
// decodes to floats that are each code * (1 / 255); those are kept as the codes,
// a quarter of the memory, so that a cache of a given size holds four times
// as many views (all 262 training views of a LERF-Mask scene in 564 MB
// instead of 2.2 GB). Any other image (16-bit, HDR, area-resized) is kept as
// floats. Unpacking gives back the decoded floats bit for bit either way.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "splat/image.h"

namespace splat {

class PackedImageRGB {
 public:
  // Keeps the codes when every value is exactly one of the 256 code values.
  static PackedImageRGB pack(ImageRGB image);
  // From 3 * width * height codes, interleaved RGB.
  static PackedImageRGB from_codes(int width, int height, std::vector<uint8_t> codes);

  int width() const { return width_; }
  int height() const { return height_; }
  bool holds_codes() const { return !codes_.empty() || floats_.data.empty(); }
  size_t bytes() const { return codes_.size() + floats_.data.size() * sizeof(float); }
  // The decoded image itself when it is held as floats, to be read in place
  // (the trainer's target: a copy of it was a pass over the photo every
  // iteration); null when it is held as codes.
  const ImageRGB* floats() const { return holds_codes() ? nullptr : &floats_; }

  // Writes the image into `out`, resizing it; a buffer reused across calls
  // is not reallocated.
  void unpack_into(ImageRGB& out) const;
  ImageRGB unpack() const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<uint8_t> codes_;  // 3 * W * H, or empty
  ImageRGB floats_;             // when the values are not all codes
};

// Reads an image file as the view cache keeps it: an 8-bit RGB(A) file is
// decoded straight to its codes (no float image made and packed again);
// anything else as read_image_rgb reads it, then packed. Unpacked, the same
// floats as read_image_rgb's. Throws InputError naming the file.
PackedImageRGB read_packed_image_rgb(const std::filesystem::path& file);

// The float an 8-bit code decodes to (code * (1 / 255), as OpenImageIO gives it).
float code_value(uint8_t code);

}  // namespace splat
