#pragma once
// op2gs-floaters: floaters and label contamination of a trained model of a
// synthetic scene (floaters.h), written as floaters.json
// (eval/metrics/floater_report.h).

#include <filesystem>

#include "eval/floaters/floaters.h"
#include "splat/scene.h"
#include "splat/view_split.h"

namespace study {

struct FloaterRunOptions {
  splat::SceneOptions scene;
  splat::SplitRule split = splat::SplitRule::kAuto;
  std::filesystem::path model;  // a labelled model: stage two's checkpoint or PLY, or vote's PLY
  FloaterOptions floaters;
  bool render = true;  // the opacity and mask shares over the test views

  void Check() const;  // throws std::invalid_argument with a one-line message
};

// Reads <scene>/surfaces.json and the model; writes the report to out_file.
FloaterReport run_floaters(const std::filesystem::path& scene_dir,
                           const std::filesystem::path& out_file, const FloaterRunOptions& options);

}  // namespace study
