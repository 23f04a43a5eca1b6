#include "splat/image.h"

#include <fmt/format.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "splat/atomic_file.h"
#include "splat/image_codec.h"

namespace splat {
namespace fs = std::filesystem;

namespace {

cv::Mat as_mat(const ImageRGB& image) {
  return cv::Mat(image.height, image.width, CV_32FC3, const_cast<float*>(image.data.data()));
}

}  // namespace

ImageInfo read_image_info(const fs::path& file) {
  const ImageFileSpec spec = ImageFileReader(file).spec();
  return {spec.width, spec.height, spec.channels, spec.bits, spec.orientation};
}

ImageRGB read_image_rgb(const fs::path& file) {
  ImageFileReader in(file);
  const ImageFileSpec& spec = in.spec();
  const auto usable = [](float v) { return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f; };
  if (spec.channels >= 3) {
    // Decoded straight into the image, alpha left out: no second copy of a
    // view the trainer loads every iteration it misses the cache.
    ImageRGB image(spec.width, spec.height);
    in.read(3, SampleType::float32, image.data.data());
    for (float& v : image.data) v = usable(v);
    return image;
  }
  const std::vector<float> pixels = in.read_all<float>(SampleType::float32);
  const int nc = spec.channels;
  ImageRGB image(spec.width, spec.height);
  const size_t n = size_t(spec.width) * spec.height;
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      // Grey (1 or grey+alpha 2 channels) is replicated; alpha is dropped.
      image.data[3 * i + c] = usable(pixels[i * nc]);
    }
  }
  return image;
}

void write_image_rgb(const fs::path& file, const ImageRGB& image) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  ImageFileSpec spec{image.width, image.height, 3};
  if (ext == ".exr") spec.type = SampleType::half;
  if (ext == ".tif" || ext == ".tiff") spec.type = SampleType::uint16;
  write_image_file(file, spec, SampleType::float32, image.data.data());
}

ImageRGB resize_area(const ImageRGB& image, int width, int height) {
  ImageRGB out(width, height);
  cv::Mat dst(height, width, CV_32FC3, out.data.data());
  cv::resize(as_mat(image), dst, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  return out;
}

namespace {

// Copies the rows of `rect` out of `src` (`channels` values a pixel) into
// `dst`, sized for the rectangle.
template <typename T>
void copy_rect(const std::vector<T>& src, int width, int height, int channels, const PixelRect& r,
               std::vector<T>& dst) {
  if (r.x < 0 || r.y < 0 || r.width < 1 || r.height < 1 || r.x + r.width > width ||
      r.y + r.height > height)
    throw std::invalid_argument(
        fmt::format("crop: the rectangle {}x{} at ({}, {}) is not inside "
                    "the {}x{} image",
                    r.width, r.height, r.x, r.y, width, height));
  const size_t row = size_t(r.width) * channels;
  for (int y = 0; y < r.height; ++y)
    std::copy_n(src.begin() + (size_t(r.y + y) * width + r.x) * channels, row,
                dst.begin() + size_t(y) * row);
}

}  // namespace

ImageRGB crop(const ImageRGB& image, const PixelRect& rect) {
  ImageRGB out(std::max(rect.width, 0), std::max(rect.height, 0));
  copy_rect(image.data, image.width, image.height, 3, rect, out.data);
  return out;
}

IdMap crop(const IdMap& map, const PixelRect& rect) {
  IdMap out(std::max(rect.width, 0), std::max(rect.height, 0));
  copy_rect(map.ids, map.width, map.height, 1, rect, out.ids);
  return out;
}

std::pair<int, int> downscaled_size(int width, int height, double downscale) {
  auto scaled = [&](int n) { return std::max(1, int(std::lround(n / downscale))); };
  return {scaled(width), scaled(height)};
}

ImageRGB downscale_area(const ImageRGB& image, int factor) {
  if (factor <= 1) return image;
  const auto [w, h] = downscaled_size(image.width, image.height, factor);
  return resize_area(image, w, h);
}

void write_mask_png(const fs::path& file, int width, int height,
                    const std::vector<uint8_t>& inside) {
  std::vector<uint8_t> px(inside.size());
  for (size_t i = 0; i < px.size(); ++i) px[i] = inside[i] ? 255 : 0;
  write_image_file(file, {width, height, 1}, SampleType::uint8, px.data());
}

}  // namespace splat
