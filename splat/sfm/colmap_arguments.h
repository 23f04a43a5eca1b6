#pragma once
// The command lines of COLMAP's steps, one function per step, as op2gs-sfm
// runs them (COLMAP 3.8's option names). Building them apart from running
// them keeps the controller a sequence of steps and lets a test read them.

#include <filesystem>
#include <string>
#include <vector>

namespace splat {

// "1,2.5,3": COLMAP's list syntax for camera parameters.
std::string colmap_list(const std::vector<double>& values);

struct FeatureExtraction {
  std::filesystem::path database, images;
  std::string camera_model;
  std::vector<double> camera_params;  // fixes the shared camera's intrinsics if given
  bool single_camera = true;
  std::filesystem::path image_list;  // only these photos, if given
  bool gpu = false;
  int max_image_size = 2000;
  int threads = 0;  // 0: COLMAP's default
};
std::vector<std::string> feature_extractor_arguments(const FeatureExtraction& e);

struct Matching {
  std::filesystem::path database;
  bool sequential = false;  // else exhaustive
  int sequential_overlap = 10;
  std::filesystem::path vocab_tree;  // loop detection, for sequential matching
  bool gpu = false;
};
// The matcher command ("sequential_matcher" or "exhaustive_matcher").
std::string matcher_command(const Matching& m);
std::vector<std::string> matcher_arguments(const Matching& m);

// Known poses: COLMAP triangulates the points with the cameras held fixed.
std::vector<std::string> point_triangulator_arguments(const std::filesystem::path& database,
                                                      const std::filesystem::path& images,
                                                      const std::filesystem::path& known_model,
                                                      const std::filesystem::path& output);

// Incremental mapping; with known intrinsics, bundle adjustment keeps them.
std::vector<std::string> mapper_arguments(const std::filesystem::path& database,
                                          const std::filesystem::path& images,
                                          const std::filesystem::path& output,
                                          bool known_intrinsics, int threads);

// Undistortion into PINHOLE cameras, in COLMAP's output layout.
std::vector<std::string> image_undistorter_arguments(const std::filesystem::path& images,
                                                     const std::filesystem::path& model,
                                                     const std::filesystem::path& output);

}  // namespace splat
