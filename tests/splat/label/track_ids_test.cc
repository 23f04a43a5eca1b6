// Joining the IDs of a lost and re-found track, on votes cast by hand.

#include "splat/label/track_ids.h"

#include <gtest/gtest.h>

namespace splat {
namespace {

// Gaussians 4 units in front of a camera at the origin, one per column of
// the ID maps; each view's ID map gives Gaussian j the ID ids[j].
struct Row {
  GaussianModel model;
  Camera camera = Camera::look_at({0, 0, 0}, {0, 0, 4}, {0, -1, 0}, 64, 64, 64, 64);
  explicit Row(int n) {
    model.resize(size_t(n));
    for (int j = 0; j < n; ++j) {
      // Pixel column 2 + 4 j, row 32.
      const double x = (2.5 + 4 * j - 32) / 64.0 * 4;
      model.means[3 * j] = float(x), model.means[3 * j + 1] = 0, model.means[3 * j + 2] = 4;
    }
  }
  IdMap view(const std::vector<uint16_t>& ids) const {
    IdMap m(64, 64);
    for (int y = 0; y < 64; ++y)
      for (size_t j = 0; j < ids.size(); ++j)
        for (int x = int(4 * j); x < int(4 * j + 4); ++x) m.at(x, y) = ids[j];
    return m;
  }
};

VoteOptions frustum() {
  VoteOptions o;
  o.visibility = VoteVisibility::kFrustum;
  return o;
}

// Object A (Gaussians 0-3) is tracked as 1, but as 7 in views 6-9; object B
// (Gaussians 4-7) is 2 throughout and touches A (Gaussian 3 is seen as 2 in
// a few views). Gaussians 2 and 3 are hidden (background) in views 3-5.
struct SwitchCase {
  Row row{8};
  LabelVotes votes{8};
  IdCooccurrence together;
  SwitchCase() {
    for (int v = 0; v < 10; ++v) {
      const uint16_t a = v >= 6 ? 7 : 1;
      std::vector<uint16_t> ids = {a, a, a, a, 2, 2, 2, 2};
      if (v >= 3 && v <= 5) ids[2] = ids[3] = 0;  // behind something: seen as background
      if (v % 4 == 0) ids[3] = 2;                 // the border leaks
      const IdMap map = row.view(ids);
      votes.add_view(row.model, row.camera, map, nullptr, frustum());
      together.add_view(segments_in_map(map, 0));
    }
  }
};

TEST(TrackIds, PlainVotingSplitsTheObjectAcrossItsTwoIds) {
  SwitchCase c;
  const std::vector<int32_t> labels = c.votes.labels();
  EXPECT_EQ(labels[0], 1);
  EXPECT_EQ(labels[2], 7);  // seen more often under the new ID
  EXPECT_EQ(labels[5], 2);
}

TEST(TrackIds, TheSwitchedIdIsJoinedToTheTrackItContinues) {
  SwitchCase c;
  const LabelVotes::IdAssociation a = c.votes.id_association();
  EXPECT_NEAR(a.votes.at(7), 15, 1e-9);  // 4 views x 4 Gaussians, but one leak
  // Gaussians 0-1 carry 1 in 6 of their 10 views, Gaussians 2-3 in 3 and 2.
  EXPECT_GT(a.association(7, 1), 0.3);
  EXPECT_LT(a.association(2, 1), 0.1);
  const TrackIdResult r = find_switched_ids(a, c.together, TrackIdOptions{});
  ASSERT_EQ(r.groups.size(), 1u);
  EXPECT_EQ(r.groups[0].kept, 1);
  EXPECT_EQ(r.groups[0].joined, std::vector<int32_t>{7});
  c.votes.remap_ids(r.canonical);
  const std::vector<int32_t> labels = c.votes.labels();
  for (int j = 0; j < 4; ++j) EXPECT_EQ(labels[size_t(j)], 1) << j;
  for (int j = 4; j < 8; ++j) EXPECT_EQ(labels[size_t(j)], 2) << j;
  EXPECT_EQ(c.votes.votes(2), 10u);  // remapping keeps every vote
}

TEST(TrackIds, IdsSeenTogetherAreNeverJoined) {
  LabelVotes::IdAssociation a;
  a.votes = {{1, 10}, {2, 10}};
  a.shared[{1, 2}] = 9;  // they share nearly every Gaussian...
  IdCooccurrence together;
  for (int v = 0; v < 10; ++v) together.add_view({1, 2});  // ...but are seen side by side
  EXPECT_TRUE(find_switched_ids(a, together, TrackIdOptions{}).groups.empty());
}

TEST(TrackIds, AGroupTakesNoIdSeenWithOneOfItsMembers) {
  // 3 continues 1 and 2 continues... both 1 and 2, which are seen together:
  // 3 joins the one it shares more Gaussians with.
  LabelVotes::IdAssociation a;
  a.votes = {{1, 100}, {2, 100}, {3, 20}};
  a.shared[{1, 3}] = 12;
  a.shared[{2, 3}] = 8;
  IdCooccurrence together;
  for (int v = 0; v < 10; ++v) together.add_view({1, 2});
  for (int v = 0; v < 3; ++v) together.add_view({3});
  const TrackIdResult r = find_switched_ids(a, together, TrackIdOptions{});
  ASSERT_EQ(r.groups.size(), 1u);
  EXPECT_EQ(r.groups[0].kept, 1);
  EXPECT_EQ(r.groups[0].joined, std::vector<int32_t>{3});
}

TEST(TrackIds, ASegmentCoveringAnotherObjectIsFound) {
  // 40 Gaussians: 0-19 object 1, 20-39 object 2 (16 columns per pixel band).
  Row row(16);
  GaussianModel model;
  for (int copy = 0; copy < 3; ++copy) {  // three Gaussians per column: enough to count
    const size_t n = model.size();
    model.resize(n + row.model.size());
    std::copy(row.model.means.begin(), row.model.means.end(), model.means.begin() + 3 * long(n));
  }
  std::vector<int32_t> labels;
  for (int copy = 0; copy < 3; ++copy)
    for (int j = 0; j < 16; ++j) labels.push_back(j < 8 ? 1 : 2);
  TrackIdOptions o;
  o.min_visible = 10;
  const std::vector<uint16_t> apart = {1, 1, 1, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 2, 2, 2};
  std::vector<uint16_t> merged = apart;
  std::fill(merged.begin() + 8, merged.begin() + 14, 1);  // 1 spills over most of 2
  EXPECT_TRUE(
      find_merged_segments(model, labels, row.camera, row.view(apart), nullptr, frustum(), {}, o)
          .empty());
  const auto found =
      find_merged_segments(model, labels, row.camera, row.view(merged), nullptr, frustum(), {}, o);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].id, 1);
  EXPECT_EQ(found[0].covers, std::vector<int32_t>{2});
  // A switched ID that names object 1 is read as 1 first: no merge.
  std::vector<uint16_t> switched = apart;
  std::fill(switched.begin(), switched.begin() + 8, 7);
  EXPECT_TRUE(find_merged_segments(model, labels, row.camera, row.view(switched), nullptr,
                                   frustum(), {{7, 1}}, o)
                  .empty());
}

TEST(TrackIds, SpecksDoNotCountAsSeen) {
  IdMap m(100, 100);
  for (int i = 0; i < 2000; ++i) m.ids[size_t(i)] = 1;
  for (int i = 2000; i < 2010; ++i) m.ids[size_t(i)] = 2;
  EXPECT_EQ(segments_in_map(m, 5e-4), std::vector<int32_t>{1});
}

TEST(TrackIds, BadOptionsAreRefused) {
  TrackIdOptions o;
  o.min_association = 0;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace splat
