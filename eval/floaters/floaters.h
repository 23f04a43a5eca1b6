#pragma once
// Floaters and label contamination in a trained model of a synthetic scene,
// measured against the scene's true surfaces (surfaces.json):
//
//   floater         a Gaussian whose centre is farther than `distance` from
//                   every true surface (objects, ground, dome) and not
//                   inside an object; counted apart inside the object
//                   region (the upright cylinder about the look-at point
//                   that holds every object, widened by half), where a
//                   floater can stand between a camera and an object:
//                   beyond it lies the background, whose far surfaces
//                   training places less exactly in depth
//   true object     for the others, the object of the nearest surface (0 for
//                   the ground and the dome), or the object it is inside
//   wrong label     a label other than the true object's (floaters: any
//                   object label); "border" when the Gaussian also lies
//                   within 2 * distance of another object's surface
//
// and how much of the picture and of the masks they make, over the views
// given: the share of rendered opacity (sum of alpha_i T_i) that floaters
// carry, and the share of the object masks' occupancy that floaters and
// wrongly labelled Gaussians carry with sigma (what the baseline sees) and
// with the learned sigma* (what dual opacity sees).

#include <filesystem>
#include <map>
#include <vector>

#include "splat/camera.h"
#include "splat/gaussians.h"
#include "synth/world.h"

namespace study {

struct FloaterOptions {
  double distance = 0.05;  // world units; the synthetic scene's objects are 0.05-0.7 across
  void Check() const;      // throws std::invalid_argument with a one-line message
};

// Where each Gaussian is, against the true surfaces.
struct SurfaceMatch {
  std::vector<uint8_t> floater;       // 1 if farther than `distance` from every surface
  std::vector<uint8_t> in_region;     // 1 inside the object region
  std::vector<int32_t> true_object;   // object ID of the nearest surface, 0 for background
  std::vector<uint8_t> near_another;  // within 2 * distance of another object's surface
};
SurfaceMatch match_surfaces(const splat::GaussianModel& model, const synth::World& world,
                            const FloaterOptions& options);

struct ObjectContamination {
  int32_t id = 0;
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
  // Per view, in the order given: the share of its rendered opacity that
  // floaters carry, all of them and those in the object region.
  std::vector<double> view_floater_opacity_share, view_region_floater_opacity_share;
  std::vector<ObjectContamination> objects;
};

// model: a labelled model; with instance opacities (stage two), sigma*
// figures are filled, otherwise they equal sigma's.
FloaterReport measure_floaters(const splat::GaussianModel& model, const synth::World& world,
                               const std::vector<splat::Camera>& views,
                               const FloaterOptions& options);

}  // namespace study
