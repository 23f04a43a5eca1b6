#include "splat/pose_file.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>

#include "splat/camera.h"
#include "splat/error.h"
#include "tests/test_util.h"

namespace splat {
namespace {

using testing_util::TempDir;

TEST(PoseFile, WritesAndReadsPosesByName) {
  TempDir dir;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const std::vector<NamedPose> poses = {{"frame 001.jpg", R, {0.1, -2, 3.5}},
                                        {"b.png", Eigen::Matrix3d::Identity(), {0, 0, 0}}};
  write_pose_file(dir / "poses.txt", poses);
  const std::vector<NamedPose> read = read_pose_file(dir / "poses.txt");
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].name, "frame 001.jpg");  // a name with a space
  EXPECT_TRUE(read[0].R.isApprox(R, 1e-10));
  EXPECT_TRUE(read[0].t.isApprox(poses[0].t, 1e-10));
  EXPECT_EQ(read[1].name, "b.png");
}

TEST(PoseFile, BadLinesAreErrorsNamingTheFileAndLine) {
  TempDir dir;
  auto error_of = [&](const std::string& text) -> std::string {
    std::ofstream(dir / "p.txt") << text;
    try {
      read_pose_file(dir / "p.txt");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error_of("# c\n1 0 0 0 1 2\n").find("p.txt: line 2"), std::string::npos);
  EXPECT_NE(error_of("2 0 0 0 1 2 3 a.png\n").find("unit quaternion"), std::string::npos);
  EXPECT_NE(error_of("1 0 0 0 1 2 3 a.png\n1 0 0 0 0 0 0 a.png\n").find("given twice"),
            std::string::npos);
  EXPECT_THROW(read_pose_file(dir / "missing.txt"), InputError);
}

TEST(Camera, MovedInCameraFrameMovesCameraCoordinates) {
  const Camera c = Camera::look_at({1, 2, -3}, {0, 0, 0}, Eigen::Vector3d::UnitY(), 64, 48, 50, 50);
  const Eigen::Vector3d rho(0.01, -0.02, 0.03), omega(0.002, 0.001, -0.003);
  const Camera moved = moved_in_camera_frame(c, rho, omega);
  const Eigen::Vector3d x(0.2, -0.1, 0.4);
  const Eigen::Matrix3d dR = Eigen::AngleAxisd(omega.norm(), omega.normalized()).toRotationMatrix();
  EXPECT_TRUE(moved.world_to_camera(x).isApprox(dR * c.world_to_camera(x) + rho, 1e-12));
}

}  // namespace
}  // namespace splat
