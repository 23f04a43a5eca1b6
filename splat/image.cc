#include "splat/image.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/png_indexed.h"

namespace splat {
namespace fs = std::filesystem;

namespace {

std::unique_ptr<OIIO::ImageInput> open_input(const fs::path& file) {
  if (!fs::exists(file)) throw InputError(file, "file does not exist");
  // Keep colour values as stored: without this, PNG RGBA is premultiplied.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(file.string(), &config);
  if (!in) throw InputError(file, "cannot read image: " + OIIO::geterror());
  const auto& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw InputError(file, "image has no pixels");
  return in;
}

template <typename T>
std::vector<T> read_pixels(OIIO::ImageInput& in, OIIO::TypeDesc type, const fs::path& file) {
  const auto& spec = in.spec();
  std::vector<T> pixels(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in.read_image(0, 0, 0, spec.nchannels, type, pixels.data()))
    throw InputError(file, "cannot decode image: " + in.geterror());
  return pixels;
}

void write_with_oiio(const fs::path& file, const OIIO::ImageSpec& spec, OIIO::TypeDesc src_type,
                     const void* pixels) {
  write_atomically(file, [&](const fs::path& tmp) {
    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out) throw InputError(file, "no image writer for this extension: " + OIIO::geterror());
    if (!out->open(tmp.string(), spec) || !out->write_image(src_type, pixels) || !out->close())
      throw InputError(file, "cannot write image: " + out->geterror());
  });
}

cv::Mat as_mat(const ImageRGB& image) {
  return cv::Mat(image.height, image.width, CV_32FC3, const_cast<float*>(image.data.data()));
}

}  // namespace

ImageRGB read_image_rgb(const fs::path& file) {
  auto in = open_input(file);
  const auto& spec = in->spec();
  const std::vector<float> pixels = read_pixels<float>(*in, OIIO::TypeDesc::FLOAT, file);
  const int nc = spec.nchannels;
  ImageRGB image(spec.width, spec.height);
  const size_t n = size_t(spec.width) * spec.height;
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      // Grey (1 or grey+alpha 2 channels) is replicated; alpha is dropped.
      const float v = pixels[i * nc + (nc >= 3 ? c : 0)];
      image.data[3 * i + c] = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
    }
  }
  return image;
}

void write_image_rgb(const fs::path& file, const ImageRGB& image) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  OIIO::TypeDesc type = OIIO::TypeDesc::UINT8;
  if (ext == ".exr") type = OIIO::TypeDesc::HALF;
  if (ext == ".tif" || ext == ".tiff") type = OIIO::TypeDesc::UINT16;
  OIIO::ImageSpec spec(image.width, image.height, 3, type);
  if (ext == ".jpg" || ext == ".jpeg") spec.attribute("Compression", "jpeg:95");
  write_with_oiio(file, spec, OIIO::TypeDesc::FLOAT, image.data.data());
}

ImageRGB resize_area(const ImageRGB& image, int width, int height) {
  ImageRGB out(width, height);
  cv::Mat dst(height, width, CV_32FC3, out.data.data());
  cv::resize(as_mat(image), dst, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  return out;
}

ImageRGB downscale_area(const ImageRGB& image, int factor) {
  if (factor <= 1) return image;
  const int w = std::max(1, int(std::lround(double(image.width) / factor)));
  const int h = std::max(1, int(std::lround(double(image.height) / factor)));
  return resize_area(image, w, h);
}

IdMap read_id_map(const fs::path& file) {
  if (auto indexed = read_png_palette_indices(file)) return std::move(*indexed);
  auto in = open_input(file);
  const auto& spec = in->spec();
  if (spec.nchannels != 1)
    throw InputError(file,
                     fmt::format("ID map must be single-channel, has {} channels", spec.nchannels));
  const auto base = OIIO::TypeDesc::BASETYPE(spec.format.basetype);
  IdMap map(spec.width, spec.height);
  // Read in the file's own integer type: converting 8 to 16 bit through
  // OpenImageIO would rescale the IDs (255 -> 65535).
  if (base == OIIO::TypeDesc::UINT8) {
    const auto px = read_pixels<uint8_t>(*in, OIIO::TypeDesc::UINT8, file);
    std::copy(px.begin(), px.end(), map.ids.begin());
  } else if (base == OIIO::TypeDesc::UINT16) {
    map.ids = read_pixels<uint16_t>(*in, OIIO::TypeDesc::UINT16, file);
  } else {
    throw InputError(file, fmt::format("ID map must be 8- or 16-bit unsigned integers, is {}",
                                       spec.format.c_str()));
  }
  return map;
}

void write_id_map(const fs::path& file, const IdMap& map, int bits) {
  if (bits == 16) {
    OIIO::ImageSpec spec(map.width, map.height, 1, OIIO::TypeDesc::UINT16);
    write_with_oiio(file, spec, OIIO::TypeDesc::UINT16, map.ids.data());
    return;
  }
  if (bits != 8) throw std::invalid_argument("write_id_map: bits must be 8 or 16");
  std::vector<uint8_t> px(map.ids.size());
  for (size_t i = 0; i < px.size(); ++i) {
    if (map.ids[i] > 255)
      throw InputError(file, fmt::format("ID {} does not fit in an 8-bit ID map", map.ids[i]));
    px[i] = uint8_t(map.ids[i]);
  }
  OIIO::ImageSpec spec(map.width, map.height, 1, OIIO::TypeDesc::UINT8);
  write_with_oiio(file, spec, OIIO::TypeDesc::UINT8, px.data());
}

void write_mask_png(const fs::path& file, int width, int height,
                    const std::vector<uint8_t>& inside) {
  std::vector<uint8_t> px(inside.size());
  for (size_t i = 0; i < px.size(); ++i) px[i] = inside[i] ? 255 : 0;
  OIIO::ImageSpec spec(width, height, 1, OIIO::TypeDesc::UINT8);
  write_with_oiio(file, spec, OIIO::TypeDesc::UINT8, px.data());
}

}  // namespace splat
