#pragma once
// Reading the safetensors format (Hugging Face): an 8-byte little-endian header
// length, a JSON header naming each tensor's dtype, shape and byte range, then
// the raw little-endian data. Tensors are read one at a time, so a 600 MB file
// never needs to sit in memory twice.

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace splat {

struct Tensor {
  std::vector<int64_t> shape;
  std::vector<float> values;  // C order
  int64_t dim(size_t i) const { return shape.at(i); }
};

class SafetensorsFile {
 public:
  // Reads and checks the header. Throws InputError naming the file when it is
  // missing, truncated, or its header is malformed.
  explicit SafetensorsFile(std::filesystem::path file);

  bool has(const std::string& name) const { return entries_.count(name) != 0; }
  std::vector<std::string> names() const;
  const std::vector<int64_t>& shape(const std::string& name) const;

  // The tensor as float32 (F32, F16 and BF16 are converted). Throws InputError
  // when the tensor is absent or has another dtype; with expected_shape, when
  // its shape differs.
  Tensor read(const std::string& name) const;
  Tensor read(const std::string& name, const std::vector<int64_t>& expected_shape) const;

  const std::filesystem::path& path() const { return file_; }

 private:
  struct Entry {
    std::string dtype;
    std::vector<int64_t> shape;
    uint64_t begin = 0, end = 0;  // byte range after the header
  };
  const Entry& entry(const std::string& name) const;

  std::filesystem::path file_;
  uint64_t data_start_ = 0;
  std::map<std::string, Entry> entries_;
};

// Writes float32 tensors in the safetensors layout, atomically (tests and
// benchmarks build model files with it).
void write_safetensors(const std::filesystem::path& file,
                       const std::map<std::string, Tensor>& tensors);

}  // namespace splat
