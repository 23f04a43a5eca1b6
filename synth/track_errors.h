#pragma once
// The errors of a video segmenter's tracks (SAM2, DEVA), on top of the
// per-view mask errors of sam2_corruption.h:
//
//   ID switch     a track is lost and re-found under a new ID, which it keeps
//                 for a run of views before the old one returns (new IDs
//                 follow the largest ID of the scene)
//   merge         two objects that touch in view are one segment under one of
//                 their IDs for a run of views
//   late object   an object is not tracked (ID 0) until some way into the
//                 sequence
//
// All are seeded; the defaults make none.

#include <cstdint>
#include <vector>

#include "splat/image.h"

namespace synth {

struct TrackErrorOptions {
  double id_switches = 0;        // expected switches per object over the sequence
  double switch_run_views = 10;  // mean views a new ID lasts
  double merges = 0;             // expected merges per touching pair over the sequence
  double merge_run_views = 6;    // mean views a merge lasts
  double late_objects = 0;       // share of objects first tracked late
  double late_fraction = 0.3;    // a late object is untracked for up to this share of views

  bool any() const { return id_switches > 0 || merges > 0 || late_objects > 0; }
  static TrackErrorOptions typical();  // the --capture preset
  void Check() const;                  // throws std::invalid_argument with a one-line message
};

// Pairs of object IDs that share a boundary in at least a fifth of the views
// where both are seen (smaller ID first).
std::vector<std::pair<int, int>> touching_pairs(const std::vector<splat::IdMap>& truth);

// Applies the errors to the ID maps of a sequence in view order. truth: the
// exact maps (to find which objects touch); object_ids: the scene's IDs.
// Returns the new IDs the switches introduced, in order.
std::vector<int> apply_track_errors(std::vector<splat::IdMap>& maps,
                                    const std::vector<splat::IdMap>& truth,
                                    const std::vector<int>& object_ids,
                                    const TrackErrorOptions& options, uint64_t seed);

}  // namespace synth
