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

  void Check() const;  // throws std::invalid_argument for negative values
};

// object_ids: the IDs that exist in the scene (spurious blobs take one of them).
splat::IdMap corrupt_like_sam2(const splat::IdMap& truth, const std::vector<int>& object_ids,
                               const Sam2CorruptionOptions& options, uint64_t seed);

}  // namespace synth
