#pragma once
// A whole stage-one run into a work folder, as op2gs-train performs it:
//
//   <work>/checkpoints/latest.ckpt        resumable state (atomically replaced)
//   <work>/point_cloud/iteration_N/point_cloud.ply   standard 3DGS PLY
//   <work>/test/renders/<view>.png        test renders at the end
//   <work>/metrics.json                   test PSNR / SSIM per view and mean
//   <work>/train_log.jsonl, training_curve.png, options.json

#include <filesystem>
#include <vector>

#include "splat/train/trainer.h"

namespace splat {

struct TrainRunOptions {
  TrainOptions train;
  int stop_at = 20000;  // stage one ends here by default
  int checkpoint_every = 1000;
  std::vector<int> ply_at;  // extra iterations with a PLY (the end always has one)
  // Iterations whose checkpoint is also kept as checkpoints/iteration_N.ckpt,
  // to resume from later (bench/studies/full_schedule.sh times the schedule from them).
  std::vector<int> keep_checkpoint_at;
  std::vector<int> test_at;  // iterations with a test evaluation (the end always has one)
  bool resume = false;       // continue from <work>/checkpoints/latest.ckpt
  // Render and score the test views at the end. Off, metrics.json says no
  // test views were scored (a benchmark's short timed runs).
  bool test_at_end = true;
  // Stage two (op2gs-learn): start from this stage-one checkpoint, with the
  // labels of this labelled model (op2gs-vote's PLY), instead of the SfM
  // points.
  std::filesystem::path start_checkpoint;
  std::filesystem::path labels_model;
  // For measuring thread scaling: the run's k-th iteration runs on the
  // (k mod n)-th of these n thread counts (bench/thread_scaling.sh gives
  // 1 2 2 1), so that a machine whose speed drifts within minutes slows every
  // count alike, and the log records each iteration's count. Training does
  // not depend on the thread count, so the model is the same. Empty: every
  // iteration on all the threads allowed.
  std::vector<int> alternate_threads;
  void Check() const;
};

struct TrainRunResult {
  int iteration = 0;
  size_t gaussians = 0;
  double test_psnr = 0, test_ssim = 0;
  size_t test_views = 0;
  double seconds = 0;
};

// The last opacity reset at or before `iteration` of a stage-one run: from
// its train_log.jsonl when the work folder has one, else from the default
// schedule (every 3,000 iterations until 15,000). -1 if none.
int last_opacity_reset(const std::filesystem::path& stage_one_work, int iteration);

TrainRunResult run_training(const std::filesystem::path& scene_dir,
                            const std::filesystem::path& work_dir, const TrainRunOptions& options);

}  // namespace splat
