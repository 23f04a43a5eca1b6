#include "splat/image_codec.h"

#include <dlfcn.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/image_codec_module.h"

namespace splat {
namespace fs = std::filesystem;

namespace {

// Where the module is: beside an installed executable (bin/ ->
// lib/op2gs/), else where this build put it.
std::vector<fs::path> module_candidates() {
  std::vector<fs::path> paths;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) paths.push_back(exe.parent_path() / ".." / "lib" / "op2gs" / OP2GS_IMAGE_CODEC_NAME);
  paths.emplace_back(OP2GS_IMAGE_CODEC_BUILD_PATH);
  return paths;
}

const ImageCodecModule& load_module() {
  std::string tried;
  for (const fs::path& path : module_candidates()) {
    if (!fs::exists(path)) {
      tried += fmt::format(" {} (missing)", path.string());
      continue;
    }
    void* library = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    const char* problem = dlerror();
    if (library) {
      const auto entry = reinterpret_cast<const ImageCodecModule* (*)()>(
          dlsym(library, "op2gs_image_codec_module"));
      if (entry) return *entry();
      problem = dlerror();
    }
    tried += fmt::format(" {} ({})", path.string(), problem ? problem : "no entry point");
  }
  throw std::runtime_error("cannot load op2gs's image codec module; tried" + tried);
}

// Loaded once per process, on first use; never unloaded.
const ImageCodecModule& codec() {
  static const ImageCodecModule& module = load_module();
  return module;
}

}  // namespace

ImageFileReader::ImageFileReader(const fs::path& file) : file_(file) {
  if (!fs::exists(file)) throw InputError(file, "file does not exist");
  std::string error;
  reader_ = codec().open(file.c_str(), &spec_, &error);
  if (!reader_) throw InputError(file, error);
  if (spec_.width <= 0 || spec_.height <= 0 || spec_.channels <= 0) {
    codec().close(reader_);
    throw InputError(file, "image has no pixels");
  }
}

ImageFileReader::~ImageFileReader() { codec().close(reader_); }

void ImageFileReader::read(int channels, SampleType type, void* pixels) {
  std::string error;
  if (!codec().read(reader_, channels, type, pixels, &error)) throw InputError(file_, error);
}

void write_image_file(const fs::path& file, const ImageFileSpec& spec, SampleType pixel_type,
                      const void* pixels) {
  const ImageCodecModule& module = codec();
  write_atomically(file, [&](const fs::path& tmp) {
    std::string error;
    if (!module.write(tmp.c_str(), spec, pixel_type, pixels, &error)) throw InputError(file, error);
  });
}

std::vector<uint8_t> encode_jpeg(const ImageRGB& image, int quality) {
  std::vector<uint8_t> bgr(size_t(3) * image.width * image.height);
  for (size_t p = 0; p < bgr.size(); p += 3)
    for (int c = 0; c < 3; ++c)
      bgr[p + 2 - c] = uint8_t(std::lround(255 * std::clamp(image.data[p + c], 0.f, 1.f)));
  std::vector<uint8_t> jpeg;
  std::string error;
  if (!codec().encode_jpeg(bgr.data(), image.width, image.height, quality, &jpeg, &error))
    throw std::runtime_error("encode_jpeg: " + error);
  return jpeg;
}

ImageRGB decode_jpeg(const std::vector<uint8_t>& bytes) {
  std::vector<uint8_t> bgr;
  int width = 0, height = 0;
  std::string error;
  if (!codec().decode_jpeg(bytes.data(), bytes.size(), &bgr, &width, &height, &error))
    throw std::runtime_error("decode_jpeg: " + error);
  ImageRGB image(width, height);
  for (size_t p = 0; p < bgr.size(); p += 3)
    for (int c = 0; c < 3; ++c) image.data[p + c] = bgr[p + 2 - c] / 255.f;
  return image;
}

}  // namespace splat
