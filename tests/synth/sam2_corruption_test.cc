#include "synth/sam2_corruption.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace synth {
namespace {

// Two touching rectangles and a small square on a background.
splat::IdMap blocks() {
  splat::IdMap m(160, 120);
  for (int y = 30; y < 90; ++y)
    for (int x = 20; x < 140; ++x) m.at(x, y) = x < 80 ? 1 : 2;
  for (int y = 100; y < 108; ++y)
    for (int x = 10; x < 18; ++x) m.at(x, y) = 3;
  return m;
}

double iou(const splat::IdMap& a, const splat::IdMap& b, int id) {
  size_t inter = 0, uni = 0;
  for (size_t i = 0; i < a.ids.size(); ++i) {
    inter += a.ids[i] == id && b.ids[i] == id;
    uni += a.ids[i] == id || b.ids[i] == id;
  }
  return uni ? double(inter) / uni : 1.0;
}

TEST(Sam2Corruption, ZeroStrengthIsExact) {
  Sam2CorruptionOptions o;
  o.strength = 0;
  EXPECT_EQ(corrupt_like_sam2(blocks(), {1, 2, 3}, o, 5).ids, blocks().ids);
}

TEST(Sam2Corruption, DefaultCorruptsButKeepsObjectsRecognisable) {
  const splat::IdMap truth = blocks();
  double mean = 0;
  int changed = 0;
  for (uint64_t seed = 0; seed < 20; ++seed) {
    const splat::IdMap m = corrupt_like_sam2(truth, {1, 2, 3}, Sam2CorruptionOptions{}, seed);
    for (int id : {1, 2}) {
      const double v = iou(truth, m, id);
      mean += v / 40;
      changed += v < 0.999;
    }
  }
  EXPECT_GT(mean, 0.75);
  EXPECT_LT(mean, 0.99);
  EXPECT_GT(changed, 30);
}

TEST(Sam2Corruption, EachEffectAlone) {
  const splat::IdMap truth = blocks();
  Sam2CorruptionOptions none;
  none.boundary_jitter_px = none.miss_probability = none.leak_probability = none.spurious_blobs = 0;

  Sam2CorruptionOptions miss = none;
  miss.miss_probability = 1;
  const splat::IdMap missed = corrupt_like_sam2(truth, {1, 2, 3}, miss, 1);
  for (size_t i = 0; i < truth.ids.size(); ++i)
    ASSERT_TRUE(missed.ids[i] == truth.ids[i] || missed.ids[i] == 0) << "misses only erase";
  EXPECT_LT(iou(truth, missed, 1), 1.0);

  Sam2CorruptionOptions leak = none;
  leak.leak_probability = 1;
  const splat::IdMap leaked = corrupt_like_sam2(truth, {1, 2, 3}, leak, 1);
  size_t one_into_two = 0;
  for (size_t i = 0; i < truth.ids.size(); ++i)
    one_into_two += truth.ids[i] == 2 && leaked.ids[i] == 1;
  EXPECT_GT(one_into_two, 0u) << "object 1 touches 2, so it leaks onto 2";

  Sam2CorruptionOptions jitter = none;
  jitter.boundary_jitter_px = 3;
  const splat::IdMap jittered = corrupt_like_sam2(truth, {1, 2, 3}, jitter, 1);
  EXPECT_LT(iou(truth, jittered, 1), 1.0);
  EXPECT_GT(iou(truth, jittered, 1), 0.8);

  Sam2CorruptionOptions blobs = none;
  blobs.spurious_blobs = 20;
  const splat::IdMap blobbed = corrupt_like_sam2(truth, {1, 2, 3}, blobs, 1);
  size_t background_labelled = 0;
  for (size_t i = 0; i < truth.ids.size(); ++i)
    background_labelled += truth.ids[i] == 0 && blobbed.ids[i] != 0;
  EXPECT_GT(background_labelled, 0u);
}

TEST(Sam2Corruption, DeterministicForSeed) {
  const Sam2CorruptionOptions o;
  EXPECT_EQ(corrupt_like_sam2(blocks(), {1, 2, 3}, o, 9).ids,
            corrupt_like_sam2(blocks(), {1, 2, 3}, o, 9).ids);
  EXPECT_NE(corrupt_like_sam2(blocks(), {1, 2, 3}, o, 9).ids,
            corrupt_like_sam2(blocks(), {1, 2, 3}, o, 10).ids);
}

TEST(Sam2Corruption, RejectsNegativeOptions) {
  Sam2CorruptionOptions o;
  o.miss_probability = -0.1;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o = {};
  o.persistence_views = 0.5;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

// How far the blocks of view i have moved right: a pixel a view, back to the
// start every 16 views, so that they stay in the image.
int shift(size_t i) { return int(i % 16); }

// A video of `n` views of the moving blocks.
std::vector<splat::IdMap> moving_blocks(int n) {
  std::vector<splat::IdMap> views;
  for (int i = 0; i < n; ++i) {
    const splat::IdMap b = blocks();
    splat::IdMap m(b.width, b.height);
    for (int y = 0; y < b.height; ++y)
      for (int x = 0; x + shift(i) < b.width; ++x) m.at(x + shift(i), y) = b.at(x, y);
    views.push_back(m);
  }
  return views;
}

// Misses only: the pixels of object 1 that a view erased, in the object's
// own frame (shifted back by the view's motion).
std::vector<std::vector<bool>> erased_parts(const std::vector<splat::IdMap>& truth,
                                            const std::vector<splat::IdMap>& corrupted) {
  std::vector<std::vector<bool>> parts;
  for (size_t i = 0; i < truth.size(); ++i) {
    std::vector<bool> erased(truth[i].ids.size(), false);
    for (int y = 0; y < truth[i].height; ++y)
      for (int x = shift(i); x < truth[i].width; ++x)
        erased[y * truth[i].width + x - shift(i)] =
            truth[i].at(x, y) == 1 && corrupted[i].at(x, y) == 0;
    parts.push_back(erased);
  }
  return parts;
}

TEST(Sam2Corruption, IndependentSequenceIsViewByView) {
  const auto truth = moving_blocks(4);
  const Sam2CorruptionOptions o;
  const auto seq = corrupt_sequence_like_sam2(truth, {1, 2, 3}, o, 7);
  ASSERT_EQ(seq.size(), truth.size());
  for (size_t i = 0; i < truth.size(); ++i)
    EXPECT_EQ(seq[i].ids, corrupt_like_sam2(truth[i], {1, 2, 3}, o, 7 * 31337 + i).ids) << i;
}

TEST(Sam2Corruption, PersistentMissesFollowTheObjectOverRuns) {
  const int n = 200;
  const auto truth = moving_blocks(n);
  Sam2CorruptionOptions o;
  o.boundary_jitter_px = o.leak_probability = o.spurious_blobs = 0;
  o.miss_probability = 0.3;
  const auto count = [&](double persistence, size_t* missed_views, size_t* same_as_previous) {
    o.persistence_views = persistence;
    const auto parts = erased_parts(truth, corrupt_sequence_like_sam2(truth, {1, 2, 3}, o, 3));
    *missed_views = *same_as_previous = 0;
    for (int i = 0; i < n; ++i) {
      const bool missed = std::count(parts[i].begin(), parts[i].end(), true) > 0;
      *missed_views += missed;
      *same_as_previous += missed && i > 0 && parts[i] == parts[i - 1];
    }
  };
  size_t independent_missed, independent_same, persistent_missed, persistent_same;
  count(1, &independent_missed, &independent_same);
  count(10, &persistent_missed, &persistent_same);
  // About 30% of the views miss a part either way...
  EXPECT_NEAR(independent_missed / double(n), 0.3, 0.1);
  EXPECT_NEAR(persistent_missed / double(n), 0.3, 0.15);
  // ...but with runs of 10 views, most misses repeat the previous view's
  // part exactly; independent ones never do.
  EXPECT_EQ(independent_same, 0u);
  EXPECT_GT(persistent_same, persistent_missed * 7 / 10);
}

Sam2CorruptionOptions no_per_view_errors() {
  Sam2CorruptionOptions o;
  o.boundary_jitter_px = o.miss_probability = o.leak_probability = o.spurious_blobs = 0;
  return o;
}

size_t area(const splat::IdMap& m, int id) {
  return size_t(std::count(m.ids.begin(), m.ids.end(), uint16_t(id)));
}

// A border bias holds for an object in every view: tight objects stay
// tight, loose ones loose, by an amount that grows with the object.
TEST(Sam2Corruption, BorderBiasIsTheSameSignForAnObjectInEveryView) {
  Sam2CorruptionOptions o = no_per_view_errors();
  o.border_bias = 0.2;
  const std::vector<splat::IdMap> truth = moving_blocks(12);
  int tight = 0, loose = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const std::vector<splat::IdMap> out = corrupt_sequence_like_sam2(truth, {1, 2, 3}, o, seed);
    for (int id : {1, 2}) {
      int shrunk = 0, grown = 0;
      for (size_t i = 0; i < truth.size(); ++i) {
        shrunk += area(out[i], id) < area(truth[i], id);
        grown += area(out[i], id) > area(truth[i], id);
      }
      EXPECT_TRUE(shrunk == 0 || grown == 0) << "object " << id << " seed " << seed;
      tight += shrunk == int(truth.size()), loose += grown == int(truth.size());
    }
  }
  EXPECT_GT(tight, 0);
  EXPECT_GT(loose, 0);
  // Dilation takes only background: the neighbour keeps its own pixels.
  o.border_bias = 1;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const splat::IdMap m = corrupt_like_sam2(blocks(), {1, 2, 3}, o, seed);
    for (size_t i = 0; i < m.ids.size(); ++i) {
      if (blocks().ids[i] != 0) {
        ASSERT_TRUE(m.ids[i] == blocks().ids[i] || m.ids[i] == 0);
      }
    }
  }
}

// A lost small object is background in every view where it is small, and a
// large object is never lost.
TEST(Sam2Corruption, SmallObjectsLostStayLostOverTheVideo) {
  Sam2CorruptionOptions o = no_per_view_errors();
  o.lose_small_objects = 1;
  o.small_object_area = 0.01;  // the 8 x 8 square (0.3% of the image), not the rectangles
  const std::vector<splat::IdMap> truth(5, blocks());
  const std::vector<splat::IdMap> out = corrupt_sequence_like_sam2(truth, {1, 2, 3}, o, 3);
  for (const splat::IdMap& m : out) {
    EXPECT_EQ(area(m, 3), 0u);
    EXPECT_EQ(area(m, 1), area(blocks(), 1));
    EXPECT_EQ(area(m, 2), area(blocks(), 2));
  }
  o.lose_small_objects = 0;
  for (const splat::IdMap& m : corrupt_sequence_like_sam2(truth, {1, 2, 3}, o, 3))
    EXPECT_EQ(m.ids, blocks().ids);
}

// Turning the whole-video errors on leaves the per-view errors as they were
// drawn: a map's change is the per-view one plus the bias, nothing else.
TEST(Sam2Corruption, VideoErrorsOffChangeNothing) {
  const std::vector<splat::IdMap> truth = moving_blocks(6);
  Sam2CorruptionOptions a, b;
  b.border_bias = 0;
  b.lose_small_objects = 0;
  const auto x = corrupt_sequence_like_sam2(truth, {1, 2, 3}, a, 9);
  const auto y = corrupt_sequence_like_sam2(truth, {1, 2, 3}, b, 9);
  for (size_t i = 0; i < x.size(); ++i) EXPECT_EQ(x[i].ids, y[i].ids);
}

}  // namespace
}  // namespace synth
