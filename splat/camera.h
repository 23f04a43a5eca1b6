#pragma once
// Pinhole cameras in COLMAP's conventions.
//
// Camera frame: x right, y down, z forward. The pose is world-to-camera:
// x_cam = R * x_world + t. Pixel coordinates follow COLMAP too: the centre of
// pixel (i, j) is at (i + 0.5, j + 0.5), so u = fx * x / z + cx with cx = W / 2
// for a centred principal point. The rasterizer uses the same convention.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace splat {

struct Camera {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // world-to-camera rotation
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // world-to-camera translation

  Eigen::Vector3d center() const { return -R.transpose() * t; }
  Eigen::Vector3d world_to_camera(const Eigen::Vector3d& x) const { return R * x + t; }
  // Pixel coordinates of a camera-space point (z must be > 0).
  Eigen::Vector2d camera_to_pixel(const Eigen::Vector3d& xc) const {
    return {fx * xc.x() / xc.z() + cx, fy * xc.y() / xc.z() + cy};
  }
  Eigen::Vector2d project(const Eigen::Vector3d& x) const {
    return camera_to_pixel(world_to_camera(x));
  }
  // World-space direction (unit) of the ray through pixel coordinates (u, v).
  Eigen::Vector3d pixel_ray(double u, double v) const;

  // A camera cut from a larger view (cropped()) keeps that view's size here;
  // 0 for a whole view. The field of view, and with it the projection's
  // Jacobian clamp, stays the view's, so a crop renders each of its pixels
  // as the whole view does.
  int uncropped_width = 0, uncropped_height = 0;

  // Of the whole view (for a crop, of the view it was cut from).
  double tan_half_fov_x() const { return 0.5 * (uncropped_width ? uncropped_width : width) / fx; }
  double tan_half_fov_y() const {
    return 0.5 * (uncropped_height ? uncropped_height : height) / fy;
  }

  // The same camera for an image resized to new_width x new_height.
  Camera resized(int new_width, int new_height) const;
  // The same camera for the width x height rectangle of its image whose
  // top-left pixel is (x, y): the principal point moves, and the field of
  // view stays the whole view's (uncropped_width, uncropped_height).
  Camera cropped(int x, int y, int new_width, int new_height) const;

  // A camera at `eye` looking at `target` with world `up` (y up by default).
  static Camera look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                        const Eigen::Vector3d& up, int width, int height, double fx, double fy);
};

// The camera moved by a pose change given in its own frame: a world point's
// camera coordinates become exp([omega]x) x_cam + rho (omega an axis-angle
// vector). The parameterisation of pose refinement and of
// GaussianGradients::camera.
Camera moved_in_camera_frame(const Camera& camera, const Eigen::Vector3d& rho,
                             const Eigen::Vector3d& omega);

// COLMAP stores rotations as unit quaternions qw qx qy qz.
Eigen::Matrix3d rotation_from_quaternion(const Eigen::Vector4d& qwxyz);
Eigen::Vector4d quaternion_from_rotation(const Eigen::Matrix3d& R);

// The reference 3DGS scene extent ("cameras_extent"): 1.1 times the largest
// distance of a camera centre from the mean of the camera centres.
double scene_extent(const std::vector<Camera>& cameras);

}  // namespace splat
