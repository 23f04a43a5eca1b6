#include "splat/train/recipe.h"

#include <algorithm>

namespace splat {
namespace {

void set_recipe(TrainRecipe recipe, TrainOptions& options) {
  if (recipe == TrainRecipe::kPaper) return;
  const bool dash = recipe == TrainRecipe::kDash;
  const int window = std::min(options.densify_until, options.total_iterations);
  ResolutionScheduleOptions& schedule = options.resolution_schedule;
  options.sparse_adam = true;
  schedule.start_downscale = 4;
  schedule.full_from = dash ? window : window / 2;
  options.half_views.from_iteration = schedule.full_from;
  // The downscale falls log-linearly from 4 to 1 over [0, full_from], so it
  // is 2 at half of it.
  if (dash) options.lr_position_hold_until = schedule.full_from / 2;
}

}  // namespace

void apply_recipe(TrainRecipe recipe, TrainOptions& options, const GivenTrainOptions& given) {
  set_recipe(recipe, options);
  if (given.sparse_adam) options.sparse_adam = *given.sparse_adam;
  if (given.half_views_from) options.half_views.from_iteration = *given.half_views_from;
  if (given.lr_position_hold_until) options.lr_position_hold_until = *given.lr_position_hold_until;
}

}  // namespace splat
