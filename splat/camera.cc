#include "splat/camera.h"

#include <algorithm>
#include <cmath>

namespace splat {

Eigen::Vector3d Camera::pixel_ray(double u, double v) const {
  const Eigen::Vector3d dir_cam((u - cx) / fx, (v - cy) / fy, 1.0);
  return (R.transpose() * dir_cam).normalized();
}

Camera Camera::resized(int new_width, int new_height) const {
  Camera c = *this;
  const double sx = double(new_width) / width;
  const double sy = double(new_height) / height;
  c.width = new_width;
  c.height = new_height;
  c.fx *= sx;
  c.cx *= sx;
  c.fy *= sy;
  c.cy *= sy;
  if (uncropped_width) c.uncropped_width = int(std::lround(uncropped_width * sx));
  if (uncropped_height) c.uncropped_height = int(std::lround(uncropped_height * sy));
  return c;
}

Camera Camera::cropped(int x, int y, int new_width, int new_height) const {
  Camera c = *this;
  if (!c.uncropped_width) c.uncropped_width = width, c.uncropped_height = height;
  c.width = new_width;
  c.height = new_height;
  c.cx -= x;
  c.cy -= y;
  return c;
}

Camera moved_in_camera_frame(const Camera& camera, const Eigen::Vector3d& rho,
                             const Eigen::Vector3d& omega) {
  const double angle = omega.norm();
  const Eigen::Matrix3d dR = angle > 0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix()
                                       : Eigen::Matrix3d::Identity();
  Camera c = camera;
  c.R = dR * camera.R;
  c.t = dR * camera.t + rho;
  return c;
}

Camera Camera::look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                       const Eigen::Vector3d& up, int width, int height, double fx, double fy) {
  const Eigen::Vector3d forward = (target - eye).normalized();
  const Eigen::Vector3d right = forward.cross(up).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Camera c;
  c.width = width;
  c.height = height;
  c.fx = fx;
  c.fy = fy;
  c.cx = 0.5 * width;
  c.cy = 0.5 * height;
  c.R.row(0) = right.transpose();
  c.R.row(1) = down.transpose();
  c.R.row(2) = forward.transpose();
  c.t = -c.R * eye;
  return c;
}

Eigen::Matrix3d rotation_from_quaternion(const Eigen::Vector4d& q) {
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
}

Eigen::Vector4d quaternion_from_rotation(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  // COLMAP keeps qw >= 0; both signs are the same rotation.
  if (q.w() < 0) q.coeffs() *= -1.0;
  return {q.w(), q.x(), q.y(), q.z()};
}

double scene_extent(const std::vector<Camera>& cameras) {
  if (cameras.empty()) return 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Camera& c : cameras) mean += c.center();
  mean /= double(cameras.size());
  double radius = 0.0;
  for (const Camera& c : cameras) radius = std::max(radius, (c.center() - mean).norm());
  return 1.1 * radius;
}

}  // namespace splat
