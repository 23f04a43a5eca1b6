#include "splat/clip/safetensors.h"

#include <fmt/format.h>

#include <bit>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/error.h"

namespace splat {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

static_assert(std::endian::native == std::endian::little, "safetensors data is little-endian");

size_t element_size(const std::string& dtype) {
  if (dtype == "F32") return 4;
  if (dtype == "F16" || dtype == "BF16") return 2;
  return 0;  // not a floating-point dtype this reader converts
}

float half_to_float(uint16_t h) {
  const uint32_t sign = uint32_t(h & 0x8000) << 16;
  uint32_t exponent = (h >> 10) & 0x1f, mantissa = h & 0x3ff, bits;
  if (exponent == 0x1f) {
    bits = sign | 0x7f800000u | (mantissa << 13);  // inf or NaN
  } else if (exponent == 0) {
    if (mantissa == 0) {
      bits = sign;
    } else {  // subnormal: normalise
      exponent = 127 - 15 + 1;
      while (!(mantissa & 0x400)) mantissa <<= 1, --exponent;
      bits = sign | (exponent << 23) | ((mantissa & 0x3ff) << 13);
    }
  } else {
    bits = sign | ((exponent + 127 - 15) << 23) | (mantissa << 13);
  }
  return std::bit_cast<float>(bits);
}

std::string shape_text(const std::vector<int64_t>& shape) {
  return fmt::format("[{}]", fmt::join(shape, ", "));
}

}  // namespace

SafetensorsFile::SafetensorsFile(fs::path file) : file_(std::move(file)) {
  std::ifstream in(file_, std::ios::binary);
  if (!in) throw InputError(file_, "cannot open the file");
  const uint64_t file_size = fs::file_size(file_);
  uint64_t header_size = 0;
  if (!in.read(reinterpret_cast<char*>(&header_size), 8) || header_size > file_size - 8)
    throw InputError(file_, "not a safetensors file (bad header length)");
  std::string text(header_size, '\0');
  in.read(text.data(), std::streamsize(header_size));
  data_start_ = 8 + header_size;
  json header;
  try {
    header = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(file_, std::string("malformed safetensors header: ") + e.what());
  }
  for (const auto& [name, value] : header.items()) {
    if (name == "__metadata__") continue;
    try {
      Entry e;
      e.dtype = value.at("dtype").get<std::string>();
      e.shape = value.at("shape").get<std::vector<int64_t>>();
      const auto offsets = value.at("data_offsets").get<std::vector<uint64_t>>();
      if (offsets.size() != 2 || offsets[0] > offsets[1]) throw std::runtime_error("bad offsets");
      e.begin = offsets[0], e.end = offsets[1];
      if (data_start_ + e.end > file_size)
        throw InputError(file_, fmt::format("truncated: tensor {} ends past the file's end", name));
      entries_.emplace(name, std::move(e));
    } catch (const json::exception& e) {
      throw InputError(file_, fmt::format("malformed header entry {}: {}", name, e.what()));
    } catch (const std::runtime_error& e) {
      if (dynamic_cast<const InputError*>(&e)) throw;
      throw InputError(file_, fmt::format("malformed header entry {}: {}", name, e.what()));
    }
  }
}

std::vector<std::string> SafetensorsFile::names() const {
  std::vector<std::string> names;
  for (const auto& [name, e] : entries_) names.push_back(name);
  return names;
}

const SafetensorsFile::Entry& SafetensorsFile::entry(const std::string& name) const {
  const auto it = entries_.find(name);
  if (it == entries_.end()) throw InputError(file_, fmt::format("no tensor named {}", name));
  return it->second;
}

const std::vector<int64_t>& SafetensorsFile::shape(const std::string& name) const {
  return entry(name).shape;
}

Tensor SafetensorsFile::read(const std::string& name) const {
  const Entry& e = entry(name);
  const size_t bytes_per = element_size(e.dtype);
  if (!bytes_per)
    throw InputError(file_,
                     fmt::format("tensor {} has dtype {}, not F32, F16 or BF16", name, e.dtype));
  uint64_t count = 1;
  for (int64_t d : e.shape) count *= uint64_t(d);
  if (count * bytes_per != e.end - e.begin)
    throw InputError(file_, fmt::format("tensor {}: shape {} does not match its byte range", name,
                                        shape_text(e.shape)));
  std::string raw(e.end - e.begin, '\0');
  std::ifstream in(file_, std::ios::binary);
  in.seekg(std::streamoff(data_start_ + e.begin));
  if (!in.read(raw.data(), std::streamsize(raw.size())))
    throw InputError(file_, fmt::format("cannot read tensor {}", name));
  Tensor t;
  t.shape = e.shape;
  t.values.resize(count);
  if (e.dtype == "F32") {
    std::memcpy(t.values.data(), raw.data(), raw.size());
  } else {
    for (size_t i = 0; i < count; ++i) {
      uint16_t h;
      std::memcpy(&h, raw.data() + 2 * i, 2);
      t.values[i] = e.dtype == "F16" ? half_to_float(h) : std::bit_cast<float>(uint32_t(h) << 16);
    }
  }
  return t;
}

Tensor SafetensorsFile::read(const std::string& name,
                             const std::vector<int64_t>& expected_shape) const {
  if (entry(name).shape != expected_shape)
    throw InputError(file_, fmt::format("tensor {} has shape {}, expected {}", name,
                                        shape_text(entry(name).shape), shape_text(expected_shape)));
  return read(name);
}

void write_safetensors(const fs::path& file, const std::map<std::string, Tensor>& tensors) {
  json header = json::object();
  uint64_t offset = 0;
  for (const auto& [name, t] : tensors) {
    const uint64_t bytes = 4 * t.values.size();
    header[name] = {
        {"dtype", "F32"}, {"shape", t.shape}, {"data_offsets", {offset, offset + bytes}}};
    offset += bytes;
  }
  std::string text = header.dump();
  text.append((8 - text.size() % 8) % 8, ' ');
  write_atomically(file, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    const uint64_t size = text.size();
    out.write(reinterpret_cast<const char*>(&size), 8);
    out.write(text.data(), std::streamsize(text.size()));
    for (const auto& [name, t] : tensors)
      out.write(reinterpret_cast<const char*>(t.values.data()),
                std::streamsize(4 * t.values.size()));
    if (!out) throw std::runtime_error(fmt::format("cannot write {}", tmp.string()));
  });
}

}  // namespace splat
