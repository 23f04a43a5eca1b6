#include "splat/npy.h"

#include <charconv>
#include <cstring>
#include <regex>
#include <stdexcept>
#include <string>

#include "splat/atomic_file.h"
#include "splat/error.h"

namespace splat {

void write_npy_f64(const std::filesystem::path& file, const std::vector<double>& values,
                   const std::vector<size_t>& shape) {
  size_t count = 1;
  std::string dims;
  for (size_t d : shape) {
    count *= d;
    dims += std::to_string(d) + ", ";
  }
  if (count != values.size()) throw std::invalid_argument("write_npy_f64: shape does not match");
  if (shape.size() > 1) dims.resize(dims.size() - 2);
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" + dims + "), }";
  // Magic (6) + version (2) + length (2) + header + '\n' is a multiple of 64.
  const size_t total = 10 + header.size() + 1;
  header += std::string((64 - total % 64) % 64, ' ') + "\n";
  std::string out = "\x93NUMPY";
  out += char(1);
  out += char(0);
  const uint16_t len = uint16_t(header.size());
  out += char(len & 0xff);
  out += char(len >> 8);
  out += header;
  out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
  write_text_atomically(file, out);
}

std::vector<double> read_npy(const std::filesystem::path& file, std::vector<size_t>* shape) {
  const std::string bytes = read_text_file(file);
  if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0)
    throw InputError(file, "not a NumPy .npy file");
  const int major = uint8_t(bytes[6]);
  const size_t len_bytes = major == 1 ? 2 : 4;
  size_t header_len = 0;
  for (size_t k = 0; k < len_bytes; ++k) header_len |= size_t(uint8_t(bytes[8 + k])) << (8 * k);
  const size_t start = 8 + len_bytes + header_len;
  if (start > bytes.size()) throw InputError(file, "truncated .npy header");
  const std::string header = bytes.substr(8 + len_bytes, header_len);
  std::smatch m;
  if (!std::regex_search(header, m, std::regex("'descr':\\s*'([<|=]f[48])'")))
    throw InputError(file, "only little-endian float64 or float32 arrays are read");
  const bool f8 = m[1].str().back() == '8';
  if (std::regex_search(header, std::regex("'fortran_order':\\s*True")))
    throw InputError(file, "Fortran-order arrays are not read");
  if (!std::regex_search(header, m, std::regex("'shape':\\s*\\(([^)]*)\\)")))
    throw InputError(file, "no shape in the .npy header");
  std::vector<size_t> dims;
  size_t count = 1;
  const std::string list = m[1].str();
  const std::regex number("\\d+");
  const size_t available = bytes.size() - start;
  for (std::sregex_iterator it(list.begin(), list.end(), number), end; it != end; ++it) {
    const std::string digits = it->str();
    size_t d = 0;
    if (std::from_chars(digits.data(), digits.data() + digits.size(), d).ec != std::errc())
      throw InputError(file, "a dimension of the .npy shape is out of range: " + digits);
    // count * d values cannot fit when count exceeds the bytes left over d.
    if (d != 0 && count > available / d)
      throw InputError(file, "the .npy shape holds more values than the file has bytes");
    dims.push_back(d);
    count *= d;
  }
  const size_t width = f8 ? 8 : 4;
  if (bytes.size() - start < count * width) throw InputError(file, "truncated .npy data");
  std::vector<double> values(count);
  for (size_t i = 0; i < count; ++i) {
    if (f8) {
      std::memcpy(&values[i], bytes.data() + start + 8 * i, 8);
    } else {
      float f;
      std::memcpy(&f, bytes.data() + start + 4 * i, 4);
      values[i] = f;
    }
  }
  if (shape) *shape = dims;
  return values;
}

}  // namespace splat
