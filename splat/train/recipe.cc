#include "splat/train/recipe.h"

#include <algorithm>

namespace splat {

void apply_recipe(TrainRecipe recipe, TrainOptions& options) {
  if (recipe == TrainRecipe::kPaper) return;
  options.sparse_adam = true;
  options.resolution_schedule.start_downscale = 4;
  options.resolution_schedule.full_from =
      std::min(options.densify_until, options.total_iterations) / 2;
  options.half_views.from_iteration = options.resolution_schedule.full_from;
}

}  // namespace splat
