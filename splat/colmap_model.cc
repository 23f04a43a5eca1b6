// COLMAP's sparse model (cameras, images, points3D) in both of its formats,
// binary and text, read with every check a user's model needs and written
// back. Kept in one file, as COLMAP keeps its model I/O, so that the readers
// and the writers of the two formats cannot drift apart.
#include "splat/colmap_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include "splat/atomic_file.h"
#include "splat/binary_io.h"
#include "splat/error.h"

namespace splat {
namespace fs = std::filesystem;

const std::vector<CameraModelInfo>& camera_models() {
  static const std::vector<CameraModelInfo> models = {
      {0, "SIMPLE_PINHOLE", 3, false},
      {1, "PINHOLE", 4, false},
      {2, "SIMPLE_RADIAL", 4, true},
      {3, "RADIAL", 5, true},
      {4, "OPENCV", 8, true},
      {5, "OPENCV_FISHEYE", 8, true},
      {6, "FULL_OPENCV", 12, true},
      {7, "FOV", 5, true},
      {8, "SIMPLE_RADIAL_FISHEYE", 4, true},
      {9, "RADIAL_FISHEYE", 5, true},
      {10, "THIN_PRISM_FISHEYE", 12, true},
  };
  return models;
}

std::optional<CameraModelInfo> camera_model_by_name(const std::string& name) {
  for (const auto& m : camera_models())
    if (name == m.name) return m;
  return std::nullopt;
}

std::optional<CameraModelInfo> camera_model_by_id(int id) {
  for (const auto& m : camera_models())
    if (id == m.id) return m;
  return std::nullopt;
}

namespace {

bool all_finite(const std::vector<double>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

void check_camera(const ColmapCamera& cam, const fs::path& file) {
  const auto info = camera_model_by_id(cam.model_id);
  if (!info)
    throw InputError(file,
                     fmt::format("camera {} has unknown model id {}", cam.camera_id, cam.model_id));
  if (int(cam.params.size()) != info->num_params)
    throw InputError(file, fmt::format("camera {} ({}) needs {} parameters, has {}", cam.camera_id,
                                       info->name, info->num_params, cam.params.size()));
}

std::map<uint32_t, ColmapCamera> read_cameras_bin(const fs::path& file) {
  BinaryReader in(file, read_text_file(file));
  std::map<uint32_t, ColmapCamera> cameras;
  const uint64_t n = in.read_count(24);
  for (uint64_t i = 0; i < n; ++i) {
    ColmapCamera cam;
    cam.camera_id = in.read<uint32_t>();
    cam.model_id = in.read<int32_t>();
    cam.width = in.read<uint64_t>();
    cam.height = in.read<uint64_t>();
    const auto info = camera_model_by_id(cam.model_id);
    if (!info)
      in.fail(fmt::format("camera {} has unknown model id {}", cam.camera_id, cam.model_id));
    cam.params.resize(info->num_params);
    for (double& p : cam.params) p = in.read<double>();
    if (!all_finite(cam.params))
      in.fail(fmt::format("camera {} has a parameter that is NaN or infinite", cam.camera_id));
    const uint32_t id = cam.camera_id;
    if (!cameras.emplace(id, std::move(cam)).second)
      in.fail(fmt::format("camera ID {} appears twice", id));
  }
  in.expect_end();
  return cameras;
}

std::map<uint32_t, ColmapImage> read_images_bin(const fs::path& file) {
  BinaryReader in(file, read_text_file(file));
  std::map<uint32_t, ColmapImage> images;
  const uint64_t n = in.read_count(64);
  for (uint64_t i = 0; i < n; ++i) {
    ColmapImage im;
    im.image_id = in.read<uint32_t>();
    for (int k = 0; k < 4; ++k) im.qvec[k] = in.read<double>();
    for (int k = 0; k < 3; ++k) im.tvec[k] = in.read<double>();
    im.camera_id = in.read<uint32_t>();
    im.name = in.read_cstring("image name");
    const uint64_t np = in.read_count(24);
    im.points2d.resize(np);
    im.point3d_ids.resize(np);
    for (uint64_t k = 0; k < np; ++k) {
      im.points2d[k].x() = in.read<double>();
      im.points2d[k].y() = in.read<double>();
      im.point3d_ids[k] = in.read<int64_t>();  // COLMAP writes uint64 max for "none"
    }
    if (!im.qvec.allFinite() || !im.tvec.allFinite())
      in.fail(fmt::format("image {} has a pose that is NaN or infinite", im.name));
    const uint32_t id = im.image_id;
    if (!images.emplace(id, std::move(im)).second)
      in.fail(fmt::format("image ID {} appears twice", id));
  }
  in.expect_end();
  return images;
}

std::map<uint64_t, ColmapPoint3D> read_points3d_bin(const fs::path& file) {
  BinaryReader in(file, read_text_file(file));
  std::map<uint64_t, ColmapPoint3D> points;
  const uint64_t n = in.read_count(43);
  for (uint64_t i = 0; i < n; ++i) {
    ColmapPoint3D p;
    p.point3d_id = in.read<uint64_t>();
    for (int k = 0; k < 3; ++k) p.xyz[k] = in.read<double>();
    for (int k = 0; k < 3; ++k) p.rgb[k] = in.read<uint8_t>();
    p.error = in.read<double>();
    const uint64_t nt = in.read_count(8);
    p.track.resize(nt);
    for (auto& el : p.track) {
      el.image_id = in.read<uint32_t>();
      el.point2d_idx = in.read<uint32_t>();
    }
    const uint64_t id = p.point3d_id;
    if (!points.emplace(id, std::move(p)).second)
      in.fail(fmt::format("point ID {} appears twice", id));
  }
  in.expect_end();
  return points;
}

void write_cameras_bin(const ColmapModel& m, const fs::path& file) {
  BinaryWriter out;
  out.write<uint64_t>(m.cameras.size());
  for (const auto& [id, cam] : m.cameras) {
    check_camera(cam, file);
    out.write<uint32_t>(cam.camera_id);
    out.write<int32_t>(cam.model_id);
    out.write<uint64_t>(cam.width);
    out.write<uint64_t>(cam.height);
    for (double p : cam.params) out.write<double>(p);
  }
  write_text_atomically(file, out.bytes());
}

void write_images_bin(const ColmapModel& m, const fs::path& file) {
  BinaryWriter out;
  out.write<uint64_t>(m.images.size());
  for (const auto& [id, im] : m.images) {
    out.write<uint32_t>(im.image_id);
    for (int k = 0; k < 4; ++k) out.write<double>(im.qvec[k]);
    for (int k = 0; k < 3; ++k) out.write<double>(im.tvec[k]);
    out.write<uint32_t>(im.camera_id);
    out.write_cstring(im.name);
    out.write<uint64_t>(im.points2d.size());
    for (size_t k = 0; k < im.points2d.size(); ++k) {
      out.write<double>(im.points2d[k].x());
      out.write<double>(im.points2d[k].y());
      out.write<int64_t>(im.point3d_ids[k]);
    }
  }
  write_text_atomically(file, out.bytes());
}

void write_points3d_bin(const ColmapModel& m, const fs::path& file) {
  BinaryWriter out;
  out.write<uint64_t>(m.points3d.size());
  for (const auto& [id, p] : m.points3d) {
    out.write<uint64_t>(p.point3d_id);
    for (int k = 0; k < 3; ++k) out.write<double>(p.xyz[k]);
    for (int k = 0; k < 3; ++k) out.write<uint8_t>(p.rgb[k]);
    out.write<double>(p.error);
    out.write<uint64_t>(p.track.size());
    for (const auto& el : p.track) {
      out.write<uint32_t>(el.image_id);
      out.write<uint32_t>(el.point2d_idx);
    }
  }
  write_text_atomically(file, out.bytes());
}

// ------------------------------------------------------------------ text ---

// Iterates over the data lines of a COLMAP text file (skipping comments and
// blank lines) and parses whitespace-separated fields with line numbers in
// every error.
class TextReader {
 public:
  explicit TextReader(const fs::path& file) : file_(file), in_(read_text_file(file)) {}

  // Advances to the next data line; false at the end of the file.
  bool next_line() {
    std::string line;
    while (std::getline(in_, line)) {
      ++line_number_;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const size_t first = line.find_first_not_of(" \t");
      if (first == std::string::npos || line[first] == '#') continue;
      fields_ = std::istringstream(line);
      line_ = line;
      return true;
    }
    return false;
  }
  // Like next_line, but a blank line counts (images.txt may have empty 2D point lines).
  bool next_raw_line() {
    std::string line;
    if (!std::getline(in_, line)) return false;
    ++line_number_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    fields_ = std::istringstream(line);
    line_ = line;
    return true;
  }
  template <typename T>
  T field(const char* what) {
    T value;
    if (!(fields_ >> value)) fail(fmt::format("expected {}", what));
    return value;
  }
  bool has_more() {
    fields_ >> std::ws;
    return !fields_.eof();
  }
  std::string rest() {
    std::string s;
    std::getline(fields_ >> std::ws, s);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.pop_back();
    return s;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(file_, fmt::format("line {}: {} in '{}'", line_number_, what, line_));
  }

 private:
  fs::path file_;
  std::istringstream in_;
  std::istringstream fields_;
  std::string line_;
  int line_number_ = 0;
};

std::map<uint32_t, ColmapCamera> read_cameras_txt(const fs::path& file) {
  TextReader in(file);
  std::map<uint32_t, ColmapCamera> cameras;
  while (in.next_line()) {
    ColmapCamera cam;
    cam.camera_id = in.field<uint32_t>("camera id");
    const auto model_name = in.field<std::string>("camera model");
    const auto info = camera_model_by_name(model_name);
    if (!info) in.fail(fmt::format("unknown camera model '{}'", model_name));
    cam.model_id = info->id;
    cam.width = in.field<uint64_t>("width");
    cam.height = in.field<uint64_t>("height");
    cam.params.resize(info->num_params);
    for (double& p : cam.params) p = in.field<double>("camera parameter");
    if (in.has_more()) in.fail(fmt::format("too many parameters for {}", info->name));
    if (!all_finite(cam.params)) in.fail("a camera parameter is NaN or infinite");
    const uint32_t id = cam.camera_id;
    if (!cameras.emplace(id, std::move(cam)).second)
      in.fail(fmt::format("camera ID {} appears twice", id));
  }
  return cameras;
}

std::map<uint32_t, ColmapImage> read_images_txt(const fs::path& file) {
  TextReader in(file);
  std::map<uint32_t, ColmapImage> images;
  while (in.next_line()) {
    ColmapImage im;
    im.image_id = in.field<uint32_t>("image id");
    for (int k = 0; k < 4; ++k) im.qvec[k] = in.field<double>("quaternion");
    for (int k = 0; k < 3; ++k) im.tvec[k] = in.field<double>("translation");
    im.camera_id = in.field<uint32_t>("camera id");
    im.name = in.rest();
    if (im.name.empty()) in.fail("expected image name");
    if (!im.qvec.allFinite() || !im.tvec.allFinite()) in.fail("the pose is NaN or infinite");
    if (images.count(im.image_id)) in.fail(fmt::format("image ID {} appears twice", im.image_id));
    // The second line of each image lists its 2D points; it may be empty.
    if (!in.next_raw_line()) in.fail("missing the line of 2D points");
    while (in.has_more()) {
      const double x = in.field<double>("point x");
      const double y = in.field<double>("point y");
      const int64_t id = in.field<int64_t>("point3D id");
      im.points2d.emplace_back(x, y);
      im.point3d_ids.push_back(id);
    }
    images[im.image_id] = std::move(im);
  }
  return images;
}

std::map<uint64_t, ColmapPoint3D> read_points3d_txt(const fs::path& file) {
  TextReader in(file);
  std::map<uint64_t, ColmapPoint3D> points;
  while (in.next_line()) {
    ColmapPoint3D p;
    p.point3d_id = in.field<uint64_t>("point id");
    for (int k = 0; k < 3; ++k) p.xyz[k] = in.field<double>("coordinate");
    for (int k = 0; k < 3; ++k) {
      const int c = in.field<int>("colour");
      if (c < 0 || c > 255) in.fail("colour outside 0..255");
      p.rgb[k] = uint8_t(c);
    }
    p.error = in.field<double>("error");
    while (in.has_more()) {
      TrackElement el;
      el.image_id = in.field<uint32_t>("track image id");
      el.point2d_idx = in.field<uint32_t>("track point2D index");
      p.track.push_back(el);
    }
    const uint64_t id = p.point3d_id;
    if (!points.emplace(id, std::move(p)).second)
      in.fail(fmt::format("point ID {} appears twice", id));
  }
  return points;
}

// Doubles are written with 17 significant digits so text round-trips exactly.
void write_cameras_txt(const ColmapModel& m, const fs::path& file) {
  std::string s = "# Camera list with one line of data per camera:\n";
  s += "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n";
  s += fmt::format("# Number of cameras: {}\n", m.cameras.size());
  for (const auto& [id, cam] : m.cameras) {
    check_camera(cam, file);
    s += fmt::format("{} {} {} {}", cam.camera_id, camera_model_by_id(cam.model_id)->name,
                     cam.width, cam.height);
    for (double p : cam.params) s += fmt::format(" {:.17g}", p);
    s += "\n";
  }
  write_text_atomically(file, s);
}

void write_images_txt(const ColmapModel& m, const fs::path& file) {
  size_t observations = 0;
  for (const auto& [id, im] : m.images)
    for (int64_t p : im.point3d_ids) observations += (p != kNoPoint3D);
  std::string s = "# Image list with two lines of data per image:\n";
  s += "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n";
  s += "#   POINTS2D[] as (X, Y, POINT3D_ID)\n";
  s += fmt::format("# Number of images: {}, mean observations per image: {}\n", m.images.size(),
                   m.images.empty() ? 0.0 : double(observations) / m.images.size());
  for (const auto& [id, im] : m.images) {
    s += fmt::format("{} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {} {}\n",
                     im.image_id, im.qvec[0], im.qvec[1], im.qvec[2], im.qvec[3], im.tvec[0],
                     im.tvec[1], im.tvec[2], im.camera_id, im.name);
    for (size_t k = 0; k < im.points2d.size(); ++k)
      s += fmt::format("{}{:.17g} {:.17g} {}", k ? " " : "", im.points2d[k].x(), im.points2d[k].y(),
                       im.point3d_ids[k]);
    s += "\n";
  }
  write_text_atomically(file, s);
}

void write_points3d_txt(const ColmapModel& m, const fs::path& file) {
  double track_sum = 0;
  for (const auto& [id, p] : m.points3d) track_sum += p.track.size();
  std::string s = "# 3D point list with one line of data per point:\n";
  s += "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n";
  s += fmt::format("# Number of points: {}, mean track length: {}\n", m.points3d.size(),
                   m.points3d.empty() ? 0.0 : track_sum / m.points3d.size());
  for (const auto& [id, p] : m.points3d) {
    s += fmt::format("{} {:.17g} {:.17g} {:.17g} {} {} {} {:.17g}", p.point3d_id, p.xyz[0],
                     p.xyz[1], p.xyz[2], p.rgb[0], p.rgb[1], p.rgb[2], p.error);
    for (const auto& el : p.track) s += fmt::format(" {} {}", el.image_id, el.point2d_idx);
    s += "\n";
  }
  write_text_atomically(file, s);
}

void check_references(const ColmapModel& m, const fs::path& dir) {
  for (const auto& [id, im] : m.images)
    if (!m.cameras.count(im.camera_id))
      throw InputError(dir / "images", fmt::format("image '{}' refers to missing camera {}",
                                                   im.name, im.camera_id));
}

}  // namespace

ColmapModel read_colmap_model(const fs::path& dir, ColmapFormat format) {
  ColmapModel m;
  if (format == ColmapFormat::kBinary) {
    m.cameras = read_cameras_bin(dir / "cameras.bin");
    m.images = read_images_bin(dir / "images.bin");
    m.points3d = read_points3d_bin(dir / "points3D.bin");
  } else {
    m.cameras = read_cameras_txt(dir / "cameras.txt");
    m.images = read_images_txt(dir / "images.txt");
    m.points3d = read_points3d_txt(dir / "points3D.txt");
  }
  check_references(m, dir);
  return m;
}

ColmapModel read_colmap_model(const fs::path& dir) {
  if (fs::exists(dir / "cameras.bin")) return read_colmap_model(dir, ColmapFormat::kBinary);
  if (fs::exists(dir / "cameras.txt")) return read_colmap_model(dir, ColmapFormat::kText);
  throw InputError(dir, "no COLMAP model here (expected cameras.bin or cameras.txt)");
}

void write_colmap_model(const ColmapModel& model, const fs::path& dir, ColmapFormat format) {
  fs::create_directories(dir);
  if (format == ColmapFormat::kBinary) {
    write_cameras_bin(model, dir / "cameras.bin");
    write_images_bin(model, dir / "images.bin");
    write_points3d_bin(model, dir / "points3D.bin");
  } else {
    write_cameras_txt(model, dir / "cameras.txt");
    write_images_txt(model, dir / "images.txt");
    write_points3d_txt(model, dir / "points3D.txt");
  }
}

Camera pinhole_camera(const ColmapModel& model, const ColmapImage& image, const fs::path& source) {
  const auto it = model.cameras.find(image.camera_id);
  if (it == model.cameras.end())
    throw InputError(
        source, fmt::format("image '{}' refers to missing camera {}", image.name, image.camera_id));
  const ColmapCamera& cam = it->second;
  const auto info = camera_model_by_id(cam.model_id);
  if (!info || info->has_distortion)
    throw InputError(source, fmt::format("camera {} uses the {} model; training needs undistorted "
                                         "PINHOLE or SIMPLE_PINHOLE images: run op2gs-sfm "
                                         "(which runs COLMAP's image_undistorter) first",
                                         cam.camera_id, info ? info->name : "unknown"));
  Camera c;
  c.width = int(cam.width);
  c.height = int(cam.height);
  if (info->id == 0) {  // SIMPLE_PINHOLE: f cx cy
    c.fx = c.fy = cam.params[0];
    c.cx = cam.params[1];
    c.cy = cam.params[2];
  } else {  // PINHOLE: fx fy cx cy
    c.fx = cam.params[0];
    c.fy = cam.params[1];
    c.cx = cam.params[2];
    c.cy = cam.params[3];
  }
  c.R = rotation_from_quaternion(image.qvec);
  c.t = image.tvec;
  return c;
}

}  // namespace splat
