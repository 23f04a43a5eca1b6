#pragma once
// What separates a real capture from a perfect rendering, added to the
// synthetic scene's photos and camera files so that the test bed has the
// imperfections real captures have (a phone video with auto-exposure, SfM
// poses, compressed frames). Every effect is seeded and off by default;
// CaptureOptions::typical() is the --capture preset.
//
//   exposure / white balance  auto-exposure and auto-white-balance drift: a
//                             gain per view and channel that wanders slowly
//                             along the sequence (an AR(1) walk in log space)
//   noise                     sensor noise: read noise plus shot noise that
//                             grows with brightness
//   jpeg_quality              the photos pass through JPEG at this quality
//   specular                  glossy objects: view-dependent highlights
//                             (applied by the ray tracer, World::specular)
//   pose / focal error        the camera files hold SfM-like poses and focal
//                             length with small errors; the photos are
//                             rendered from the true cameras

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "splat/camera.h"
#include "splat/image.h"

namespace synth {

struct CaptureOptions {
  // Standard deviation over the sequence of a view's exposure, in stops.
  double exposure_stops = 0;
  // Standard deviation of a view's per-channel white-balance gain, in log units.
  double white_balance = 0;
  // Correlation of the exposure and white balance of consecutive views.
  double drift_correlation = 0.85;
  // Sensor noise: a pixel of intensity I (in [0, 1]) gets Gaussian noise of
  // standard deviation noise * sqrt(1 + 4 I): read noise in the shadows,
  // shot noise growing with brightness (2.2 times as much at white).
  double noise = 0;
  int jpeg_quality = 0;  // 1..100; 0: no compression
  // Strength of the objects' specular highlights (0: Lambertian as before).
  double specular = 0;
  // Standard deviation of the camera files' rotation error (degrees, per
  // axis) and camera-centre error (fraction of the orbit radius, per axis).
  double pose_rotation_degrees = 0;
  double pose_translation = 0;
  // Relative error of the focal length in the camera files (one value for
  // the shared camera, drawn with this standard deviation).
  double focal_error = 0;

  // The --capture preset: every imperfection at a strength typical of a
  // handheld phone capture registered by COLMAP (docs/synthetic.md).
  static CaptureOptions typical();
  bool photometric() const;  // any effect on the photos' pixels
  bool geometric() const;    // any error in the camera files
  void Check() const;        // throws std::invalid_argument with a one-line message
};

// Per view, the gain of each colour channel (exposure times white balance).
std::vector<Eigen::Vector3d> view_gains(const CaptureOptions& options, int views, uint64_t seed);

// The photo as the camera records it: gain, noise, clipping, JPEG.
void record_photo(splat::ImageRGB& image, const Eigen::Vector3d& gain,
                  const CaptureOptions& options, uint64_t seed);

// The cameras as SfM would report them: each pose disturbed (rotation about
// the camera centre, then the centre moved), every focal length scaled by
// one shared error. orbit_radius scales the centre error.
std::vector<splat::Camera> sfm_like_cameras(const std::vector<splat::Camera>& truth,
                                            const CaptureOptions& options, double orbit_radius,
                                            uint64_t seed);

}  // namespace synth
