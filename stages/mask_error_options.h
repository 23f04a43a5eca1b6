#pragma once
// The options of a segmenter's mask errors (synth/sam2_corruption.h), which
// op2gs-synth (as --sam2-<name>) and op2gs-mask-errors (as --<name>) share.

#include <string>

#include "stages/common.h"
#include "synth/sam2_corruption.h"

namespace stages {

inline void add_mask_error_options(CLI::App& app, synth::Sam2CorruptionOptions& o,
                                   const std::string& prefix) {
  const auto add = [&](const std::string& name, double& value, const std::string& help) {
    app.add_option("--" + prefix + name, value, help)->capture_default_str();
  };
  add("strength", o.strength, "scales every mask error (0 = exact)");
  add("jitter", o.boundary_jitter_px, "boundary jitter amplitude in pixels");
  add("miss", o.miss_probability, "chance per object and view of a missed part");
  add("leak", o.leak_probability, "chance per object and view of a leak onto a neighbour");
  add("blobs", o.spurious_blobs, "mean spurious blobs per view");
  add("persistence", o.persistence_views,
      "mean run of consecutive views over which a miss or leak persists (1: independent views)");
  add("border-bias", o.border_bias,
      "each object's mask eroded or dilated in every view by up to this fraction of its radius "
      "(a segmenter tight or loose on it throughout)");
  add("lose-small", o.lose_small_objects,
      "share of objects never tracked while small (background wherever they cover less than "
      "--" +
          prefix + "small-area of the image)");
  add("small-area", o.small_object_area, "what counts as small: a share of the image's area");
}

}  // namespace stages
