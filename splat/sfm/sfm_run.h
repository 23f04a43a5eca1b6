#pragma once
// The SfM stage (op2gs-sfm): from a scene folder of photos to the undistorted
// pinhole model the trainer reads, with Debian's COLMAP 3.8. The user's folder
// is never modified; everything goes into the output folder:
//
//   <out>/database.db             COLMAP's features and matches (reused on rerun)
//   <out>/sparse_raw/<n>/         the models the mapper made
//   <out>/colmap.log              everything COLMAP printed
//   <out>/undistorted/            COLMAP's undistorter output
//   <out>/scene/                  the scene for the next stages: images/ and
//                                 sparse/0/ (undistorted, PINHOLE), sam2/
//                                 (undistorted likewise, or linked when the
//                                 cameras are pinholes already), and links
//                                 to the user's images_train/, test_mask/
//                                 and other benchmark files
//   <out>/scene/photo_cameras/    when the photos were undistorted: their
//                                 cameras (a COLMAP model without points),
//                                 so that op2gs-eval can score renders
//                                 against ground truth drawn on the photos
//   <out>/sfm.json                views registered and not, the model kept
//
// With `import_model`, an existing model replaces the SfM steps: linked as it
// is when its cameras are pinholes (no COLMAP needed), else undistorted.
//
// A rerun skips the steps that finished with the same inputs and options.

#include <filesystem>
#include <string>
#include <vector>

#include "splat/sfm/colmap_command.h"

namespace splat {

enum class SfmMatcher { kAuto, kExhaustive, kSequential };

struct SfmOptions {
  std::string images_dir = "images";
  SfmMatcher matcher = SfmMatcher::kAuto;  // auto: exhaustive up to 250 images
  int sequential_overlap = 10;
  // Vocabulary tree for loop detection in sequential matching (off without).
  std::filesystem::path vocab_tree;
  bool single_camera = true;
  std::string camera_model = "OPENCV";  // as the reference 3DGS convert script
  // Known intrinsics fx fy cx cy (PINHOLE, held fixed), or empty.
  std::vector<double> intrinsics;
  enum class Gpu { kAuto, kOn, kOff } gpu = Gpu::kAuto;
  double min_registered_fraction = 0.5;  // fail below this share of views
  int threads = 0;                       // 0: COLMAP's default (all cores)
  // SIFT runs on photos scaled down to this many pixels on their long side
  // (COLMAP's default is 3200): a 1080p video frame stays whole, a 12-48 MP
  // phone photo is scaled down 2-4x, which makes extraction several times
  // faster. Features are found at the reduced size; poses are for the photos.
  int max_image_size = 2000;
  ColmapCommand colmap;  // the binary; its log is set by run_sfm

  // Import instead of running SfM: an existing COLMAP model folder (binary or
  // text), or a nerfstudio / instant-ngp transforms.json (transforms_json.h;
  // COLMAP triangulates the points when it has none); undistorted if its
  // cameras have distortion.
  std::filesystem::path import_model;
  // Import the LLFF cameras of <scene>/poses_bounds.npy (3DOVS) instead of
  // estimating poses; COLMAP only triangulates the points, cameras fixed.
  bool llff = false;
  // True cameras (a COLMAP model), if known: the pose accuracy after a
  // similarity alignment goes into sfm.json.
  std::filesystem::path truth;
  // Folders of ID maps (<stem>.png) in the scene that are resampled with the
  // images when COLMAP undistorts them, rather than linked as they are.
  std::vector<std::string> id_map_dirs = {"sam2", "object_mask", "object_mask_deva", "instance_gt"};

  void Check() const;  // throws std::invalid_argument
};

struct SfmResult {
  size_t views = 0, registered = 0;
  std::vector<std::string> unregistered;
  size_t models = 0;            // models the mapper made
  int kept_model = -1;          // index of the largest
  std::filesystem::path scene;  // <out>/scene
  double center_rmse = -1;      // against `truth`, in its units; -1 without
  double rotation_error_deg = -1;
};

SfmResult run_sfm(const std::filesystem::path& scene_dir, const std::filesystem::path& out_dir,
                  const SfmOptions& options);

}  // namespace splat
