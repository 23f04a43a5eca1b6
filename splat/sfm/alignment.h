#pragma once
// Pose accuracy of a reconstruction against true cameras: the similarity
// transform (scale, rotation, translation) that best maps the estimated
// camera centres onto the true ones (Umeyama's least squares), and the
// errors left after it.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "splat/colmap_model.h"

namespace splat {

struct Similarity {
  double scale = 1;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return scale * R * x + t; }
};

// Least-squares similarity from `from` to `to` (same size, at least 3 points
// not on a line). Throws std::invalid_argument otherwise.
Similarity align_similarity(const std::vector<Eigen::Vector3d>& from,
                            const std::vector<Eigen::Vector3d>& to);

struct PoseAccuracy {
  size_t matched = 0;             // images in both models (by name)
  double center_rmse = 0;         // camera centres after alignment, true units
  double rotation_error_deg = 0;  // mean angle between aligned and true orientations
  Similarity alignment;           // estimated -> true
};

// Matches the images of both models by name and aligns the estimated camera
// centres to the true ones.
PoseAccuracy pose_accuracy(const ColmapModel& estimated, const ColmapModel& truth);

// The same against the model in `truth_model` (op2gs-sfm --truth). Throws
// InputError naming it when it shares fewer than 3 image names with
// `estimated`.
PoseAccuracy pose_accuracy_against(const ColmapModel& estimated,
                                   const std::filesystem::path& truth_model);

}  // namespace splat
