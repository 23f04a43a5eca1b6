#pragma once
// COLMAP sparse models (cameras, images, points3D) in memory, and reading and
// writing them in COLMAP's binary (.bin) and text (.txt) formats.
//
// The formats are COLMAP's own (src/base/reconstruction.cc in COLMAP 3.8):
// every camera model by name and id, image poses world-to-camera as
// qw qx qy qz tx ty tz, 2D points with their 3D point id (-1 for none), and 3D
// points with colour, error and track.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "splat/camera.h"

namespace splat {

// COLMAP's camera models, with their ids and parameter counts.
struct CameraModelInfo {
  int id;
  const char* name;
  int num_params;
  bool has_distortion;
};
const std::vector<CameraModelInfo>& camera_models();
std::optional<CameraModelInfo> camera_model_by_name(const std::string& name);
std::optional<CameraModelInfo> camera_model_by_id(int id);

struct ColmapCamera {
  uint32_t camera_id = 0;
  int model_id = 1;  // PINHOLE
  uint64_t width = 0;
  uint64_t height = 0;
  std::vector<double> params;
  bool operator==(const ColmapCamera&) const = default;
};

inline constexpr int64_t kNoPoint3D = -1;

struct ColmapImage {
  uint32_t image_id = 0;
  Eigen::Vector4d qvec{1, 0, 0, 0};  // qw qx qy qz, world-to-camera
  Eigen::Vector3d tvec = Eigen::Vector3d::Zero();
  uint32_t camera_id = 0;
  std::string name;
  std::vector<Eigen::Vector2d> points2d;
  std::vector<int64_t> point3d_ids;  // one per 2D point, kNoPoint3D if none
  bool operator==(const ColmapImage&) const = default;
};

struct TrackElement {
  uint32_t image_id = 0;
  uint32_t point2d_idx = 0;
  bool operator==(const TrackElement&) const = default;
};

struct ColmapPoint3D {
  uint64_t point3d_id = 0;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::array<uint8_t, 3> rgb{0, 0, 0};
  double error = 0;
  std::vector<TrackElement> track;
  bool operator==(const ColmapPoint3D&) const = default;
};

struct ColmapModel {
  std::map<uint32_t, ColmapCamera> cameras;
  std::map<uint32_t, ColmapImage> images;
  std::map<uint64_t, ColmapPoint3D> points3d;
  bool operator==(const ColmapModel&) const = default;
};

enum class ColmapFormat { kBinary, kText };

// Reads a model folder holding either cameras.bin/images.bin/points3D.bin or
// the .txt files (binary preferred when both exist). Throws InputError naming
// the offending file for anything missing, truncated or malformed.
ColmapModel read_colmap_model(const std::filesystem::path& dir);
ColmapModel read_colmap_model(const std::filesystem::path& dir, ColmapFormat format);

// Writes the three files into dir (created if needed), each atomically.
void write_colmap_model(const ColmapModel& model, const std::filesystem::path& dir,
                        ColmapFormat format);

// The training camera of one image. Only undistorted PINHOLE and
// SIMPLE_PINHOLE models are accepted; anything else throws an InputError
// (naming `source`) that says to run the SfM stage's undistortion.
Camera pinhole_camera(const ColmapModel& model, const ColmapImage& image,
                      const std::filesystem::path& source);

}  // namespace splat
