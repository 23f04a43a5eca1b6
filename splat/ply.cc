// One format, both directions: the 3DGS PLY (binary little-endian, the
// reference's property names, op2gs's label and instance opacity beside
// them) read with every check a user's file needs and written back. Kept in
// one file, as COLMAP keeps its model I/O, so that the reader and the writer
// cannot drift apart.
#include "splat/ply.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "splat/atomic_file.h"
#include "splat/error.h"

namespace splat {
namespace fs = std::filesystem;

namespace {

enum class PlyType { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat32, kFloat64 };

std::optional<PlyType> parse_type(const std::string& s) {
  static const std::map<std::string, PlyType> types = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUInt8},
      {"uint8", PlyType::kUInt8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUInt16},  {"uint16", PlyType::kUInt16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUInt32},     {"uint32", PlyType::kUInt32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  auto it = types.find(s);
  if (it == types.end()) return std::nullopt;
  return it->second;
}

size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUInt8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUInt16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUInt32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

double read_binary_value(const char* p, PlyType t) {
  auto get = [p](auto v) {
    std::memcpy(&v, p, sizeof(v));
    return double(v);
  };
  switch (t) {
    case PlyType::kInt8:
      return get(int8_t{});
    case PlyType::kUInt8:
      return get(uint8_t{});
    case PlyType::kInt16:
      return get(int16_t{});
    case PlyType::kUInt16:
      return get(uint16_t{});
    case PlyType::kInt32:
      return get(int32_t{});
    case PlyType::kUInt32:
      return get(uint32_t{});
    case PlyType::kFloat32:
      return get(float{});
    case PlyType::kFloat64:
      return get(double{});
  }
  return 0;
}

struct PlyProperty {
  std::string name;
  PlyType type;
  bool is_list = false;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
  size_t stride() const {
    size_t s = 0;
    for (const auto& p : properties) s += type_size(p.type);
    return s;
  }
  bool has_list() const {
    for (const auto& p : properties)
      if (p.is_list) return true;
    return false;
  }
};

struct PlyHeader {
  bool binary = true;
  std::vector<PlyElement> elements;
};

PlyHeader read_header(std::istream& in, const fs::path& file) {
  std::string line;
  if (!std::getline(in, line) || (line != "ply" && line != "ply\r"))
    throw InputError(file, "not a PLY file (no 'ply' magic line)");
  PlyHeader h;
  bool have_format = false;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ss(line);
    std::string key;
    ss >> key;
    auto bad = [&](const std::string& what) {
      throw InputError(file, fmt::format("header line {}: {} in '{}'", line_number, what, line));
    };
    if (key == "end_header") {
      if (!have_format) bad("missing 'format' line");
      return h;
    } else if (key == "format") {
      std::string fmt_name, version;
      ss >> fmt_name >> version;
      if (fmt_name == "binary_little_endian")
        h.binary = true;
      else if (fmt_name == "ascii")
        h.binary = false;
      else if (fmt_name == "binary_big_endian")
        bad("big-endian PLY is not supported");
      else
        bad("unknown format");
      have_format = true;
    } else if (key == "element") {
      PlyElement e;
      if (!(ss >> e.name >> e.count)) bad("malformed element");
      h.elements.push_back(e);
    } else if (key == "property") {
      if (h.elements.empty()) bad("property before any element");
      std::string type_name, name;
      ss >> type_name;
      PlyProperty p;
      if (type_name == "list") {
        std::string count_type, item_type;
        ss >> count_type >> item_type >> name;
        p.is_list = true;
        p.type = parse_type(item_type).value_or(PlyType::kUInt8);
      } else {
        const auto t = parse_type(type_name);
        if (!t) bad("unknown property type");
        ss >> name;
        p.type = *t;
      }
      if (name.empty()) bad("property without a name");
      p.name = name;
      h.elements.back().properties.push_back(p);
    } else if (key != "comment" && key != "obj_info" && !key.empty()) {
      bad("unknown header keyword");
    }
  }
  throw InputError(file, "header has no 'end_header' (truncated file?)");
}

// Where each model parameter comes from in a vertex row: property indices.
struct VertexLayout {
  int xyz[3], dc[3], opacity, scale[3], rot[4];
  std::vector<int> rest;  // channel-major, 3 * coeffs entries
  int rest_coeffs = 0;
  int instance_opacity = -1, label = -1;
};

VertexLayout layout_of(const PlyElement& v, const fs::path& file) {
  std::map<std::string, int> index;
  for (size_t i = 0; i < v.properties.size(); ++i) index[v.properties[i].name] = int(i);
  auto need = [&](const std::string& name) {
    auto it = index.find(name);
    if (it == index.end())
      throw InputError(file, fmt::format("not a 3DGS PLY: vertex property '{}' is missing", name));
    return it->second;
  };
  VertexLayout l;
  const char* axes = "xyz";
  for (int k = 0; k < 3; ++k) l.xyz[k] = need(std::string(1, axes[k]));
  for (int k = 0; k < 3; ++k) l.dc[k] = need(fmt::format("f_dc_{}", k));
  for (int k = 0; k < 3; ++k) l.scale[k] = need(fmt::format("scale_{}", k));
  for (int k = 0; k < 4; ++k) l.rot[k] = need(fmt::format("rot_{}", k));
  l.opacity = need("opacity");
  int n_rest = 0;
  while (index.count(fmt::format("f_rest_{}", n_rest))) ++n_rest;
  if (n_rest % 3 != 0 || n_rest > kShRestFloats ||
      (n_rest != 0 && n_rest != 9 && n_rest != 24 && n_rest != 45))
    throw InputError(file, fmt::format("{} f_rest properties do not match an SH degree 0..3 "
                                       "(0, 9, 24 or 45)",
                                       n_rest));
  for (int k = 0; k < n_rest; ++k) l.rest.push_back(index[fmt::format("f_rest_{}", k)]);
  l.rest_coeffs = n_rest / 3;
  if (index.count("instance_opacity")) l.instance_opacity = index["instance_opacity"];
  if (index.count("label")) l.label = index["label"];
  return l;
}

// A label stored as a float must still be a whole number an int32 holds:
// anything else is not an object ID (and its conversion would be undefined).
int32_t label_of(double value, size_t vertex, const fs::path& file) {
  if (!(value == std::floor(value) && value >= std::numeric_limits<int32_t>::min() &&
        value <= std::numeric_limits<int32_t>::max()))
    throw InputError(file,
                     fmt::format("vertex {}: label {} is not an integer object ID", vertex, value));
  return int32_t(value);
}

// Copies vertex i's row (values already decoded to doubles) into the model.
void store_row(const std::vector<double>& row, const VertexLayout& l, size_t i,
               const fs::path& file, GaussianModel& m) {
  for (int k = 0; k < 3; ++k) {
    m.means[3 * i + k] = float(row[l.xyz[k]]);
    m.sh_dc[3 * i + k] = float(row[l.dc[k]]);
    m.log_scales[3 * i + k] = float(row[l.scale[k]]);
  }
  for (int k = 0; k < 4; ++k) m.rotations[4 * i + k] = float(row[l.rot[k]]);
  m.opacity_logits[i] = float(row[l.opacity]);
  for (int c = 0; c < 3; ++c)
    for (int j = 0; j < l.rest_coeffs; ++j)
      m.sh_rest[kShRestFloats * i + 3 * j + c] = float(row[l.rest[c * l.rest_coeffs + j]]);
  if (l.instance_opacity >= 0) m.instance_opacity_logits[i] = float(row[l.instance_opacity]);
  if (l.label >= 0) m.labels[i] = label_of(row[l.label], i, file);
}

// The bytes from the read position to the end of the file.
uint64_t bytes_left(std::istream& in) {
  const auto here = in.tellg();
  in.seekg(0, std::ios::end);
  const auto left = uint64_t(in.tellg() - here);
  in.seekg(here);
  return left;
}

void skip_binary_element(std::istream& in, const PlyElement& e, const fs::path& file) {
  if (e.has_list())
    throw InputError(file, fmt::format("element '{}' before 'vertex' has list properties "
                                       "(unsupported)",
                                       e.name));
  // A count past the bytes that follow is a lie, and its product may overflow.
  const size_t stride = e.stride();
  if (stride > 0 && bytes_left(in) / stride < e.count)
    throw InputError(file, fmt::format("truncated in element '{}'", e.name));
  in.seekg(std::streamoff(e.count * stride), std::ios::cur);
}

// ASCII rows of an element before the vertex element, one line each.
void skip_ascii_element(std::istream& in, const PlyElement& e, const fs::path& file) {
  for (uint64_t i = 0; i < e.count; ++i) {
    if (in.peek() == std::char_traits<char>::eof())
      throw InputError(file, fmt::format("truncated in element '{}'", e.name));
    in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
}

// Each decoded row of a vertex element, with its index.
using RowSink = std::function<void(const std::vector<double>& row, size_t i)>;

void read_binary_vertices(std::istream& in, const PlyElement& v, const RowSink& store,
                          const fs::path& file) {
  const size_t stride = v.stride();
  std::vector<size_t> offsets;
  size_t off = 0;
  for (const auto& p : v.properties) {
    offsets.push_back(off);
    off += type_size(p.type);
  }
  constexpr size_t kChunk = 65536;
  std::vector<char> buffer;
  std::vector<double> row(v.properties.size());
  for (size_t start = 0; start < v.count; start += kChunk) {
    const size_t n = std::min<size_t>(kChunk, v.count - start);
    buffer.resize(n * stride);
    in.read(buffer.data(), std::streamsize(buffer.size()));
    if (size_t(in.gcount()) != buffer.size())
      throw InputError(file, fmt::format("file is truncated: header says {} vertices, data ends "
                                         "in vertex {}",
                                         v.count, start + in.gcount() / stride));
    for (size_t r = 0; r < n; ++r) {
      const char* p = buffer.data() + r * stride;
      for (size_t k = 0; k < row.size(); ++k)
        row[k] = read_binary_value(p + offsets[k], v.properties[k].type);
      store(row, start + r);
    }
  }
}

// ASCII: elements before the vertex element are skipped line by line.
void read_ascii_vertices(std::istream& in, const PlyElement& v, const RowSink& store,
                         const fs::path& file) {
  std::vector<double> row(v.properties.size());
  std::string line;
  for (size_t i = 0; i < v.count; ++i) {
    if (!std::getline(in, line))
      throw InputError(
          file, fmt::format("file is truncated: header says {} vertices, found {}", v.count, i));
    const char* p = line.data();
    const char* end = line.data() + line.size();
    for (size_t k = 0; k < row.size(); ++k) {
      while (p < end && (*p == ' ' || *p == '\t')) ++p;
      const auto [next, ec] = std::from_chars(p, end, row[k]);
      if (ec != std::errc())
        throw InputError(
            file, fmt::format("vertex {}: property '{}' is not a number", i, v.properties[k].name));
      p = next;
    }
    store(row, i);
  }
}

// Reads the header and finds the vertex element; `prepare` sees it first and
// returns the sink its rows go to.
void read_vertices(const fs::path& file,
                   const std::function<RowSink(const PlyElement& vertex)>& prepare) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "cannot open file");
  const PlyHeader h = read_header(in, file);
  for (const PlyElement& e : h.elements) {
    if (e.name != "vertex") {
      if (h.binary)
        skip_binary_element(in, e, file);
      else
        skip_ascii_element(in, e, file);
      continue;
    }
    if (e.properties.empty()) throw InputError(file, "the vertex element has no properties");
    for (const PlyProperty& p : e.properties)
      if (p.is_list) throw InputError(file, fmt::format("vertex property '{}' is a list", p.name));
    if (e.count > 0) {
      // Reject a lying vertex count before allocating for it: a binary row
      // takes its stride, an ASCII row at least a character and a separator
      // per property.
      const uint64_t available = bytes_left(in);
      const size_t row = h.binary ? e.stride() : 2 * e.properties.size();
      if (available / row < e.count)
        throw InputError(file, fmt::format("file is truncated: header says {} vertices of {} "
                                           "{}bytes, {} bytes follow the header",
                                           e.count, row, h.binary ? "" : "or more ", available));
    }
    const RowSink store = prepare(e);
    if (h.binary)
      read_binary_vertices(in, e, store, file);
    else
      read_ascii_vertices(in, e, store, file);
    return;
  }
  throw InputError(file, "PLY has no 'vertex' element");
}

}  // namespace

GaussianModel read_gaussian_ply(const fs::path& file) {
  GaussianModel m;
  size_t bad = 0, first_bad = 0;  // Gaussians with a NaN or infinite parameter
  read_vertices(file, [&](const PlyElement& e) -> RowSink {
    const VertexLayout l = layout_of(e, file);
    m.resize(e.count);
    m.has_instance_opacity = l.instance_opacity >= 0;
    m.has_labels = l.label >= 0;
    return [&, l](const std::vector<double>& row, size_t i) {
      if (!std::all_of(row.begin(), row.end(), [](double v) { return std::isfinite(v); }))
        first_bad = bad++ ? first_bad : i;
      store_row(row, l, i, file, m);
    };
  });
  // A broken model must not be voted on or rendered as if nothing were wrong.
  if (bad)
    throw InputError(file, fmt::format("{} of {} Gaussians have NaN or infinite parameters (the "
                                       "first: vertex {})",
                                       bad, m.size(), first_bad));
  return m;
}

PointCloud read_point_ply(const fs::path& file) {
  PointCloud cloud;
  size_t bad = 0;  // points with a NaN or infinite coordinate or colour
  read_vertices(file, [&](const PlyElement& e) -> RowSink {
    std::map<std::string, int> index;
    for (size_t i = 0; i < e.properties.size(); ++i) index[e.properties[i].name] = int(i);
    auto find = [&](std::initializer_list<const char*> names) {
      for (const char* n : names)
        if (const auto it = index.find(n); it != index.end()) return it->second;
      return -1;
    };
    const int xyz[3] = {find({"x"}), find({"y"}), find({"z"})};
    if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)
      throw InputError(file, "not a point cloud: vertex properties x, y, z are missing");
    const int rgb[3] = {find({"red", "diffuse_red", "r"}), find({"green", "diffuse_green", "g"}),
                        find({"blue", "diffuse_blue", "b"})};
    cloud.xyz.resize(e.count);
    cloud.rgb.assign(e.count, {128, 128, 128});  // grey where the file has no colour
    return [&cloud, &bad, xyz, rgb](const std::vector<double>& row, size_t i) {
      cloud.xyz[i] = {row[xyz[0]], row[xyz[1]], row[xyz[2]]};
      bool finite = cloud.xyz[i].allFinite();
      for (int k = 0; k < 3; ++k) {
        if (rgb[k] < 0) continue;
        if (!std::isfinite(row[rgb[k]])) {
          finite = false;
          continue;
        }
        cloud.rgb[i][k] = uint8_t(std::clamp(row[rgb[k]], 0.0, 255.0));
      }
      bad += !finite;
    };
  });
  if (bad > 0)
    throw InputError(file,
                     fmt::format("{} of {} points have NaN or infinite coordinates or colours", bad,
                                 cloud.xyz.size()));
  return cloud;
}

void write_gaussian_ply(const fs::path& file, const GaussianModel& m) {
  const size_t n = m.size();
  std::string header = fmt::format("ply\nformat binary_little_endian 1.0\nelement vertex {}\n", n);
  std::vector<std::string> names = {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"};
  for (int k = 0; k < kShRestFloats; ++k) names.push_back(fmt::format("f_rest_{}", k));
  for (const char* s :
       {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
    names.push_back(s);
  if (m.has_instance_opacity) names.push_back("instance_opacity");
  for (const auto& name : names) header += "property float " + name + "\n";
  if (m.has_labels) header += "property int label\n";
  header += "end_header\n";

  const size_t floats = names.size();
  const size_t stride = 4 * floats + (m.has_labels ? 4 : 0);
  write_atomically(file, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << header;
    constexpr size_t kChunk = 65536;
    std::vector<char> buffer;
    std::vector<float> row(floats);
    for (size_t start = 0; start < n; start += kChunk) {
      const size_t count = std::min(kChunk, n - start);
      buffer.resize(count * stride);
      for (size_t r = 0; r < count; ++r) {
        const size_t i = start + r;
        float* f = row.data();
        for (int k = 0; k < 3; ++k) *f++ = m.means[3 * i + k];
        for (int k = 0; k < 3; ++k) *f++ = 0.f;  // normals: unused by 3DGS, kept for viewers
        for (int k = 0; k < 3; ++k) *f++ = m.sh_dc[3 * i + k];
        for (int c = 0; c < 3; ++c)
          for (int j = 0; j < kShRestCoeffs; ++j) *f++ = m.sh_rest[kShRestFloats * i + 3 * j + c];
        *f++ = m.opacity_logits[i];
        for (int k = 0; k < 3; ++k) *f++ = m.log_scales[3 * i + k];
        for (int k = 0; k < 4; ++k) *f++ = m.rotations[4 * i + k];
        if (m.has_instance_opacity) *f++ = m.instance_opacity_logits[i];
        char* dst = buffer.data() + r * stride;
        std::memcpy(dst, row.data(), 4 * floats);
        if (m.has_labels) std::memcpy(dst + 4 * floats, &m.labels[i], 4);
      }
      out.write(buffer.data(), std::streamsize(buffer.size()));
    }
    out.close();
    if (!out) throw_write_error(file);
  });
}

}  // namespace splat
