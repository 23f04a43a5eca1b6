#pragma once
// Float RGB images and integer ID maps as pixel buffers; RGB images and
// masks read and written through OpenImageIO (ID map files: id_maps.h).

#include <cstdint>
#include <filesystem>
#include <utility>
#include <vector>

namespace splat {

// Interleaved float RGB, row-major, values in [0, 1].
struct ImageRGB {
  int width = 0;
  int height = 0;
  std::vector<float> data;  // size 3 * width * height

  ImageRGB() = default;
  ImageRGB(int w, int h) : width(w), height(h), data(size_t(3) * w * h, 0.0f) {}
  float* pixel(int x, int y) { return data.data() + 3 * (size_t(y) * width + x); }
  const float* pixel(int x, int y) const { return data.data() + 3 * (size_t(y) * width + x); }
  size_t bytes() const { return data.size() * sizeof(float); }
};

// One integer ID per pixel (object IDs, 0 = background / unlabeled).
struct IdMap {
  int width = 0;
  int height = 0;
  std::vector<uint16_t> ids;  // size width * height

  IdMap() = default;
  IdMap(int w, int h) : width(w), height(h), ids(size_t(w) * h, 0) {}
  uint16_t& at(int x, int y) { return ids[size_t(y) * width + x]; }
  uint16_t at(int x, int y) const { return ids[size_t(y) * width + x]; }
};

// What an image file's header says, without decoding its pixels.
struct ImageInfo {
  int width = 0, height = 0, channels = 0;
  int bits = 8;         // per sample
  int orientation = 1;  // EXIF orientation: 1 upright, 6 and 8 turned by 90 degrees, ...
};
// Throws InputError naming the file when it cannot be opened as an image.
ImageInfo read_image_info(const std::filesystem::path& file);

// Reads PNG (8/16 bit), JPEG, EXR, or anything else OpenImageIO reads, to RGB
// in [0, 1]. Grey images are replicated to RGB; an alpha channel is dropped;
// float (HDR) values are clamped to [0, 1]. Throws InputError naming the file.
ImageRGB read_image_rgb(const std::filesystem::path& file);

// Writes RGB atomically. The extension picks the format: .png and .jpg are
// written as 8 bit, .exr as half float, .tif as 16 bit.
void write_image_rgb(const std::filesystem::path& file, const ImageRGB& image);

// The size of a width x height image downscaled by `downscale`: rounded, at
// least one pixel each way (the reference 3DGS loader's rule).
std::pair<int, int> downscaled_size(int width, int height, double downscale);

// Downscales by an integer factor with an area (box) filter: OpenCV's
// INTER_AREA to round(W / factor) x round(H / factor), as the reference 3DGS
// loader sizes its downsampled images.
ImageRGB downscale_area(const ImageRGB& image, int factor);
// Resizes with an area filter to an exact size (for images_N folders whose
// size is off by rounding, and for a maximum-width resolution option).
ImageRGB resize_area(const ImageRGB& image, int width, int height);

// A rectangle of pixels: columns [x, x + width), rows [y, y + height).
struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
};
// The pixels of `rect`, which must lie inside the image (else
// std::invalid_argument).
ImageRGB crop(const ImageRGB& image, const PixelRect& rect);
IdMap crop(const IdMap& map, const PixelRect& rect);

// A binary mask as an 8-bit PNG with values 0 and 255 (the format of the
// benchmarks' ground-truth masks).
void write_mask_png(const std::filesystem::path& file, int width, int height,
                    const std::vector<uint8_t>& inside);

}  // namespace splat
