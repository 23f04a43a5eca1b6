#pragma once
// Gives a folder of exact ID maps (a real capture's, or a synthetic scene's)
// a video segmenter's errors: the per-view SAM2-like mask errors of
// sam2_corruption.h and the track errors of track_errors.h, so that one
// scene can be run with exact and with realistic masks side by side
// (op2gs-mask-errors, docs/synthetic.md).

#include <cstdint>
#include <filesystem>

#include "synth/sam2_corruption.h"
#include "synth/track_errors.h"

namespace synth {

struct MaskErrorRunOptions {
  Sam2CorruptionOptions sam2;  // per-view errors
  TrackErrorOptions tracks;    // none by default
  uint64_t seed = 1;
  void Check() const;
};

struct MaskErrorRunResult {
  size_t maps = 0;
  size_t objects = 0;
  size_t new_ids = 0;          // introduced by ID switches
  double changed_share = 0;    // of the pixels, over all maps
  double mean_object_iou = 0;  // of the objects' masks against the exact ones, over views
};

// Reads every <in>/*.png in name order (the video's order), writes the maps
// with errors under the same names into `out`, and copies objects.json.
// Throws InputError naming a
// file that is not an ID map.
MaskErrorRunResult add_mask_errors(const std::filesystem::path& in,
                                   const std::filesystem::path& out,
                                   const MaskErrorRunOptions& options);

}  // namespace synth
