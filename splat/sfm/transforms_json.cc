#include "splat/sfm/transforms_json.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/image.h"
#include "splat/ply.h"

namespace splat {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// A number at `key` of the frame, else of the file's top level.
std::optional<double> number(const json& frame, const json& top, const char* key) {
  for (const json* j : {&frame, &top})
    if (j->contains(key) && (*j)[key].is_number()) return (*j)[key].get<double>();
  return std::nullopt;
}

std::string text(const json& frame, const json& top, const char* key) {
  for (const json* j : {&frame, &top})
    if (j->contains(key) && (*j)[key].is_string()) return (*j)[key].get<std::string>();
  return "";
}

bool flag(const json& frame, const json& top, const char* key) {
  for (const json* j : {&frame, &top})
    if (j->contains(key) && (*j)[key].is_boolean()) return (*j)[key].get<bool>();
  return false;
}

// The photo of a frame: file_path as written, else with a usual extension
// (instant-ngp and NeRF captures often leave it out). Empty if none exists.
fs::path find_photo(const fs::path& base, const std::string& file_path) {
  const fs::path p = base / file_path;
  if (fs::is_regular_file(p)) return p;
  for (const char* ext : {".png", ".jpg", ".jpeg", ".JPG", ".PNG", ".JPEG"}) {
    fs::path with = p;
    with += ext;
    if (fs::is_regular_file(with)) return with;
  }
  return {};
}

// A frame's camera in COLMAP's terms; w and h come from the photo when the
// file does not give them.
ColmapCamera frame_camera(const json& frame, const json& top, const ImageInfo& photo,
                          const fs::path& file, const std::string& frame_name) {
  auto bad = [&](const std::string& what) {
    return InputError(file, fmt::format("frame {}: {}", frame_name, what));
  };
  ColmapCamera c;
  const double w = number(frame, top, "w").value_or(photo.width);
  const double h = number(frame, top, "h").value_or(photo.height);
  if (std::lround(w) != photo.width || std::lround(h) != photo.height)
    throw bad(fmt::format("the photo is {}x{}, the file says {}x{}", photo.width, photo.height,
                          std::lround(w), std::lround(h)));
  c.width = uint64_t(photo.width), c.height = uint64_t(photo.height);
  std::optional<double> fx = number(frame, top, "fl_x"), fy = number(frame, top, "fl_y");
  if (!fx)
    if (const auto ax = number(frame, top, "camera_angle_x")) fx = 0.5 * w / std::tan(0.5 * *ax);
  if (!fy)
    if (const auto ay = number(frame, top, "camera_angle_y")) fy = 0.5 * h / std::tan(0.5 * *ay);
  if (!fx && fy) fx = fy;
  if (fx && !fy) fy = fx;
  if (!fx || !(*fx > 0) || !(*fy > 0)) throw bad("no focal length (fl_x / fl_y or camera_angle_x)");
  const double cx = number(frame, top, "cx").value_or(0.5 * w);
  const double cy = number(frame, top, "cy").value_or(0.5 * h);
  auto coeff = [&](const char* k) { return number(frame, top, k).value_or(0.0); };
  const double k1 = coeff("k1"), k2 = coeff("k2"), k3 = coeff("k3"), k4 = coeff("k4");
  const double p1 = coeff("p1"), p2 = coeff("p2");
  std::string model = text(frame, top, "camera_model");
  if (model.empty())
    model = flag(frame, top, "is_fisheye")       ? "OPENCV_FISHEYE"
            : (k1 || k2 || k3 || k4 || p1 || p2) ? "OPENCV"
                                                 : "PINHOLE";
  if (model == "PINHOLE" || model == "SIMPLE_PINHOLE") {
    if (k1 || k2 || k3 || k4 || p1 || p2)
      throw bad("camera_model " + model + " with distortion coefficients");
    c.model_id = camera_model_by_name("PINHOLE")->id;
    c.params = {*fx, *fy, cx, cy};
  } else if (model == "OPENCV") {
    // nerfstudio's radial polynomial 1 + k1 r^2 + k2 r^4 + k3 r^6 + k4 r^8:
    // COLMAP's OPENCV up to k2, FULL_OPENCV up to k3; k4 has no equivalent.
    if (k4) throw bad("OPENCV with k4 != 0: no COLMAP camera model has that polynomial");
    c.model_id = camera_model_by_name(k3 ? "FULL_OPENCV" : "OPENCV")->id;
    c.params = {*fx, *fy, cx, cy, k1, k2, p1, p2};
    if (k3) c.params.insert(c.params.end(), {k3, 0, 0, 0});
  } else if (model == "OPENCV_FISHEYE") {
    if (p1 || p2) throw bad("OPENCV_FISHEYE with tangential coefficients p1 / p2");
    c.model_id = camera_model_by_name("OPENCV_FISHEYE")->id;
    c.params = {*fx, *fy, cx, cy, k1, k2, k3, k4};
  } else {
    throw bad("camera_model '" + model +
              "' is not supported (PINHOLE, OPENCV or OPENCV_FISHEYE; equirectangular captures "
              "cannot be splatted)");
  }
  return c;
}

// transform_matrix (camera to world, OpenGL axes) as COLMAP's world-to-camera
// rotation and translation. The rotation block is projected onto the nearest
// rotation; a block that is far from one is an error.
void set_pose(const json& frame, ColmapImage& image, const fs::path& file) {
  auto bad = [&](const std::string& what) {
    return InputError(file, fmt::format("frame {}: {}", image.name, what));
  };
  const json& m = frame.contains("transform_matrix") ? frame["transform_matrix"] : json();
  if (!m.is_array() || m.size() < 3) throw bad("no transform_matrix (4x4 or 3x4)");
  Eigen::Matrix3d r;
  Eigen::Vector3d t;
  for (int i = 0; i < 3; ++i) {
    if (!m[i].is_array() || m[i].size() < 4) throw bad("transform_matrix rows need 4 numbers");
    for (int j = 0; j < 4; ++j) {
      if (!m[i][j].is_number()) throw bad("transform_matrix holds a value that is not a number");
      const double v = m[i][j].get<double>();
      if (!std::isfinite(v)) throw bad("transform_matrix holds NaN or infinity");
      (j < 3 ? r(i, j) : t(i)) = v;
    }
  }
  r.col(1) *= -1;  // OpenGL (y up, z back) to OpenCV / COLMAP (y down, z forward)
  r.col(2) *= -1;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  if (rotation.determinant() < 0 || (svd.singularValues().array() - 1).abs().maxCoeff() > 0.01)
    throw bad("the rotation of transform_matrix is not a rotation (scaled or mirrored)");
  const Eigen::Matrix3d world_to_camera = rotation.transpose();
  const Eigen::Quaterniond q(world_to_camera);
  image.qvec = {q.w(), q.x(), q.y(), q.z()};
  image.tvec = -world_to_camera * t;
}

json parse(const fs::path& file) {
  try {
    json j = json::parse(read_text_file(file));
    if (!j.is_object()) throw InputError(file, "not a transforms.json: the top level is no object");
    if (!j.contains("frames") || !j["frames"].is_array() || j["frames"].empty())
      throw InputError(file, "not a transforms.json: no \"frames\" list");
    return j;
  } catch (const json::exception& e) {
    throw InputError(file, std::string("malformed JSON: ") + e.what());
  }
}

// The points of ply_file_path, or of sparse_pc.ply beside the file.
void read_points(const json& top, const fs::path& file, TransformsCapture& c) {
  fs::path ply;
  if (top.contains("ply_file_path") && top["ply_file_path"].is_string()) {
    ply = file.parent_path() / top["ply_file_path"].get<std::string>();
    if (!fs::is_regular_file(ply)) throw InputError(ply, "ply_file_path names no file");
  } else if (fs::is_regular_file(file.parent_path() / "sparse_pc.ply")) {
    ply = file.parent_path() / "sparse_pc.ply";
  } else {
    return;
  }
  const PointCloud cloud = read_point_ply(ply);
  for (size_t i = 0; i < cloud.xyz.size(); ++i) {
    if (!cloud.xyz[i].allFinite()) continue;
    ColmapPoint3D p;
    p.point3d_id = c.model.points3d.size() + 1;
    p.xyz = cloud.xyz[i];
    p.rgb = cloud.rgb[i];
    c.model.points3d[p.point3d_id] = p;
  }
  c.has_points = !c.model.points3d.empty();
  c.points_file = ply;
}

}  // namespace

TransformsCapture read_transforms_json(const fs::path& file, const fs::path& images_dir) {
  const json top = parse(file);
  TransformsCapture c;
  c.flavour =
      top.contains("camera_angle_x") || top.contains("aabb_scale") ? "instant-ngp" : "nerfstudio";
  c.applied_transform = top.contains("applied_transform");
  const fs::path images = fs::weakly_canonical(images_dir);
  std::map<std::vector<double>, uint32_t> camera_ids;  // by model id, size and parameters
  std::set<std::string> names;
  for (const json& frame : top["frames"]) {
    if (!frame.is_object() || !frame.contains("file_path") || !frame["file_path"].is_string())
      throw InputError(file, "a frame has no file_path");
    const std::string file_path = frame["file_path"].get<std::string>();
    const fs::path photo = find_photo(file.parent_path(), file_path);
    if (photo.empty()) {
      c.missing.push_back(file_path);
      continue;
    }
    // The folders resolved, not the photo: a photo may be a link to a file
    // elsewhere (a capture linked into a scene folder), named by the link.
    const fs::path relative =
        (fs::weakly_canonical(photo.parent_path()) / photo.filename()).lexically_relative(images);
    if (relative.empty() || *relative.begin() == "..")
      throw InputError(file, fmt::format("frame {}: the photo is not in the image folder {}",
                                         file_path, images_dir.string()));
    ColmapImage image;
    image.name = relative.generic_string();
    if (!names.insert(image.name).second)
      throw InputError(file, "two frames name the same photo " + image.name);
    set_pose(frame, image, file);
    const ImageInfo info = read_image_info(photo);
    const ColmapCamera camera = frame_camera(frame, top, info, file, file_path);
    std::vector<double> key = {double(camera.model_id), double(camera.width),
                               double(camera.height)};
    key.insert(key.end(), camera.params.begin(), camera.params.end());
    auto [it, added] = camera_ids.emplace(key, uint32_t(camera_ids.size() + 1));
    if (added) {
      ColmapCamera with_id = camera;
      with_id.camera_id = it->second;
      c.model.cameras[with_id.camera_id] = with_id;
    }
    image.camera_id = it->second;
    image.image_id = uint32_t(c.model.images.size() + 1);
    c.model.images[image.image_id] = image;
  }
  if (c.model.images.empty())
    throw InputError(file, fmt::format("none of the {} frames has its photo (first: {})",
                                       top["frames"].size(), c.missing.front()));
  read_points(top, file, c);
  return c;
}

}  // namespace splat
