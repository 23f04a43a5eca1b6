#pragma once
// Binary files, read and written with bounds checks. Every binary reader uses
// these rather than its own:
//   - read_pod / read_vector (and their writers): plain values and vectors in
//     the machine's byte order from a stream, short reads as exceptions (the
//     checkpoint format);
//   - BinaryReader / BinaryWriter: little-endian records of a whole file held
//     in memory (COLMAP's .bin model files), a truncated or corrupt file as an
//     InputError naming it and the byte.

#include <fmt/format.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "splat/error.h"

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

// Reads values from a whole file's bytes, with bounds checks that turn
// truncation into an InputError instead of a crash.
class BinaryReader {
 public:
  BinaryReader(std::filesystem::path file, std::string bytes)
      : file_(std::move(file)), data_(std::move(bytes)) {}

  template <typename T>
  T read() {
    need(sizeof(T));
    T value;
    std::memcpy(&value, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  // A zero-terminated string; `what` names it in the error.
  std::string read_cstring(const char* what) {
    const size_t end = data_.find('\0', pos_);
    if (end == std::string::npos) fail(std::string("unterminated ") + what);
    std::string s = data_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return s;
  }
  // A count of records of at least min_record_bytes each: counts that cannot
  // fit in the rest of the file are refused before anything is allocated.
  uint64_t read_count(size_t min_record_bytes) {
    const uint64_t n = read<uint64_t>();
    if (min_record_bytes > 0 && n > (data_.size() - pos_) / min_record_bytes)
      fail(fmt::format("count {} does not fit in the file (truncated or corrupt)", n));
    return n;
  }
  void expect_end() {
    if (pos_ != data_.size())
      fail(fmt::format("{} unexpected trailing bytes", data_.size() - pos_));
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(file_, fmt::format("{} (at byte {})", what, pos_));
  }

 private:
  void need(size_t n) {
    if (data_.size() - pos_ < n) fail("file is truncated");
  }
  std::filesystem::path file_;
  std::string data_;
  size_t pos_ = 0;
};

// Collects values as bytes, to be written in one piece.
class BinaryWriter {
 public:
  template <typename T>
  void write(T value) {
    buffer_.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  void write_cstring(const std::string& s) { buffer_.append(s.c_str(), s.size() + 1); }
  const std::string& bytes() const { return buffer_; }

 private:
  std::string buffer_;
};

}  // namespace splat
