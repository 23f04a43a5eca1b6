#pragma once
// Refined camera poses by image name: what pose refinement (op2gs-train
// --refine-poses) writes and the later stages read instead of the COLMAP
// model's poses (SceneOptions::poses).
//
// A text file, one view per line, in COLMAP's conventions (world-to-camera,
// as in images.txt): "QW QX QY QZ TX TY TZ NAME", the name last so that it may
// hold spaces; lines starting with '#' are comments.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace splat {

struct NamedPose {
  std::string name;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // world-to-camera rotation
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // world-to-camera translation
};

// Throws InputError naming the file and line for a malformed line or a name
// given twice.
std::vector<NamedPose> read_pose_file(const std::filesystem::path& file);

// Written atomically.
void write_pose_file(const std::filesystem::path& file, const std::vector<NamedPose>& poses);

// The pose file a stage uses (its --poses option): the one given, none for
// "none", else the first of the refined pose files an earlier stage may have
// written that exists (WorkLayout::refined_poses_of_*, logged), else none (the
// COLMAP model's poses).
std::filesystem::path choose_pose_file(const std::string& option,
                                       const std::vector<std::filesystem::path>& defaults);

}  // namespace splat
