// op2gs-train: stage one, 3DGS training with the reference recipe.

#include <tbb/global_control.h>

#include <optional>

#include "splat/train/train_run.h"
#include "stages/common.h"

int main(int argc, char** argv) {
  CLI::App app{"Train a 3D Gaussian Splatting model (stage one of OP2GS) on a scene folder."};
  splat::TrainRunOptions o;
  std::string scene, work, split = "auto";
  int resolution = 1, threads = 0;
  double cache_mb = 2048;
  std::vector<float> background;
  app.add_option("scene", scene, "scene folder (images/, sparse/0/)")->required();
  app.add_option("work", work, "work folder for checkpoints, PLY, renders, logs")->required();
  app.add_option("--iterations", o.stop_at, "stop at this iteration (stage one: 20000)")
      ->capture_default_str();
  app.add_option("--schedule", o.train.total_iterations, "length of the learning-rate schedule")
      ->capture_default_str();
  app.add_flag("--resume", o.resume, "continue from <work>/checkpoints/latest.ckpt");
  app.add_option("--resolution", resolution,
                 "downscale factor 1, 2, 4 or 8 (uses images_N/ if present)")
      ->capture_default_str();
  app.add_option("--max-width", o.train.scene.max_width,
                 "scale images down to at most this width (0: off)");
  app.add_option("--images", o.train.scene.images_dir, "image folder inside the scene")
      ->capture_default_str();
  app.add_option("--split", split, "train/test split: auto, lerf (images_train/), every8, all")
      ->capture_default_str();
  app.add_option("--seed", o.train.seed, "random seed")->capture_default_str();
  app.add_option("--sh-degree", o.train.sh_degree, "largest SH degree")->capture_default_str();
  app.add_option("--background", background, "background colour r g b in [0, 1]")->expected(3);
  app.add_option("--checkpoint-every", o.checkpoint_every, "iterations between checkpoints")
      ->capture_default_str();
  app.add_option("--ply-at", o.ply_at, "also write a PLY at these iterations");
  app.add_option("--test-at", o.test_at, "also evaluate the test views at these iterations");
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
  app.add_option("--cache-mb", cache_mb, "decoded images kept in memory, MiB")
      ->capture_default_str();
  app.add_option("--threads", threads, "worker threads (0: all cores)")->capture_default_str();
  return stages::run_stage(app, argc, argv, [&] {
    std::optional<tbb::global_control> limit;
    if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, threads);
    o.train.scene.downscale = resolution;
    o.train.scene.cache_bytes = size_t(cache_mb * (1 << 20));
    if (!background.empty()) std::copy_n(background.begin(), 3, o.train.background);
    o.train.split = stages::parse_split(split);
    const splat::TrainRunResult r = splat::run_training(scene, work, o);
    spdlog::info("iteration {}: {} Gaussians, {:.1f} s", r.iteration, r.gaussians, r.seconds);
    if (r.test_views)
      spdlog::info("test views ({}): PSNR {:.2f} dB, SSIM {:.4f}", r.test_views, r.test_psnr,
                   r.test_ssim);
    spdlog::info("outputs in {}", work);
  });
}
