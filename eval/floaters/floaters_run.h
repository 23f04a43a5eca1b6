#pragma once
// op2gs-floaters: floaters and label contamination of a trained model of a
// synthetic scene (floaters.h), written as JSON:
//
//   {"distance", "gaussians", "floaters", "floater_share", "floaters_labelled",
//    "floater_opacity_share", "mask_floater_share": {"sigma", "sigma_star"},
//    "mask_wrong_share": {"sigma", "sigma_star"}, "views",
//    "objects": [{"id", "name", "gaussians", "wrong", "labelled",
//                 "labelled_wrongly", "labelled_floaters", "labelled_border",
//                 "sigma": {"right", "wrong"}, "sigma_star": {"right", "wrong"}}]}

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
