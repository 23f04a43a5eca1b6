#include "eval/synthetic/npy.h"

#include <stdexcept>
#include <string>

#include "splat/atomic_file.h"

namespace synth {

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
  splat::write_text_atomically(file, out);
}

}  // namespace synth
