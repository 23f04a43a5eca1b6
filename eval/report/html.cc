#include "eval/report/html.h"

#include "splat/atomic_file.h"
#include "splat/image_codec.h"

namespace eval {

std::string html_escape(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string base64(std::string_view bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) v |= uint8_t(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[v & 63] : '=';
  }
  return out;
}

std::string jpeg_data_uri(const splat::ImageRGB& image) {
  const std::vector<uint8_t> jpeg = splat::encode_jpeg(image, 90);
  return "data:image/jpeg;base64," +
         base64(std::string_view(reinterpret_cast<const char*>(jpeg.data()), jpeg.size()));
}

std::string file_data_uri(const std::string& file, const std::string& mime) {
  return "data:" + mime + ";base64," + base64(splat::read_text_file(file));
}

}  // namespace eval
