#include "splat/packed_image.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "splat/image_codec.h"

namespace splat {
namespace {

// OpenImageIO decodes an 8-bit sample k as k * (1 / 255.f) (not k / 255.f,
// which differs in the last bit for about half the codes). Should a decoder
// round otherwise, pack() finds values that are not codes and keeps floats:
// never a changed pixel, only more memory.
const std::array<float, 256>& code_values() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int k = 0; k < 256; ++k) t[k] = float(k) * (1.f / 255.f);
    return t;
  }();
  return table;
}

// The code of v if v is exactly a code's value, else -1.
int code_of(float v, const std::array<float, 256>& table) {
  if (!(v >= 0.f && v <= 1.f)) return -1;
  const int k = int(std::lrint(v * 255.f));
  return table[size_t(k)] == v ? k : -1;
}

constexpr size_t kGrain = size_t(1) << 16;

}  // namespace

float code_value(uint8_t code) { return code_values()[code]; }

PackedImageRGB PackedImageRGB::pack(ImageRGB image) {
  PackedImageRGB p;
  p.width_ = image.width;
  p.height_ = image.height;
  const std::array<float, 256>& table = code_values();
  const size_t n = image.data.size();
  std::vector<uint8_t> codes(n);
  const float* v = image.data.data();
  const bool all_codes = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, n, kGrain), true,
      [&](const tbb::blocked_range<size_t>& r, bool ok) {
        for (size_t i = r.begin(); ok && i < r.end(); ++i) {
          const int k = code_of(v[i], table);
          ok = k >= 0;
          codes[i] = uint8_t(k);
        }
        return ok;
      },
      [](bool a, bool b) { return a && b; });
  if (all_codes)
    p.codes_ = std::move(codes);
  else
    p.floats_ = std::move(image);
  return p;
}

PackedImageRGB PackedImageRGB::from_codes(int width, int height, std::vector<uint8_t> codes) {
  if (codes.size() != size_t(3) * width * height)
    throw std::invalid_argument("PackedImageRGB::from_codes: size mismatch");
  PackedImageRGB p;
  p.width_ = width;
  p.height_ = height;
  p.codes_ = std::move(codes);
  return p;
}

PackedImageRGB read_packed_image_rgb(const std::filesystem::path& file) {
  ImageFileReader in(file);
  const ImageFileSpec& spec = in.spec();
  if (spec.type != SampleType::uint8 || spec.channels < 3)
    return PackedImageRGB::pack(read_image_rgb(file));
  std::vector<uint8_t> codes(size_t(3) * spec.width * spec.height);
  in.read(3, SampleType::uint8, codes.data());
  return PackedImageRGB::from_codes(spec.width, spec.height, std::move(codes));
}

void PackedImageRGB::unpack_into(ImageRGB& out) const {
  out.width = width_;
  out.height = height_;
  // On all cores, floats as codes: the trainer takes a view every iteration,
  // and a copy on one thread left the others waiting (6% of an early
  // iteration's time).
  const size_t n = codes_.empty() ? floats_.data.size() : codes_.size();
  out.data.resize(n);
  const std::array<float, 256>& table = code_values();
  float* to = out.data.data();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const auto& r) {
    if (codes_.empty())
      std::copy_n(floats_.data.data() + r.begin(), r.size(), to + r.begin());
    else
      for (size_t i = r.begin(); i < r.end(); ++i) to[i] = table[codes_[i]];
  });
}

ImageRGB PackedImageRGB::unpack() const {
  ImageRGB image;
  unpack_into(image);
  return image;
}

}  // namespace splat
