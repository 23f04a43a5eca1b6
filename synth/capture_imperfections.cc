#include "synth/capture_imperfections.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <stdexcept>

#include "splat/image_codec.h"

namespace synth {

CaptureOptions CaptureOptions::typical() {
  CaptureOptions o;
  o.exposure_stops = 0.25;  // auto-exposure wanders within about half a stop
  o.white_balance = 0.03;   // a few per cent between channels
  o.noise = 0.006;          // 1.5 / 255 in the shadows, 3.4 / 255 at white
  o.jpeg_quality = 90;      // a phone's default
  o.specular = 0.35;        // glossy plastic and painted surfaces
  // An image shift of about 1.2 px RMS at 320 px wide (2.3 px at 640): the
  // rotation's two in-plane axes and the centre's two lateral ones, seen
  // from the orbit's 3.2 units. More than COLMAP's reprojection error of a
  // good registration (which its bundle adjustment minimises), as the poses
  // of handheld video frames with blur and rolling shutter are off by.
  o.pose_rotation_degrees = 0.1;
  o.pose_translation = 0.002;
  o.focal_error = 0.005;
  return o;
}

bool CaptureOptions::photometric() const {
  return exposure_stops > 0 || white_balance > 0 || noise > 0 || jpeg_quality > 0;
}

bool CaptureOptions::geometric() const {
  return pose_rotation_degrees > 0 || pose_translation > 0 || focal_error > 0;
}

void CaptureOptions::Check() const {
  for (double v : {exposure_stops, white_balance, noise, specular, pose_rotation_degrees,
                   pose_translation, focal_error})
    if (!(v >= 0 && std::isfinite(v)))
      throw std::invalid_argument("capture imperfections must be finite and >= 0");
  if (!(drift_correlation >= 0 && drift_correlation < 1))
    throw std::invalid_argument("drift correlation must be in [0, 1)");
  if (jpeg_quality < 0 || jpeg_quality > 100)
    throw std::invalid_argument(
        fmt::format("JPEG quality must be in 0..100, not {}", jpeg_quality));
  if (focal_error >= 0.2) throw std::invalid_argument("focal error must be below 0.2");
}

std::vector<Eigen::Vector3d> view_gains(const CaptureOptions& o, int views, uint64_t seed) {
  std::mt19937_64 rng(seed * 0x2545F4914F6CDD1DULL + 3);
  std::normal_distribution<double> n01(0, 1);
  const double rho = o.drift_correlation;
  const double step = std::sqrt(1 - rho * rho);  // keeps the walk's variance stationary
  double exposure = n01(rng);
  Eigen::Vector3d balance(n01(rng), n01(rng), n01(rng));
  std::vector<Eigen::Vector3d> gains;
  for (int i = 0; i < views; ++i) {
    if (i > 0) {
      exposure = rho * exposure + step * n01(rng);
      for (int c = 0; c < 3; ++c) balance[c] = rho * balance[c] + step * n01(rng);
    }
    Eigen::Vector3d g;
    for (int c = 0; c < 3; ++c)
      g[c] = std::exp2(o.exposure_stops * exposure) * std::exp(o.white_balance * balance[c]);
    gains.push_back(g);
  }
  return gains;
}

void record_photo(splat::ImageRGB& image, const Eigen::Vector3d& gain, const CaptureOptions& o,
                  uint64_t seed) {
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ULL + 11);
  std::normal_distribution<float> n01(0, 1);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      float* p = image.pixel(x, y);
      for (int c = 0; c < 3; ++c) {
        float v = float(gain[c]) * p[c];
        if (o.noise > 0) v += float(o.noise) * std::sqrt(1 + 4 * std::max(v, 0.f)) * n01(rng);
        p[c] = std::clamp(v, 0.f, 1.f);
      }
    }
  }
  // Saved and read back as a JPEG, as the camera app would.
  if (o.jpeg_quality > 0) image = splat::decode_jpeg(splat::encode_jpeg(image, o.jpeg_quality));
}

std::vector<splat::Camera> sfm_like_cameras(const std::vector<splat::Camera>& truth,
                                            const CaptureOptions& o, double orbit_radius,
                                            uint64_t seed) {
  std::mt19937_64 rng(seed * 0xD1B54A32D192ED03ULL + 5);
  std::normal_distribution<double> n01(0, 1);
  const double focal_scale = 1 + o.focal_error * n01(rng);
  std::vector<splat::Camera> out;
  for (const splat::Camera& c : truth) {
    splat::Camera s = c;
    const Eigen::Vector3d axis_angle =
        o.pose_rotation_degrees * M_PI / 180 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    const Eigen::Vector3d shift =
        o.pose_translation * orbit_radius * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    const double angle = axis_angle.norm();
    const Eigen::Matrix3d turn =
        angle > 0 ? Eigen::AngleAxisd(angle, axis_angle / angle).toRotationMatrix()
                  : Eigen::Matrix3d::Identity();
    const Eigen::Vector3d centre = c.center() + shift;
    s.R = turn * c.R;
    s.t = -s.R * centre;
    s.fx *= focal_scale;
    s.fy *= focal_scale;
    out.push_back(s);
  }
  return out;
}

}  // namespace synth
