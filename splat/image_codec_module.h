#pragma once
// The table of functions the image codec module exports
// (image_codec_module.cc) and the core calls (image_codec.cc). Internal: the
// module and the core are built together, so C++ types may cross; errors come
// back as text, never as exceptions.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "splat/image_codec.h"

namespace splat {

struct ImageCodecModule {
  // Opens `file` and fills `spec`; null and `error` set when it cannot.
  void* (*open)(const char* file, ImageFileSpec* spec, std::string* error);
  bool (*read)(void* reader, int channels, SampleType type, void* pixels, std::string* error);
  void (*close)(void* reader);
  bool (*write)(const char* file, const ImageFileSpec& spec, SampleType pixel_type,
                const void* pixels, std::string* error);
  // 8-bit BGR rows, as OpenCV lays them out.
  bool (*encode_jpeg)(const uint8_t* bgr, int width, int height, int quality,
                      std::vector<uint8_t>* jpeg, std::string* error);
  bool (*decode_jpeg)(const uint8_t* jpeg, size_t size, std::vector<uint8_t>* bgr, int* width,
                      int* height, std::string* error);
};

}  // namespace splat

// The module's one exported symbol.
extern "C" const splat::ImageCodecModule* op2gs_image_codec_module();
