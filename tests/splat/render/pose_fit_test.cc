#include "splat/render/pose_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <sstream>

#include "tests/splat/render/scenes.h"

namespace splat {
namespace {

using testing_scenes::random_scene;
using testing_scenes::test_camera;

// Rotation angle (radians) and centre distance between two cameras.
std::pair<double, double> pose_error(const Camera& a, const Camera& b) {
  return {Eigen::AngleAxisd(a.R * b.R.transpose()).angle(), (a.center() - b.center()).norm()};
}

ImageRGB render_photo(const GaussianModel& m, const Camera& cam) {
  const CpuRenderer renderer;
  const RenderOutput out = renderer.render(m, cam, RenderSettings{});
  ImageRGB photo(cam.width, cam.height);
  photo.data.assign(out.color.begin(), out.color.end());
  return photo;
}

TEST(PoseFit, RecoversAPerturbedCameraFromItsPhoto) {
  GaussianModel m = random_scene(300, 31, 3, /*edge_cases=*/false);
  const Camera truth = test_camera(96, 72);
  const ImageRGB photo = render_photo(m, truth);
  // About 2 pixels of error in rotation and in translation.
  const Camera start = moved_in_camera_frame(truth, {0.02, -0.015, 0.03}, {0.004, -0.006, 0.003});
  const auto [angle0, distance0] = pose_error(start, truth);
  PoseFitOptions o;
  o.iterations = 150;
  const CpuRenderer renderer;
  const Camera fitted = fit_camera_to_photo(renderer, m, start, photo, RenderSettings{}, 4.0, o);
  const auto [angle, distance] = pose_error(fitted, truth);
  EXPECT_LT(angle, 0.25 * angle0) << angle0 << " -> " << angle << " rad";
  EXPECT_LT(distance, 0.25 * distance0) << distance0 << " -> " << distance;
}

TEST(PoseFit, NoStepsLeavesTheCamera) {
  const GaussianModel m = random_scene(20, 32);
  const Camera c = test_camera(32, 24);
  const Camera same = fit_camera_to_photo(CpuRenderer{}, m, c, render_photo(m, c), RenderSettings{},
                                          1.0, PoseFitOptions{});
  EXPECT_EQ(same.R, c.R);
  EXPECT_EQ(same.t, c.t);
}

TEST(ViewPoseCorrections, StepsComposeAndSaveExactly) {
  ViewPoseCorrections p(3);
  const Camera c = test_camera(32, 24);
  EXPECT_EQ(p.apply(1, c).R, c.R);
  p.step(1, {1, -2, 0.5, 0.1, 0, -3}, {1e-3f, 1e-2f});
  p.step(1, {0.5, -1, 1, 0.2, 0.1, -1}, {1e-3f, 1e-2f});
  EXPECT_GT(p.angle(1), 0.0);
  EXPECT_GT(p.distance(1), 0.0);
  EXPECT_EQ(p.angle(0), 0.0);
  // Adam's first step moves every component against its gradient by lr.
  ViewPoseCorrections one(1);
  one.step(0, {1, 0, 0, 0, 0, 0}, {1e-3f, 1e-2f});
  EXPECT_NEAR(one.distance(0), 1e-2, 1e-6);
  EXPECT_TRUE(
      one.apply(0, c)
          .world_to_camera(Eigen::Vector3d::Zero())
          .isApprox(c.world_to_camera(Eigen::Vector3d::Zero()) + Eigen::Vector3d(-1e-2, 0, 0),
                    1e-6));
  std::stringstream s;
  p.save(s);
  ViewPoseCorrections loaded;
  loaded.load(s);
  ASSERT_EQ(loaded.size(), 3u);
  EXPECT_EQ(loaded.apply(1, c).R, p.apply(1, c).R);
  EXPECT_EQ(loaded.apply(1, c).t, p.apply(1, c).t);
}

}  // namespace
}  // namespace splat
