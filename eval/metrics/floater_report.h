#pragma once
// What op2gs-floaters measures of a labelled model of a synthetic scene
// (eval/floaters/floaters.h says how), and its file, floaters.json, with one
// writer and one reader: op2gs-floaters writes it, op2gs-report reads it.
//
//   {"distance", "gaussians", "floaters", "floater_share", "floaters_labelled",
//    "region": {"gaussians", "floaters", "floater_opacity_share"}, "views",
//    "floater_opacity_share", "per_view": [{"view", "floater_opacity_share",
//    "region_floater_opacity_share"}], "mask_floater_share": {"sigma",
//    "sigma_star"}, "mask_wrong_share": {"sigma", "sigma_star"},
//    "objects": [{"id", "name", "gaussians", "wrong", "labelled",
//                 "labelled_wrongly", "labelled_floaters", "labelled_border",
//                 "sigma": {"right", "wrong"}, "sigma_star": {"right", "wrong"}}]}

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace eval {

struct ObjectContamination {
  int32_t id = 0;
  std::string name;             // the scene's name of the object; empty if unnamed
  size_t gaussians = 0;         // Gaussians whose true object this is
  size_t wrong = 0;             // of those, labelled otherwise
  size_t labelled = 0;          // Gaussians labelled with this ID
  size_t labelled_wrongly = 0;  // of those, floaters or another true object's
  size_t labelled_floaters = 0;
  size_t labelled_border = 0;  // wrongly labelled ones on a border with this object
  double mean_sigma_wrong = 0, mean_sigma_star_wrong = 0;  // over labelled_wrongly
  double mean_sigma_right = 0, mean_sigma_star_right = 0;  // over the correct ones
};

struct FloaterReport {
  double distance = 0;
  size_t gaussians = 0;
  size_t floaters = 0;
  size_t floaters_labelled = 0;                      // floaters with an object label
  size_t region_gaussians = 0, region_floaters = 0;  // in the object region
  // Pooled over the views given.
  double floater_opacity_share = 0;         // of the picture's rendered opacity
  double region_floater_opacity_share = 0;  // of it, floaters in the object region
  double mask_floater_share_sigma = 0;      // of the masks' occupancy, with sigma
  double mask_floater_share_sigma_star = 0;
  double mask_wrong_share_sigma = 0;  // wrongly labelled (floaters included)
  double mask_wrong_share_sigma_star = 0;
  // Per view, in the order given (names in view_names when known): the share
  // of its rendered opacity that floaters carry, all of them and those in the
  // object region.
  std::vector<std::string> view_names;
  std::vector<double> view_floater_opacity_share, view_region_floater_opacity_share;
  std::vector<ObjectContamination> objects;
};

// Writes floaters.json atomically.
void write_floater_report(const std::filesystem::path& file, const FloaterReport& report);

// Throws splat::InputError naming the file when it is not such a report.
FloaterReport read_floater_report(const std::filesystem::path& file);

}  // namespace eval
