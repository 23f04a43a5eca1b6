#pragma once
// Image files (OpenImageIO) and JPEG bytes (OpenCV), through a codec module
// the core loads the first time a process reads or writes an image
// (image_codec_module.cc, built as its own shared module). Why: Debian's
// OpenImageIO brings about 260 shared libraries that cost every process
// 0.5 s to load, and most runs of a stage (--help, a refused input) and most
// unit tests touch no image.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "splat/image.h"

namespace splat {

// The sample types the readers and writers ask for; `other` is any type
// OpenImageIO stores that none of them asks for (32-bit integers, double).
enum class SampleType { uint8, uint16, half, float32, other };

// What an image file's header says.
struct ImageFileSpec {
  int width = 0, height = 0, channels = 0;
  SampleType type = SampleType::uint8;  // as stored
  int bits = 8;                         // per stored sample
  int orientation = 1;                  // EXIF orientation, 1 = as stored
  std::string type_name = "uint8";      // the stored type as OpenImageIO names it
};

// An open image file. Colour values are kept as stored: RGBA is not
// premultiplied by its alpha. Throws InputError naming the file when it is
// missing, unreadable or has no pixels.
class ImageFileReader {
 public:
  explicit ImageFileReader(const std::filesystem::path& file);
  ~ImageFileReader();
  ImageFileReader(const ImageFileReader&) = delete;
  ImageFileReader& operator=(const ImageFileReader&) = delete;

  const ImageFileSpec& spec() const { return spec_; }

  // The first `channels` channels of every pixel of the first subimage,
  // converted to `type` (integers rescaled to its range, as OpenImageIO
  // does), into `pixels`. Throws InputError naming the file.
  void read(int channels, SampleType type, void* pixels);

  // Every channel of every pixel, converted to `type` (T must match it).
  template <typename T>
  std::vector<T> read_all(SampleType type) {
    std::vector<T> pixels(size_t(spec_.width) * spec_.height * spec_.channels);
    read(spec_.channels, type, pixels.data());
    return pixels;
  }

 private:
  std::filesystem::path file_;
  void* reader_ = nullptr;
  ImageFileSpec spec_;
};

// Writes `pixels` (spec.width x spec.height x spec.channels of `pixel_type`)
// as a file of spec.type samples, atomically (a temporary name, then renamed
// into place). The extension picks the format; JPEG is written at quality 95.
void write_image_file(const std::filesystem::path& file, const ImageFileSpec& spec,
                      SampleType pixel_type, const void* pixels);

// An RGB image as JPEG bytes at `quality` (1-100), values rounded to 8 bits.
std::vector<uint8_t> encode_jpeg(const ImageRGB& image, int quality);

// JPEG bytes decoded to RGB in [0, 1]. Throws std::runtime_error when they
// are not a JPEG image.
ImageRGB decode_jpeg(const std::vector<uint8_t>& bytes);

}  // namespace splat
