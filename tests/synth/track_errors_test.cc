#include "synth/track_errors.h"

#include <gtest/gtest.h>

#include <set>

namespace synth {
namespace {

// A sequence of identical views: objects 1 and 2 touch, 3 stands apart.
std::vector<splat::IdMap> sequence(int views) {
  splat::IdMap m(64, 48);
  for (int y = 10; y < 30; ++y)
    for (int x = 5; x < 45; ++x) m.at(x, y) = x < 25 ? 1 : 2;
  for (int y = 36; y < 44; ++y)
    for (int x = 50; x < 58; ++x) m.at(x, y) = 3;
  return std::vector<splat::IdMap>(size_t(views), m);
}

std::set<int> ids_in(const splat::IdMap& m) { return {m.ids.begin(), m.ids.end()}; }

TEST(TrackErrors, TouchingPairsAreThoseSharingABoundary) {
  const auto pairs = touching_pairs(sequence(3));
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], std::make_pair(1, 2));
}

TEST(TrackErrors, NoneByDefault) {
  const auto truth = sequence(20);
  auto maps = truth;
  EXPECT_TRUE(apply_track_errors(maps, truth, {1, 2, 3}, TrackErrorOptions{}, 1).empty());
  for (size_t i = 0; i < maps.size(); ++i) EXPECT_EQ(maps[i].ids, truth[i].ids);
}

TEST(TrackErrors, AnIdSwitchRenamesOneObjectForARunOfViews) {
  const auto truth = sequence(60);
  TrackErrorOptions o;
  o.id_switches = 1.5;
  o.switch_run_views = 8;
  int switched_views = 0;
  for (uint64_t seed = 0; seed < 10; ++seed) {
    auto maps = truth;
    const std::vector<int> fresh = apply_track_errors(maps, truth, {1, 2, 3}, o, seed);
    for (int id : fresh) EXPECT_GT(id, 3);
    for (size_t i = 0; i < maps.size(); ++i) {
      // Pixels keep their object: only the ID under which it is seen changes.
      for (size_t p = 0; p < maps[i].ids.size(); ++p)
        EXPECT_EQ(maps[i].ids[p] == 0, truth[i].ids[p] == 0);
      for (int id : ids_in(maps[i])) switched_views += id > 3;
    }
  }
  // About 10 seeds x 3 objects x 1.5 switches x 8 views (less where runs
  // overlap or leave the sequence).
  EXPECT_GT(switched_views, 100);
  EXPECT_LT(switched_views, 500);
}

TEST(TrackErrors, AMergeGivesTwoTouchingObjectsOneId) {
  const auto truth = sequence(40);
  TrackErrorOptions o;
  o.merges = 2;
  o.merge_run_views = 5;
  auto maps = truth;
  EXPECT_TRUE(apply_track_errors(maps, truth, {1, 2, 3}, o, 4).empty());
  int merged = 0;
  for (const splat::IdMap& m : maps) {
    const std::set<int> ids = ids_in(m);
    EXPECT_TRUE(ids.count(3));  // the lone object never merges
    if (ids.count(1) != ids.count(2)) ++merged;
    EXPECT_TRUE(ids.count(1) || ids.count(2));
  }
  EXPECT_GT(merged, 0);
  EXPECT_LT(merged, 40);
}

TEST(TrackErrors, ALateObjectIsUntrackedAtTheStart) {
  const auto truth = sequence(50);
  TrackErrorOptions o;
  o.late_objects = 1;  // every object
  o.late_fraction = 0.4;
  auto maps = truth;
  apply_track_errors(maps, truth, {1, 2, 3}, o, 9);
  EXPECT_EQ(ids_in(maps.front()), std::set<int>{0});
  EXPECT_EQ(ids_in(maps.back()), (std::set<int>{0, 1, 2, 3}));
  for (size_t i = 20; i < maps.size(); ++i) EXPECT_EQ(maps[i].ids, truth[i].ids);
}

TEST(TrackErrors, BadOptionsAreRefused) {
  TrackErrorOptions o;
  o.switch_run_views = 0;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o = {};
  o.late_objects = 2;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace synth
