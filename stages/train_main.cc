// op2gs-train: stage one, 3DGS training with the paper's recipe or the fast one.

#include "splat/train/recipe.h"
#include "stages/training_cli.h"

int main(int argc, char** argv) {
  CLI::App app{"Train a 3D Gaussian Splatting model (stage one of OP2GS) on a scene folder."};
  splat::TrainRunOptions o;  // stops at 20,000 by default
  std::string scene, work;
  app.add_option("scene", scene, "scene folder (images/, sparse/0/)")->required();
  app.add_option("work", work, "work folder for checkpoints, PLY, renders, logs")->required();
  stages::TrainingCli common(app, o);
  app.add_flag("--resume", o.resume, "continue from <work>/checkpoints/latest.ckpt");
  std::string recipe = "paper";
  app.add_option("--recipe", recipe,
                 "paper: the reference 3DGS recipe; fast: sparse Adam, a resolution schedule "
                 "(the views at a quarter size at first, full size from half the densification "
                 "window on) and, from there on, half views (docs/stages.md); dash: an "
                 "experiment, the fast recipe with DashGaussian's schedules (full size where "
                 "densification ends, the position learning rate held at first); "
                 "--sparse-adam (--no-sparse-adam), --half-views-from and "
                 "--position-lr-hold-until, if given, keep their values")
      ->capture_default_str()
      // The last one given wins, so that the pipeline's TRAIN_OPTS overrides its
      // RECIPE.
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--densify-from", o.train.densify_from, "first densification iteration")
      ->capture_default_str();
  app.add_option("--densify-until", o.train.densify_until, "last densification iteration")
      ->capture_default_str();
  app.add_option("--densify-every", o.train.densify_every, "iterations between densifications")
      ->capture_default_str();
  app.add_option("--opacity-reset-every", o.train.opacity_reset_every,
                 "iterations between opacity resets")
      ->capture_default_str();
  app.add_option("--sh-increase-every", o.train.sh_increase_every,
                 "iterations between SH degree increases")
      ->capture_default_str();
  app.add_option("--max-screen-radius", o.train.densify.max_screen_radius,
                 "prune Gaussians larger than this on screen (pixels) after the first opacity "
                 "reset (the spec's rule is 20); 0, the default, never does, as the reference "
                 "implementation in effect does")
      ->capture_default_str();
  app.add_option("--max-gaussians", o.train.densify.max_gaussians,
                 "a budget: densification adds no Gaussian beyond this many, the candidates "
                 "with the largest gradients first; 0, the default, has none (the paper's rule)")
      ->capture_default_str();
  return stages::run_stage(app, argc, argv, [&] {
    common.apply();
    // What the command line gives beside --recipe wins over the recipe.
    splat::GivenTrainOptions given;
    if (app.count("--sparse-adam") || app.count("--no-sparse-adam"))
      given.sparse_adam = o.train.sparse_adam;
    if (app.count("--half-views-from")) given.half_views_from = o.train.half_views.from_iteration;
    if (app.count("--position-lr-hold-until"))
      given.lr_position_hold_until = o.train.lr_position_hold_until;
    splat::apply_recipe(
        stages::parse_choice<splat::TrainRecipe>("--recipe", recipe,
                                                 {{"paper", splat::TrainRecipe::kPaper},
                                                  {"fast", splat::TrainRecipe::kFast},
                                                  {"dash", splat::TrainRecipe::kDash}}),
        o.train, given);
    stages::TrainingCli::report(splat::run_training(scene, work, o), work);
  });
}
