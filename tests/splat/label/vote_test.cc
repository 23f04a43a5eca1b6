// Label voting on hand-built cases: occlusion, ties, background, many IDs.

#include "splat/label/vote.h"

#include <gtest/gtest.h>

#include <cmath>

#include "splat/id_maps.h"

namespace splat {
namespace {

// Adds an isotropic Gaussian; opacity near 1 unless given.
void add_gaussian(GaussianModel& m, Eigen::Vector3f mean, float scale, float opacity = 0.99f) {
  const size_t i = m.size();
  m.resize(i + 1);
  for (int k = 0; k < 3; ++k) {
    m.means[3 * i + k] = mean[k];
    m.log_scales[3 * i + k] = std::log(scale);
    m.sh_dc[3 * i + k] = 0.5f;
  }
  m.opacity_logits[i] = std::log(opacity / (1 - opacity));
}

Camera camera_at(Eigen::Vector3d eye, Eigen::Vector3d target, int size = 64) {
  return Camera::look_at(eye, target, {0, -1, 0}, size, size, size, size);
}

IdMap uniform_map(int size, uint16_t id) {
  IdMap m(size, size);
  std::fill(m.ids.begin(), m.ids.end(), id);
  return m;
}

VoteOptions frustum_only() {
  VoteOptions o;
  o.visibility = VoteVisibility::kFrustum;
  return o;
}

// One small Gaussian 4 units in front of a camera at the origin.
struct OneGaussian {
  GaussianModel model;
  Camera camera = camera_at({0, 0, 0}, {0, 0, 4});
  OneGaussian() { add_gaussian(model, {0, 0, 4}, 0.05f); }
};

// A big opaque Gaussian at z = 2 hides a small one at z = 4 from a camera at
// the origin; a second camera sees the small one from the side.
struct OcclusionCase {
  GaussianModel model;
  Camera front = camera_at({0, 0, 0}, {0, 0, 4});
  Camera side = camera_at({4, 0, 4}, {0, 0, 4});
  OcclusionCase() {
    add_gaussian(model, {0, 0, 2}, 0.5f);
    add_gaussian(model, {0, 0, 4}, 0.05f);
  }
};

TEST(Vote, OccludedGaussianDoesNotVoteInTheOccludingView) {
  OcclusionCase c;
  const CpuRenderer renderer;
  VoteOptions options;  // depth culling
  LabelVotes votes(c.model.size());
  const DepthMap front_depth = render_depth_map(renderer, c.model, c.front, options);
  const DepthMap side_depth = render_depth_map(renderer, c.model, c.side, options);
  // The front view sees the big Gaussian's surface at depth ~2.
  EXPECT_NEAR(front_depth.depth[32 * 64 + 32], 2.0f, 0.1f);
  votes.add_view(c.model, c.front, uniform_map(64, 1), &front_depth, options);
  votes.add_view(c.model, c.side, uniform_map(64, 2), &side_depth, options);
  EXPECT_EQ(votes.votes(1), 1u);  // only the side view
  EXPECT_EQ(votes.labels()[1], 2);
  EXPECT_EQ(votes.labels()[0], 1);  // the big one is visible in the front view

  // Without depth culling the hidden Gaussian votes in both views: a tie,
  // which goes to the smaller ID.
  options.visibility = VoteVisibility::kFrustum;
  LabelVotes frustum(c.model.size());
  frustum.add_view(c.model, c.front, uniform_map(64, 1), nullptr, options);
  frustum.add_view(c.model, c.side, uniform_map(64, 2), nullptr, options);
  EXPECT_EQ(frustum.votes(1), 2u);
  EXPECT_EQ(frustum.labels()[1], 1);
}

TEST(Vote, MajorityWinsAndTiesGoToTheSmallestId) {
  const OneGaussian g;
  const GaussianModel& m = g.model;
  const Camera& cam = g.camera;
  const VoteOptions o = frustum_only();
  LabelVotes votes(1);
  votes.add_view(m, cam, uniform_map(64, 7), nullptr, o);
  votes.add_view(m, cam, uniform_map(64, 3), nullptr, o);
  EXPECT_EQ(votes.labels()[0], 3);  // 1:1, smallest ID
  votes.add_view(m, cam, uniform_map(64, 7), nullptr, o);
  EXPECT_EQ(votes.labels()[0], 7);  // 2:1
  EXPECT_EQ(votes.votes(0), 3u);
  EXPECT_EQ(votes.votes_for_label(0), 2u);
}

TEST(Vote, BackgroundVotesCountAndUnseenGaussiansGetZero) {
  GaussianModel m;
  add_gaussian(m, {0, 0, 4}, 0.05f);     // seen: background twice, object once
  add_gaussian(m, {0, 0, -4}, 0.05f);    // behind the camera
  add_gaussian(m, {50, 0, 4}, 0.05f);    // outside the image
  add_gaussian(m, {0, 0, 0.1f}, 0.05f);  // in front of the near plane
  const Camera cam = camera_at({0, 0, 0}, {0, 0, 4});
  const VoteOptions o = frustum_only();
  LabelVotes votes(m.size());
  votes.add_view(m, cam, uniform_map(64, 0), nullptr, o);
  votes.add_view(m, cam, uniform_map(64, 0), nullptr, o);
  votes.add_view(m, cam, uniform_map(64, 4), nullptr, o);
  const std::vector<int32_t> labels = votes.labels();
  EXPECT_EQ(labels[0], 0);
  EXPECT_EQ(votes.votes(0), 3u);
  for (size_t j = 1; j < m.size(); ++j) {
    EXPECT_EQ(labels[j], 0);
    EXPECT_EQ(votes.votes(j), 0u) << j;
  }
}

TEST(Vote, ManyDistinctIdsAreCountedExactly) {
  const OneGaussian g;
  const GaussianModel& m = g.model;
  const Camera& cam = g.camera;
  const VoteOptions o = frustum_only();
  LabelVotes votes(1);
  // ID k gets k votes for k = 1..6, more IDs than are counted inline.
  for (uint16_t k = 1; k <= 6; ++k)
    for (int n = 0; n < k; ++n) votes.add_view(m, cam, uniform_map(64, k), nullptr, o);
  EXPECT_EQ(votes.labels()[0], 6);
  EXPECT_EQ(votes.votes(0), 21u);
  EXPECT_EQ(votes.votes_for_label(0), 6u);
}

TEST(Vote, ReadsTheIdAtTheCentresPixel) {
  GaussianModel m;
  add_gaussian(m, {0, 0, 4}, 0.05f);    // projects to the image centre
  add_gaussian(m, {-1, -1, 4}, 0.05f);  // to one of the corner quarters
  const Camera cam = camera_at({0, 0, 0}, {0, 0, 4});
  IdMap ids(64, 64);  // a different ID in each quarter
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) ids.at(x, y) = uint16_t(1 + (x >= 32) + 2 * (y >= 32));
  const VoteOptions o = frustum_only();
  LabelVotes votes(2);
  votes.add_view(m, cam, ids, nullptr, o);
  const Eigen::Vector2d p = cam.project({-1, -1, 4});
  const int corner_id = ids.at(int(p.x()), int(p.y()));
  EXPECT_NE(corner_id, 4);
  EXPECT_EQ(votes.labels()[0], 4);  // pixel (32, 32)
  EXPECT_EQ(votes.labels()[1], corner_id);
}

TEST(IdMaps, NearestResizeFollowsPillowsRule) {
  IdMap m(3, 1);
  m.ids = {10, 20, 30};
  EXPECT_EQ(resize_id_map_nearest(m, 2, 1).ids, (std::vector<uint16_t>{10, 30}));
  IdMap n(2, 1);
  n.ids = {1, 2};
  EXPECT_EQ(resize_id_map_nearest(n, 5, 1).ids, (std::vector<uint16_t>{1, 1, 2, 2, 2}));
}

}  // namespace
}  // namespace splat
