#include "splat/image_file.h"

#include "splat/atomic_file.h"

namespace splat {
namespace fs = std::filesystem;

std::unique_ptr<OIIO::ImageInput> open_image_input(const fs::path& file) {
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

void write_image_with_oiio(const fs::path& file, const OIIO::ImageSpec& spec,
                           OIIO::TypeDesc src_type, const void* pixels) {
  write_atomically(file, [&](const fs::path& tmp) {
    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out) throw InputError(file, "no image writer for this extension: " + OIIO::geterror());
    if (!out->open(tmp.string(), spec) || !out->write_image(src_type, pixels) || !out->close())
      throw InputError(file, "cannot write image: " + out->geterror());
  });
}

}  // namespace splat
