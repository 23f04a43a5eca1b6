#pragma once
// Video segmenters (SAM2, DEVA) lose a track and find the object again under
// a new ID. Voting then splits the object: the Gaussians seen mostly while it
// carried the new ID get that ID, the others the old one, and a mask for
// either ID shows part of the object. This finds the IDs that name one object
// and maps them to one label before the majority is taken.
//
// Two IDs name one object when
//   - they are (almost) never both in one view: a segmenter gives an object
//     one ID per frame, while two objects are seen together somewhere; and
//   - they label the same Gaussians: the Gaussians that carry one ID in some
//     views carry the other in a large share of the other views that see
//     them (LabelVotes::IdAssociation). Touching objects share only the
//     Gaussians on their common border, a small share.
// IDs are joined greedily, most associated pair first, and never into a
// group holding an ID seen together with one of the other group's. The group
// keeps the ID with the most votes.
//
// The opposite error, one ID covering two touching objects for a while (a
// merge), leaves the vote alone: the two objects are seen apart in most
// views, so each Gaussian's majority stays its own object's unless the merge
// lasts most of the sequence. It harms stage two instead, whose object loss
// would teach the segment's object to cover the other one. Once the labels
// are known, find_merged_segments finds such segments: in one view, an ID
// whose segment holds most of another object's visible Gaussians. Stage two
// then does not sample that ID in that view.

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "splat/label/vote.h"

namespace splat {

// Which IDs appear in each view, and which appear together.
class IdCooccurrence {
 public:
  // ids: the IDs whose segment in the view is large enough to count (0 ignored).
  void add_view(const std::vector<int32_t>& ids);
  size_t views(int32_t id) const;
  size_t together(int32_t a, int32_t b) const;
  const std::map<int32_t, size_t>& views_per_id() const { return views_; }

 private:
  std::map<int32_t, size_t> views_;
  std::map<std::pair<int32_t, int32_t>, size_t> together_;
};

// The IDs whose segment in an ID map covers at least min_share of its pixels
// (and at least 16 pixels): smaller specks are the segmenter's noise.
std::vector<int32_t> segments_in_map(const IdMap& map, double min_share);

struct TrackIdOptions {
  // Join two IDs when the Gaussians of one carry the other in at least this
  // share of the views that see them.
  double min_association = 0.3;
  // ... and they appear together in at most this share of the views where
  // the rarer of the two appears.
  double max_together = 0.05;
  // Segments below this share of a view's pixels do not count as appearing.
  double min_segment_share = 5e-4;
  // A segment covers another object when it holds at least this share of the
  // object's Gaussians visible in the view (and at least min_visible of them).
  double min_covered_share = 0.5;
  int min_visible = 20;

  void Check() const;  // throws std::invalid_argument with a one-line message
};

// One object seen under several IDs: the IDs joined and the ID they keep.
struct JoinedIds {
  int32_t kept = 0;
  std::vector<int32_t> joined;  // the others, ascending
};

// The groups of IDs that name one object; `canonical` maps every joined ID
// to the ID its group keeps (for LabelVotes::remap_ids).
// A pair of IDs that share Gaussians, as the decision saw it (for the summary).
struct IdPair {
  int32_t a = 0, b = 0;
  double a_to_b = 0, b_to_a = 0;  // association(a, b), association(b, a)
  size_t together = 0, views_a = 0, views_b = 0;
};
struct TrackIdResult {
  std::vector<JoinedIds> groups;
  std::map<int32_t, int32_t> canonical;
  std::vector<IdPair> pairs;  // every pair with an association of at least 0.1
};
TrackIdResult find_switched_ids(const LabelVotes::IdAssociation& association,
                                const IdCooccurrence& cooccurrence, const TrackIdOptions& options);

// One view's segment that covers another object too.
struct MergedSegment {
  int32_t id = 0;               // the segment's ID, after the canonical mapping
  std::vector<int32_t> covers;  // the other objects' labels
};
// labels: the voted label of every Gaussian; ids: the view's ID map (the
// camera's size), read through `canonical`; depth and vote as for voting.
std::vector<MergedSegment> find_merged_segments(const GaussianModel& model,
                                                const std::vector<int32_t>& labels,
                                                const Camera& camera, const IdMap& ids,
                                                const DepthMap* depth, const VoteOptions& vote,
                                                const std::map<int32_t, int32_t>& canonical,
                                                const TrackIdOptions& options);

}  // namespace splat
