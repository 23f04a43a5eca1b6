#include "splat/png_indexed.h"

#include <fmt/format.h>
#include <png.h>

#include <algorithm>
#include <cctype>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "splat/error.h"

namespace splat {
namespace fs = std::filesystem;

namespace {

// Everything libpng touches lives on the heap, in one object: libpng reports
// errors with longjmp, after which automatic variables changed since setjmp
// would hold indeterminate values.
struct PngReadState {
  FILE* file = nullptr;
  png_structp png = nullptr;
  png_infop info = nullptr;
  std::string error;
  std::vector<png_byte> indices;
  std::vector<png_bytep> rows;

  ~PngReadState() {
    if (png) png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
    if (file) std::fclose(file);
  }
};

void on_png_error(png_structp png, png_const_charp message) {
  static_cast<PngReadState*>(png_get_error_ptr(png))->error = message;
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

bool has_png_signature(FILE* file) {
  png_byte signature[8];
  return std::fread(signature, 1, 8, file) == 8 && png_sig_cmp(signature, 0, 8) == 0;
}

uint32_t big_endian(const png_byte* b) {
  return uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | b[3];
}

// A chunk's four-letter type, printable whatever the file holds.
std::string chunk_name(const png_byte* type) {
  std::string name(reinterpret_cast<const char*>(type), 4);
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '?';
  return name;
}

// Walks the chunk list after the signature: a chunk that claims more bytes
// than the file has left would have libpng allocate that much (gigabytes,
// from a few hundred bytes of file) before it finds the file cut short.
void check_chunk_lengths(FILE* file, const fs::path& path) {
  const long start = std::ftell(file);
  std::fseek(file, 0, SEEK_END);
  const long end = std::ftell(file);
  std::fseek(file, start, SEEK_SET);
  png_byte header[8];
  while (std::fread(header, 1, 8, file) == 8) {
    const uint64_t length = big_endian(header);
    const long at = std::ftell(file);
    if (uint64_t(end - at) < length + 4)
      throw InputError(path,
                       fmt::format("PNG chunk '{}' claims {} bytes, the file has {} left",
                                   chunk_name(header + 4), length, std::max(0L, end - at - 4)));
    if (std::memcmp(header + 4, "IEND", 4) == 0) break;
    std::fseek(file, long(length) + 4, SEEK_CUR);
  }
  std::fseek(file, start, SEEK_SET);
}

}  // namespace

std::optional<IdMap> read_png_palette_indices(const fs::path& file) {
  const auto state = std::make_unique<PngReadState>();
  PngReadState& s = *state;
  s.file = std::fopen(file.c_str(), "rb");
  if (!s.file || !has_png_signature(s.file)) return std::nullopt;
  check_chunk_lengths(s.file, file);
  s.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &s, on_png_error, on_png_warning);
  if (!s.png) throw std::bad_alloc();
  s.info = png_create_info_struct(s.png);
  if (!s.info) throw std::bad_alloc();
  if (setjmp(png_jmpbuf(s.png))) throw InputError(file, "cannot decode PNG: " + s.error);

  png_init_io(s.png, s.file);
  png_set_sig_bytes(s.png, 8);
  png_read_info(s.png, s.info);
  if (png_get_color_type(s.png, s.info) != PNG_COLOR_TYPE_PALETTE) return std::nullopt;
  png_set_packing(s.png);  // 1, 2 and 4-bit indices to one byte each
  png_set_interlace_handling(s.png);
  png_read_update_info(s.png, s.info);
  const int width = int(png_get_image_width(s.png, s.info));
  const int height = int(png_get_image_height(s.png, s.info));
  if (png_get_rowbytes(s.png, s.info) != size_t(width))
    throw InputError(file, "unexpected row size in a palette PNG");

  s.indices.resize(size_t(width) * height);
  s.rows.resize(size_t(height));
  for (int y = 0; y < height; ++y) s.rows[y] = s.indices.data() + size_t(y) * width;
  png_read_image(s.png, s.rows.data());
  png_read_end(s.png, nullptr);

  IdMap map(width, height);
  std::copy(s.indices.begin(), s.indices.end(), map.ids.begin());
  return map;
}

}  // namespace splat
