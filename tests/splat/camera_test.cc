#include "splat/camera.h"

#include <gtest/gtest.h>

#include <random>

namespace splat {
namespace {

TEST(Camera, LookAtProjectsTargetToPrincipalPoint) {
  const Camera c =
      Camera::look_at({3, 2, 1}, {0, 0.5, 0}, Eigen::Vector3d::UnitY(), 320, 240, 300, 300);
  const Eigen::Vector2d px = c.project({0, 0.5, 0});
  EXPECT_NEAR(px.x(), 160.0, 1e-9);
  EXPECT_NEAR(px.y(), 120.0, 1e-9);
  EXPECT_NEAR((c.center() - Eigen::Vector3d(3, 2, 1)).norm(), 0.0, 1e-12);
  // y down in the camera frame: a point above the target projects higher (smaller v).
  EXPECT_LT(c.project({0, 1.0, 0}).y(), 120.0);
}

TEST(Camera, PixelRayInvertsProjection) {
  const Camera c = Camera::look_at({0, 1, -4}, {0, 0, 0}, Eigen::Vector3d::UnitY(), 64, 48, 50, 55);
  const Eigen::Vector3d dir = c.pixel_ray(10.25, 30.5);
  const Eigen::Vector2d back = c.project(c.center() + 2.5 * dir);
  EXPECT_NEAR(back.x(), 10.25, 1e-9);
  EXPECT_NEAR(back.y(), 30.5, 1e-9);
}

TEST(Camera, ACroppedCameraProjectsToTheSamePixelsLessTheOffset) {
  const Camera c = Camera::look_at({0, 1, -4}, {0, 0, 0}, Eigen::Vector3d::UnitY(), 64, 48, 50, 55);
  const Camera half = c.cropped(32, 0, 32, 48);
  EXPECT_EQ(half.width, 32);
  EXPECT_EQ(half.height, 48);
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(0.3, 0.1, 0.2), Eigen::Vector3d(-0.4, 0, 1)}) {
    EXPECT_NEAR((half.project(x) - (c.project(x) - Eigen::Vector2d(32, 0))).norm(), 0.0, 1e-12);
    EXPECT_NEAR(
        (c.cropped(5, 7, 10, 10).project(x) - (c.project(x) - Eigen::Vector2d(5, 7))).norm(), 0.0,
        1e-12);
  }
  EXPECT_EQ(half.fx, c.fx);
  EXPECT_EQ(half.fy, c.fy);
  EXPECT_TRUE(half.R == c.R && half.t == c.t);
  // The field of view, which clamps the projection, stays the whole view's,
  // also when a crop is cropped again or resized with its view.
  EXPECT_EQ(half.tan_half_fov_x(), c.tan_half_fov_x());
  EXPECT_EQ(half.tan_half_fov_y(), c.tan_half_fov_y());
  EXPECT_EQ(half.cropped(0, 0, 16, 48).tan_half_fov_x(), c.tan_half_fov_x());
  EXPECT_DOUBLE_EQ(c.resized(32, 24).cropped(16, 0, 16, 24).tan_half_fov_x(), c.tan_half_fov_x());
}

TEST(Camera, QuaternionRoundTripKeepsQwNonNegative) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n;
  for (int i = 0; i < 100; ++i) {
    Eigen::Vector4d q(n(rng), n(rng), n(rng), n(rng));
    q.normalize();
    const Eigen::Matrix3d R = rotation_from_quaternion(q);
    const Eigen::Vector4d back = quaternion_from_rotation(R);
    EXPECT_GE(back[0], 0.0);
    EXPECT_LT((rotation_from_quaternion(back) - R).norm(), 1e-12);
  }
}

TEST(Camera, ResizedScalesIntrinsics) {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 500;
  c.cx = 320;
  c.cy = 240;
  const Camera h = c.resized(320, 240);
  EXPECT_DOUBLE_EQ(h.fx, 250);
  EXPECT_DOUBLE_EQ(h.cx, 160);
  EXPECT_DOUBLE_EQ(h.tan_half_fov_x(), c.tan_half_fov_x());
}

TEST(Camera, SceneExtentIsReferenceDefinition) {
  std::vector<Camera> cams;
  for (const auto& eye :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, 3, 0)}) {
    Camera c;
    c.t = -eye;  // R = I: centre = eye
    cams.push_back(c);
  }
  // Mean (0, 1, 0); farthest centre (0, 3, 0) at distance 2.
  EXPECT_NEAR(scene_extent(cams), 1.1 * 2.0, 1e-12);
  EXPECT_EQ(scene_extent({}), 0.0);
}

}  // namespace
}  // namespace splat
