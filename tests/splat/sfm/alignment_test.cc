// Similarity alignment recovers a known transform; pose accuracy of a model
// against itself moved by a similarity is zero.

#include "splat/sfm/alignment.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace splat {
namespace {

TEST(Alignment, RecoversAKnownSimilarity) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  Similarity truth;
  truth.scale = 2.5;
  truth.R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  truth.t = {1, -2, 0.5};
  std::vector<Eigen::Vector3d> from, to;
  for (int i = 0; i < 20; ++i) {
    from.emplace_back(g(rng), g(rng), g(rng));
    to.push_back(truth.apply(from.back()));
  }
  const Similarity s = align_similarity(from, to);
  EXPECT_NEAR(s.scale, 2.5, 1e-9);
  EXPECT_LT((s.R - truth.R).norm(), 1e-9);
  EXPECT_LT((s.t - truth.t).norm(), 1e-9);
  EXPECT_THROW(align_similarity({from[0], from[1]}, {to[0], to[1]}), std::invalid_argument);
}

TEST(Alignment, PoseAccuracyOfAMovedModelIsZero) {
  ColmapModel truth, moved;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const Similarity s{
      0.5, Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitY()).toRotationMatrix(), {3, 0, 1}};
  for (uint32_t i = 1; i <= 8; ++i) {
    const Eigen::Vector3d eye(3 * std::cos(i), u(rng), 3 * std::sin(i));
    const Camera c = Camera::look_at(eye, {0, 0, 0}, Eigen::Vector3d::UnitY(), 10, 10, 10, 10);
    ColmapImage im;
    im.image_id = i;
    im.name = fmt::format("v{}", i);
    im.qvec = quaternion_from_rotation(c.R);
    im.tvec = c.t;
    truth.images[i] = im;
    // The same camera in a frame where x_moved = s^-1 (x_true).
    const Eigen::Matrix3d R = c.R * s.R;
    const Eigen::Vector3d center = s.R.transpose() * (c.center() - s.t) / s.scale;
    im.qvec = quaternion_from_rotation(R);
    im.tvec = -R * center;
    moved.images[i] = im;
  }
  const PoseAccuracy acc = pose_accuracy(moved, truth);
  EXPECT_EQ(acc.matched, 8u);
  EXPECT_LT(acc.center_rmse, 1e-9);
  EXPECT_LT(acc.rotation_error_deg, 1e-6);
  EXPECT_NEAR(acc.alignment.scale, 0.5, 1e-9);
}

}  // namespace
}  // namespace splat
