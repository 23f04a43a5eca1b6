// The image codec module: OpenImageIO for image files, OpenCV for JPEG bytes.
// Built as a shared module of its own and loaded on first use
// (image_codec.h says why); it links nothing of op2gs.

#include "splat/image_codec_module.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <opencv2/imgcodecs.hpp>
#include <string>

namespace splat {
namespace {

OIIO::TypeDesc to_oiio(SampleType type) {
  switch (type) {
    case SampleType::uint8:
      return OIIO::TypeDesc::UINT8;
    case SampleType::uint16:
      return OIIO::TypeDesc::UINT16;
    case SampleType::half:
      return OIIO::TypeDesc::HALF;
    case SampleType::float32:
      return OIIO::TypeDesc::FLOAT;
    case SampleType::other:
      break;
  }
  return OIIO::TypeDesc::UNKNOWN;
}

SampleType from_oiio(OIIO::TypeDesc type) {
  switch (OIIO::TypeDesc::BASETYPE(type.basetype)) {
    case OIIO::TypeDesc::UINT8:
      return SampleType::uint8;
    case OIIO::TypeDesc::UINT16:
      return SampleType::uint16;
    case OIIO::TypeDesc::HALF:
      return SampleType::half;
    case OIIO::TypeDesc::FLOAT:
      return SampleType::float32;
    default:
      return SampleType::other;
  }
}

void* open_image(const char* file, ImageFileSpec* spec, std::string* error) {
  // Keep colour values as stored: without this, PNG RGBA is premultiplied.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(file, &config);
  if (!in) {
    *error = "cannot read image: " + OIIO::geterror();
    return nullptr;
  }
  const OIIO::ImageSpec& s = in->spec();
  spec->width = s.width;
  spec->height = s.height;
  spec->channels = s.nchannels;
  spec->type = from_oiio(s.format);
  spec->bits = int(s.format.size() * 8);
  spec->orientation = s.get_int_attribute("Orientation", 1);
  spec->type_name = s.format.c_str();
  return in.release();
}

bool read_image(void* reader, int channels, SampleType type, void* pixels, std::string* error) {
  auto* in = static_cast<OIIO::ImageInput*>(reader);
  if (in->read_image(0, 0, 0, channels, to_oiio(type), pixels)) return true;
  *error = "cannot decode image: " + in->geterror();
  return false;
}

void close_image(void* reader) { delete static_cast<OIIO::ImageInput*>(reader); }

bool write_image(const char* file, const ImageFileSpec& spec, SampleType pixel_type,
                 const void* pixels, std::string* error) {
  OIIO::ImageSpec s(spec.width, spec.height, spec.channels, to_oiio(spec.type));
  std::string ext = std::filesystem::path(file).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (ext == ".jpg" || ext == ".jpeg") s.attribute("Compression", "jpeg:95");
  auto out = OIIO::ImageOutput::create(file);
  if (!out) {
    *error = "no image writer for this extension: " + OIIO::geterror();
    return false;
  }
  if (out->open(file, s) && out->write_image(to_oiio(pixel_type), pixels) && out->close())
    return true;
  *error = "cannot write image: " + out->geterror();
  return false;
}

bool encode_jpeg(const uint8_t* bgr, int width, int height, int quality, std::vector<uint8_t>* jpeg,
                 std::string* error) {
  const cv::Mat image(height, width, CV_8UC3, const_cast<uint8_t*>(bgr));
  if (cv::imencode(".jpg", image, *jpeg, {cv::IMWRITE_JPEG_QUALITY, quality})) return true;
  *error = "OpenCV could not encode the JPEG";
  return false;
}

bool decode_jpeg(const uint8_t* jpeg, size_t size, std::vector<uint8_t>* bgr, int* width,
                 int* height, std::string* error) {
  const cv::Mat bytes(1, int(size), CV_8UC1, const_cast<uint8_t*>(jpeg));
  const cv::Mat image = cv::imdecode(bytes, cv::IMREAD_COLOR);
  if (image.empty()) {
    *error = "not a JPEG image";
    return false;
  }
  *width = image.cols;
  *height = image.rows;
  bgr->assign(image.datastart, image.dataend);
  return true;
}

constexpr ImageCodecModule kModule{open_image,  read_image,  close_image,
                                   write_image, encode_jpeg, decode_jpeg};

}  // namespace
}  // namespace splat

extern "C" __attribute__((visibility("default"))) const splat::ImageCodecModule*
op2gs_image_codec_module() {
  return &splat::kModule;
}
