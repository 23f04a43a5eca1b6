#pragma once
// The command-line options op2gs-train and op2gs-learn share (the run's
// length, resolution, split, outputs, threads), and their summary at the end.

#include "splat/train/train_run.h"
#include "stages/common.h"

namespace stages {

class TrainingCli {
 public:
  // Adds the shared options to app; they fill o (kept by reference).
  TrainingCli(CLI::App& app, splat::TrainRunOptions& o) : o_(o) {
    app.add_option("--iterations", o.stop_at, "stop at this iteration")->capture_default_str();
    app.add_option("--schedule", o.train.total_iterations, "length of the learning-rate schedule")
        ->capture_default_str();
    add_scene_options(app, o.train.scene, split_, threads_,
                      "downscale factor 1, 2, 4 or 8 (uses images_N/ if present)");
    app.add_option("--max-width", o.train.scene.max_width,
                   "scale images down to at most this width (0: off)");
    app.add_option("--seed", o.train.seed,
                   "random seed (op2gs-learn: 0 continues the stage-one checkpoint's random "
                   "stream, another value starts a new one)")
        ->capture_default_str();
    app.add_option("--sh-degree", o.train.sh_degree, "largest SH degree")->capture_default_str();
    app.add_option("--background", background_, "background colour r g b in [0, 1]")->expected(3);
    app.add_option("--checkpoint-every", o.checkpoint_every, "iterations between checkpoints")
        ->capture_default_str();
    app.add_option("--ply-at", o.ply_at, "also write a PLY at these iterations");
    app.add_option("--keep-checkpoint-at", o.keep_checkpoint_at,
                   "also keep the checkpoint of these iterations as checkpoints/iteration_N.ckpt");
    app.add_option("--test-at", o.test_at, "also evaluate the test views at these iterations");
    app.add_flag("!--no-final-test", o.test_at_end,
                 "do not render and score the test views at the end (metrics.json then has none)");
    app.add_flag("--exposure-compensation", o.train.exposure.enabled,
                 "learn a colour transform per training view (exposure, white balance) applied "
                 "before the loss; test views are rendered without it");
    app.add_option("--exposure-regularization", o.train.exposure.regularization,
                   "weight of the pull of each view's transform towards the identity")
        ->capture_default_str();
    app.add_flag("--refine-poses", o.train.poses.enabled,
                 "learn a correction of every training view's camera pose (for poses a pixel or "
                 "so off); writes refined_poses.txt, which the later stages use");
    app.add_option("--refine-poses-from", o.train.poses.from_iteration,
                   "the iteration pose refinement starts at")
        ->capture_default_str();
    app.add_option("--fit-test-poses", o.train.test_pose_fit.iterations,
                   "before scoring a test view, fit its camera pose to its photo with this many "
                   "steps, the model held fixed (0: off)")
        ->capture_default_str();
    app.add_flag("--sparse-adam,!--no-sparse-adam", o.train.sparse_adam,
                 "Adam steps only the Gaussians in view (theirs out of view keep values and "
                 "moments, as gsplat's selective Adam); off in the paper's recipe");
    app.add_option("--half-views-from", o.train.half_views.from_iteration,
                   "from this iteration on, each iteration trains on one half of its view, the "
                   "halves alternating by epoch (0: never, the paper's recipe)")
        ->capture_default_str();
    app.add_option("--position-lr-hold-until", o.train.lr_position_hold_until,
                   "the position learning rate stays at its initial value until this "
                   "iteration, then decays to its final one at the schedule's end (0: decays "
                   "from the start, the paper's recipe; --recipe dash sets half its "
                   "densification window; give stage two the same value)")
        ->capture_default_str();
    app.add_option("--cache-mb", cache_mb_, "decoded images kept in memory, MiB")
        ->capture_default_str();
    app.add_option(
        "--alternate-threads", o.alternate_threads,
        "benchmarking: run the iterations on these thread counts in turn (e.g. 1 2 2 "
        "1; each at most --threads), so that a machine's drift slows every count "
        "alike; train_log.jsonl records each iteration's count (bench/thread_scaling.sh)");
  }

  // Moves the parsed values into the options and limits the threads (for as
  // long as this object lives).
  void apply() {
    limit_.emplace(threads_);
    o_.train.scene.cache_bytes = size_t(cache_mb_ * (1 << 20));
    if (!background_.empty()) std::copy_n(background_.begin(), 3, o_.train.background);
    o_.train.split = parse_split(split_);
  }

  static void report(const splat::TrainRunResult& r, const std::string& outputs) {
    spdlog::info("iteration {}: {} Gaussians, {:.1f} s", r.iteration, r.gaussians, r.seconds);
    if (r.test_views)
      spdlog::info("test views ({}): PSNR {:.2f} dB, SSIM {:.4f}", r.test_views, r.test_psnr,
                   r.test_ssim);
    spdlog::info("outputs in {}", outputs);
  }

 private:
  splat::TrainRunOptions& o_;
  std::string split_ = "auto";
  int threads_ = 0;
  double cache_mb_ = 2048;
  std::vector<float> background_;
  std::optional<ThreadLimit> limit_;
};

}  // namespace stages
