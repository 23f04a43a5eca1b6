#pragma once
// Little helpers for the checkpoint format: plain values and vectors in the
// machine's byte order, with short reads turned into exceptions.

#include <cstdint>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <vector>

namespace splat {

template <typename T>
void write_pod(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <typename T>
T read_pod(std::istream& in) {
  T v;
  if (!in.read(reinterpret_cast<char*>(&v), sizeof(T))) throw std::runtime_error("truncated");
  return v;
}

template <typename T>
void write_vector(std::ostream& out, const std::vector<T>& v) {
  write_pod(out, uint64_t(v.size()));
  out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(T)));
}

template <typename T>
std::vector<T> read_vector(std::istream& in, uint64_t max_elements = uint64_t(1) << 34) {
  const uint64_t n = read_pod<uint64_t>(in);
  if (n > max_elements) throw std::runtime_error("implausible array size");
  // A lying size is refused before it is allocated, where the stream knows
  // how much it holds.
  if (const std::streampos here = in.tellg(); here != std::streampos(-1)) {
    in.seekg(0, std::ios::end);
    const std::streamoff left = in.tellg() - here;
    in.seekg(here);
    if (left < 0 || uint64_t(left) / sizeof(T) < n) throw std::runtime_error("truncated");
  }
  std::vector<T> v(n);
  if (!in.read(reinterpret_cast<char*>(v.data()), std::streamsize(n * sizeof(T))))
    throw std::runtime_error("truncated");
  return v;
}

}  // namespace splat
