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

#include "eval/metrics/floater_report.h"
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

// The report's types are the file's (eval/metrics/floater_report.h).
using eval::FloaterReport;
using eval::ObjectContamination;

// model: a labelled model; with instance opacities (stage two), sigma*
// figures are filled, otherwise they equal sigma's. The objects are named as
// in the world; the views are not named.
FloaterReport measure_floaters(const splat::GaussianModel& model, const synth::World& world,
                               const std::vector<splat::Camera>& views,
                               const FloaterOptions& options);

}  // namespace study
