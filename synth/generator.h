#pragma once
// Generates a complete synthetic benchmark scene in the LERF-Mask layout
// (docs/inputs.md, docs/evaluation.md):
//
//   images/frame_NNNNN.png        all views (ray traced, supersampled)
//   images_train/                 the training views (every test_every-th view is a test view)
//   sparse/0/*.txt                the true cameras and points sampled on the surfaces
//   instance_gt/<stem>.png        exact instance ID maps (0 = background)
//   sam2/<stem>.png               ID maps corrupted as real SAM2 masks are
//   sam2/objects.json             names of the IDs
//   test_mask/<k>/<name>.png      binary ground truth per test view and object
//   queries.txt                   one query (object name) per line
//   objects.json                  the object table (id, name, shape, hard case)
//   scene.json                    how the scene was made (options, orbit, seed)
//   surfaces.json                 the true surfaces (objects, ground, dome), to
//                                 find floaters in a trained model
//
// and optionally the same scene in the 3DOVS layout (images/NN.png,
// segmentations/, poses_bounds.npy; or, prepared as the 3DGS papers do,
// sparse/0/ and object_mask_deva/) in a second folder.
//
// The scene can also be shipped as users receive real captures
// (docs/inputs.md), to test that they are read as they come:
//   lerf-mask-download  Gaussian Grouping's LERF-Mask download: JPEG photos
//                       frame_NNNNN.jpg, images_train/, DEVA-like ID maps in
//                       object_mask/ (black on the test views), binary
//                       sparse/0/, test_mask/, and COLMAP's leftovers
//                       distorted/ and stereo/;
//   nerfstudio          images/*.jpg, transforms.json (OpenGL poses with
//                       nerfstudio's applied_transform) and sparse_pc.ply,
//                       SAM2 ID maps in sam2/;
//   instant-ngp         images/*.jpg, transforms.json with camera_angle_x and
//                       file paths without extension, no points, sam2/.
// With distortion set, the photos and ID maps are rendered through an OPENCV
// lens and every camera file says so.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "splat/camera.h"
#include "splat/colmap_model.h"
#include "synth/capture_imperfections.h"
#include "synth/sam2_corruption.h"
#include "synth/track_errors.h"
#include "synth/world.h"

namespace synth {

enum class OutputFormat { kOp2gs, kLerfMaskDownload, kNerfstudio, kInstantNgp };

struct SynthOptions {
  int views = 40;
  int width = 320;
  int height = 240;
  uint64_t seed = 1;
  int supersample = 3;  // samples per pixel along each axis (anti-aliasing)
  int test_every = 8;   // view i is a test view when i % test_every == 0
  double fov_x_degrees = 55.0;
  double orbit_radius = 3.2;      // camera distance from the look-at point
  double radius_jitter = 0.08;    // relative
  double orbit_height = 1.5;      // camera height above the ground
  double height_jitter = 0.35;    // absolute
  int num_points = 6000;          // sparse points sampled on the surfaces
  bool write_sparse = true;       // false: no sparse/ (for testing SfM from scratch)
  std::filesystem::path ovs_dir;  // if set: also write the 3DOVS layout here
  int ovs_test_views = 5;
  bool ovs_prepared = false;  // the 3DOVS layout as ObjectGS prepares it
  OutputFormat format = OutputFormat::kOp2gs;
  std::vector<double> distortion;  // OPENCV k1 k2 p1 p2 of the photos; empty: pinhole
  Sam2CorruptionOptions sam2;
  TrackErrorOptions tracks;  // the segmenter's track errors (ID switches, merges)
  CaptureOptions capture;    // exposure, noise, JPEG, gloss, SfM-like pose error

  void Check() const;  // throws std::invalid_argument with a one-line message
};

// Generates the scene into out_dir: renders the world (render_scene.h),
// corrupts its ID maps as SAM2 would (sam2_corruption.h, track_errors.h), and
// writes it in the format asked for (scene_writers.h). The folder is built
// aside and swapped in whole; an existing out_dir (or ovs_dir) is replaced
// only with force (otherwise std::runtime_error).
void generate_scene(const SynthOptions& options, const std::filesystem::path& out_dir, bool force);

}  // namespace synth
