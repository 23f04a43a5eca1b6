#pragma once
// Turns an exact instance ID map into one that looks like a real SAM2 video
// mask: boundaries that wander by a few pixels, parts of objects missed,
// small spurious blobs, and occasional leaks onto a neighbour. Every effect is
// seeded and its strength configurable, so tests can dial contamination up or
// down.

#include <cstdint>
#include <vector>

#include "splat/image.h"

namespace synth {

struct Sam2CorruptionOptions {
  double strength = 1.0;            // multiplies every effect; 0 = exact copy
  double boundary_jitter_px = 2.5;  // amplitude of the smooth boundary displacement
  double miss_probability = 0.25;   // per object and view: erase a blob of the object
  double miss_radius = 0.35;        // blob radius, fraction of the object's equivalent radius
  double leak_probability = 0.2;    // per object and view: spill onto a neighbour
  double leak_radius = 0.3;         // spill radius, fraction of the equivalent radius
  double spurious_blobs = 1.5;      // mean number of stray blobs per view
  double spurious_radius = 0.012;   // stray blob radius, fraction of the image diagonal
  // Mean length, in consecutive views, of the runs over which an object's miss
  // or leak persists, as SAM2's video memory carries an error forward. 1:
  // drawn independently for every view. The share of views with a miss or a
  // leak does not depend on it; blobs and jitter are always per view.
  double persistence_views = 1;
  // Errors that hold for an object over the whole video (drawn once per
  // object from the seed, independently of the per-view errors above, so
  // that turning them on leaves those unchanged):
  //  - a border bias: each object's mask is eroded or dilated (over the
  //    background) in every view by a fraction, drawn uniformly from
  //    [-border_bias, border_bias], of its equivalent radius in that view:
  //    a segmenter that is tight on a transparent object is tight in every
  //    frame, and the error is wider on a larger object;
  //  - small objects lost: with probability lose_small_objects an object is
  //    one the segmenter never tracks, and it is background in every view
  //    where it covers less than small_object_area of the image.
  double border_bias = 0;
  double lose_small_objects = 0;
  double small_object_area = 0.002;

  void Check() const;  // throws std::invalid_argument for negative values
};

// One view. object_ids: the IDs that exist in the scene (spurious blobs take
// one of them). Ignores persistence_views; the whole-video errors are drawn
// from `seed` as for a video of this one view.
splat::IdMap corrupt_like_sam2(const splat::IdMap& truth, const std::vector<int>& object_ids,
                               const Sam2CorruptionOptions& options, uint64_t seed);

// The views of a video in order; view i of an independent sequence
// (persistence_views = 1) is corrupt_like_sam2(truth[i], ..., seed * 31337 + i).
std::vector<splat::IdMap> corrupt_sequence_like_sam2(const std::vector<splat::IdMap>& truth,
                                                     const std::vector<int>& object_ids,
                                                     const Sam2CorruptionOptions& options,
                                                     uint64_t seed);

}  // namespace synth
