#pragma once
// The training recipes op2gs-train offers. The paper's is the reference
// 3DGS recipe (docs/gaussian-splatting.md) and the default. The fast one
// keeps its loss, learning rates and densification rule, and saves time in
// how they are applied (docs/benchmarks.md, "The fast recipe"):
//   - sparse Adam: only the Gaussians in view step (TrainOptions::sparse_adam);
//   - a resolution schedule: the training views at a quarter of their width
//     and height at iteration 0, at full resolution from half the
//     densification window on (or half the schedule, if shorter), so the
//     Gaussians that densification adds late are fitted to full-resolution
//     photos (resolution_schedule.h);
//   - half views: from full resolution on, each iteration trains on one
//     half of its view (half_views.h), so the late phase, where the model
//     has all its Gaussians, costs about half as much an iteration.
// The dash recipe (an experiment, docs/benchmarks.md) is the fast one with
// two of DashGaussian's (CVPR 2025) scheduling rules in place of ours:
//   - the resolution rises over the whole densification window, not half
//     of it, so full resolution (and half views) start where it ends;
//   - the position learning rate stays at its initial value until the
//     views are at least half their full width and height, then decays to
//     its final value at the schedule's end: small views cannot place
//     Gaussians finely, so the schedule's decay is not spent on them.

#include <optional>

#include "splat/train/trainer.h"

namespace splat {

enum class TrainRecipe { kPaper, kFast, kDash };

// The options of a recipe that a user set themselves (op2gs-train's
// --sparse-adam or --no-sparse-adam, --half-views-from and
// --position-lr-hold-until): a recipe sets the others, and these keep the
// user's values.
struct GivenTrainOptions {
  std::optional<bool> sparse_adam;
  std::optional<int> half_views_from;
  std::optional<int> lr_position_hold_until;
};

// Sets what the recipe changes from the paper's, but for the options in
// `given`. Call it after the schedule's length and the densification window
// are set: the fast and dash recipes' resolution schedules follow them.
void apply_recipe(TrainRecipe recipe, TrainOptions& options, const GivenTrainOptions& given = {});

}  // namespace splat
