// End-to-end tests of stage one on a tiny synthetic scene.

#include "splat/train/trainer.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/image.h"
#include "splat/train/train_run.h"
#include "synth/generator.h"
#include "tests/test_util.h"
#include "tests/tiny_scene.h"

namespace splat {
namespace {

namespace fs = std::filesystem;
using testing_util::read_file;
using testing_util::TempDir;

// The tiny scene, generated once for the whole suite.
const fs::path& tiny_scene() {
  static const fs::path dir = testing_util::generate_tiny_scene("trainer_scene");
  return dir;
}

TrainOptions quick_options() {
  TrainOptions o;
  o.densify_from = 100;
  o.densify_every = 50;
  o.opacity_reset_every = 1000;
  o.total_iterations = 3000;
  return o;
}

double mean_test_psnr(Trainer& t) {
  double sum = 0;
  const auto metrics = t.evaluate(t.split().test);
  for (const auto& m : metrics) sum += m.psnr;
  return sum / metrics.size();
}

TEST(Trainer, TestPsnrRisesWellAboveTheStart) {
  Trainer t(tiny_scene(), quick_options());
  t.initialize_from_sfm();
  ASSERT_EQ(t.split().test.size(), 2u);  // views 0 and 8
  const double before = mean_test_psnr(t);
  size_t densified = 0;
  t.train_until(
      400, [&](const IterationStats& s) { densified += s.densified.cloned + s.densified.split; });
  const double after = mean_test_psnr(t);
  EXPECT_GT(after, before + 5.0) << "before " << before << " dB, after " << after << " dB";
  EXPECT_GT(densified, 0u);
  EXPECT_GT(t.model().size(), 3000u);
}

// Sparse Adam reaches the trainer: it trains (the PSNR rises as in the
// reference recipe) and its model is not the reference's.
TEST(Trainer, SparseAdamTrainsAndIsNotTheReferenceStep) {
  TrainOptions sparse_options = quick_options();
  sparse_options.sparse_adam = true;
  Trainer sparse(tiny_scene(), sparse_options), dense(tiny_scene(), quick_options());
  sparse.initialize_from_sfm();
  dense.initialize_from_sfm();
  const double before = mean_test_psnr(sparse);
  sparse.train_until(400);
  dense.train_until(400);
  const double after = mean_test_psnr(sparse), reference = mean_test_psnr(dense);
  EXPECT_GT(after, before + 5.0) << "before " << before << " dB, after " << after << " dB";
  EXPECT_GT(after, reference - 1.0) << "sparse " << after << " dB, reference " << reference;
  EXPECT_FALSE(sparse.model() == dense.model());
}

// The resolution schedule's slow reference: a schedule held at a
// downscale of 2 (it reaches 1 only after a million iterations) renders
// and compares each view as the scene loaded at half size does, so both
// train the same model, through densification, bit for bit.
TEST(Trainer, AResolutionScheduleAtHalfSizeTrainsAsTheHalfSizeScene) {
  TrainOptions scheduled = quick_options();
  scheduled.resolution_schedule = {2.0, 1000000};
  TrainOptions half = quick_options();
  half.scene.downscale = 2;
  Trainer a(tiny_scene(), scheduled), b(tiny_scene(), half);
  a.initialize_from_sfm();
  b.initialize_from_sfm();
  int downscaled = 0;
  a.train_until(260, [&](const IterationStats& s) { downscaled += s.downscale > 1.99; });
  b.train_until(260);
  EXPECT_EQ(downscaled, 260);
  EXPECT_GT(a.model().size(), b.model().size() / 2);  // densification ran
  EXPECT_TRUE(a.model() == b.model()) << "the scheduled run differs from the half-size scene's";
}

// The fast recipe's schedule reaches full resolution at full_from and trains.
TEST(Trainer, AResolutionScheduleEndsAtFullResolutionAndTrains) {
  TrainOptions o = quick_options();
  o.resolution_schedule = {4.0, 200};
  Trainer t(tiny_scene(), o);
  t.initialize_from_sfm();
  const double before = mean_test_psnr(t);
  std::vector<double> downscale;
  t.train_until(400, [&](const IterationStats& s) { downscale.push_back(s.downscale); });
  EXPECT_GT(downscale[0], 3.9);
  EXPECT_NEAR(downscale[99], 2.0, 1e-9);  // iteration 100
  EXPECT_GT(downscale[198], 1.0);         // iteration 199
  EXPECT_EQ(downscale[199], 1.0);         // iteration 200
  EXPECT_EQ(downscale[399], 1.0);
  const double after = mean_test_psnr(t);
  EXPECT_GT(after, before + 5.0) << "before " << before << " dB, after " << after << " dB";
}

// The dash recipe's hold: the position learning rate stays at its initial
// value until the hold ends, then falls log-linearly to its final value at
// the schedule's end; without a hold it falls from the start.
TEST(Trainer, PositionLearningRateHoldsThenFallsToItsFinalValue) {
  TrainOptions o = quick_options();
  o.total_iterations = 40;
  const auto rates = [&](int hold) {
    o.lr_position_hold_until = hold;
    Trainer t(tiny_scene(), o);
    t.initialize_from_sfm();
    std::vector<double> lr;
    t.train_until(40, [&](const IterationStats& s) { lr.push_back(s.lr_position); });
    return lr;  // lr[i] is iteration i + 1's
  };
  const std::vector<double> held = rates(20), plain = rates(0);
  const double init = held[0], ratio = double(o.lr_position_final) / o.lr_position_init;
  EXPECT_EQ(held[19], init);  // iteration 20, the hold's end
  EXPECT_LT(held[20], init);
  EXPECT_NEAR(held[29], init * std::sqrt(ratio), 1e-6 * init);  // half of the fall
  EXPECT_NEAR(held[39], init * ratio, 1e-6 * init);             // the schedule's end
  EXPECT_LT(plain[0], init);                                    // falls from iteration 1
  EXPECT_NEAR(plain[19], init * std::sqrt(ratio), 1e-6 * init);
  EXPECT_NEAR(plain[39], held[39], 1e-6 * init);
}

// The fast recipe's half views: from their first iteration on every step
// trains on a half, the model still learns the scene, and a run resumed
// among them is the uninterrupted run (the half follows from the iteration
// and the view, not from state outside the checkpoint).
TEST(Trainer, HalfViewsTrainAndResumeExactly) {
  TempDir dir;
  TrainOptions o = quick_options();
  o.half_views.from_iteration = 200;
  Trainer straight(tiny_scene(), o);
  straight.initialize_from_sfm();
  const double before = mean_test_psnr(straight);
  std::vector<bool> half;
  straight.train_until(400, [&](const IterationStats& s) { half.push_back(s.half_view); });
  EXPECT_FALSE(half[0]);
  EXPECT_FALSE(half[198]);  // iteration 199
  EXPECT_TRUE(half[199]);   // iteration 200
  EXPECT_TRUE(half[399]);
  const double after = mean_test_psnr(straight);
  EXPECT_GT(after, before + 5.0) << "before " << before << " dB, after " << after << " dB";

  Trainer first(tiny_scene(), o);
  first.initialize_from_sfm();
  first.train_until(310);
  first.save_checkpoint(dir / "ckpt");
  Trainer resumed(tiny_scene(), o);
  resumed.load_checkpoint(dir / "ckpt");
  resumed.train_until(400);
  EXPECT_TRUE(resumed.model() == straight.model())
      << "resumed run differs from the uninterrupted one";
}

TEST(Trainer, ResumeGivesTheSameParametersAsAnUninterruptedRun) {
  TempDir dir;
  Trainer straight(tiny_scene(), quick_options());
  straight.initialize_from_sfm();
  straight.train_until(260);  // crosses densification steps (150, 200, 250)

  Trainer first(tiny_scene(), quick_options());
  first.initialize_from_sfm();
  first.train_until(170);
  first.save_checkpoint(dir / "ckpt");
  Trainer resumed(tiny_scene(), quick_options());
  resumed.load_checkpoint(dir / "ckpt");
  EXPECT_EQ(resumed.iteration(), 170);
  resumed.train_until(260);
  EXPECT_TRUE(resumed.model() == straight.model())
      << "resumed run differs from the uninterrupted one";
}

TEST(Trainer, ExposureCompensationResumesExactlyAndLearnsTransforms) {
  TempDir dir;
  TrainOptions o = quick_options();
  o.exposure.enabled = true;
  Trainer straight(tiny_scene(), o);
  straight.initialize_from_sfm();
  straight.train_until(120);
  ASSERT_TRUE(straight.compensates_exposure());

  Trainer first(tiny_scene(), o);
  first.initialize_from_sfm();
  first.train_until(60);
  first.save_checkpoint(dir / "ckpt");
  // The checkpoint keeps compensation on, even for a run not asking for it.
  Trainer resumed(tiny_scene(), quick_options());
  resumed.load_checkpoint(dir / "ckpt");
  ASSERT_TRUE(resumed.compensates_exposure());
  resumed.train_until(120);
  EXPECT_TRUE(resumed.model() == straight.model());
  size_t moved = 0;
  for (size_t v = 0; v < straight.exposure().size(); ++v) {
    EXPECT_EQ(resumed.exposure().params(v), straight.exposure().params(v));
    moved += straight.exposure().params(v) != ViewColorTransforms(1).params(0);
  }
  EXPECT_GT(moved, 0u);  // training views' transforms were learned
}

TEST(Trainer, PoseRefinementResumesExactlyAndMovesTheTrainingViews) {
  TempDir dir;
  TrainOptions o = quick_options();
  o.poses.enabled = true;
  o.poses.from_iteration = 50;
  Trainer straight(tiny_scene(), o);
  straight.initialize_from_sfm();
  straight.train_until(120);
  ASSERT_TRUE(straight.refines_poses());

  Trainer first(tiny_scene(), o);
  first.initialize_from_sfm();
  first.train_until(80);
  first.save_checkpoint(dir / "ckpt");
  // The checkpoint keeps refinement on, even for a run not asking for it.
  TrainOptions without = o;
  without.poses.enabled = false;
  Trainer resumed(tiny_scene(), without);
  resumed.load_checkpoint(dir / "ckpt");
  ASSERT_TRUE(resumed.refines_poses());
  resumed.train_until(120);
  EXPECT_TRUE(resumed.model() == straight.model());

  const std::vector<NamedPose> poses = straight.refined_poses();
  ASSERT_EQ(poses.size(), straight.split().train.size());
  size_t moved = 0;
  for (size_t k = 0; k < poses.size(); ++k) {
    const size_t v = straight.split().train[k];
    const Camera& given = straight.scene().views()[v].camera;
    EXPECT_EQ(poses[k].name, straight.scene().views()[v].name);
    EXPECT_EQ(poses[k].R, resumed.camera_of(v).R);
    moved += !(poses[k].t == given.t);
  }
  EXPECT_GT(moved, 0u);
  // Small corrections: well under a degree after a few steps.
  EXPECT_LT(straight.largest_pose_correction().first, 0.01);
  // Test views keep the model's poses.
  for (size_t v : straight.split().test)
    EXPECT_EQ(straight.camera_of(v).t, straight.scene().views()[v].camera.t);
}

TEST(Trainer, SameSeedSameModel) {
  Trainer a(tiny_scene(), quick_options()), b(tiny_scene(), quick_options());
  a.initialize_from_sfm();
  b.initialize_from_sfm();
  a.train_until(120);
  b.train_until(120);
  EXPECT_TRUE(a.model() == b.model());
}

// Training does not depend on the thread count (docs/renderer.md,
// "Determinism"): one thread and all of them give the same model bit for
// bit, through densification.
TEST(Trainer, OneThreadAndAllThreadsTrainTheSameModel) {
  Trainer all(tiny_scene(), quick_options());
  all.initialize_from_sfm();
  all.train_until(260);
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  Trainer single(tiny_scene(), quick_options());
  single.initialize_from_sfm();
  single.train_until(260);
  EXPECT_TRUE(single.model() == all.model()) << "one thread trains another model";
}

TEST(Trainer, NonFiniteLossStopsAndIsNeverCheckpointed) {
  TempDir dir;
  Trainer t(tiny_scene(), quick_options());
  t.initialize_from_sfm();
  std::fill(t.model().sh_dc.begin(), t.model().sh_dc.end(), std::nanf(""));
  EXPECT_THROW(t.train_until(5), TrainingDiverged);
  EXPECT_THROW(t.save_checkpoint(dir / "ckpt"), TrainingDiverged);
  EXPECT_FALSE(fs::exists(dir / "ckpt"));
}

TEST(Trainer, BadInputIsReportedWithTheFile) {
  TempDir dir;
  fs::copy(tiny_scene(), dir / "s", fs::copy_options::recursive);
  {  // an image of the wrong size for its camera: found before training starts
    write_image_rgb(dir / "s" / "images" / "frame_00003.png", ImageRGB(50, 40));
    TrainOptions o = quick_options();
    o.split = SplitRule::kAll;
    try {
      Trainer t(dir / "s", o);
      FAIL() << "expected InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("frame_00003.png"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("50x40"), std::string::npos) << e.what();
    }
  }
  {  // a missing image
    fs::remove(dir / "s" / "images" / "frame_00005.png");
    EXPECT_THROW(Trainer(dir / "s", quick_options()), InputError);
  }
  {  // a model with no points
    TempDir empty;
    fs::copy(tiny_scene(), empty / "s", fs::copy_options::recursive);
    splat::write_text_atomically(empty / "s" / "sparse" / "0" / "points3D.txt", "");
    Trainer t(empty / "s", quick_options());
    EXPECT_THROW(t.initialize_from_sfm(), InputError);
  }
}

TEST(TrainRun, WritesEveryArtifactAndResumes) {
  TempDir dir;
  TrainRunOptions o;
  o.train = quick_options();
  o.stop_at = 120;
  o.checkpoint_every = 50;
  o.ply_at = {100};
  o.keep_checkpoint_at = {60};
  const TrainRunResult r = run_training(tiny_scene(), dir / "work", o);
  EXPECT_EQ(r.iteration, 120);
  EXPECT_EQ(r.test_views, 2u);
  for (const char* f : {"checkpoints/latest.ckpt", "point_cloud/iteration_100/point_cloud.ply",
                        "point_cloud/iteration_120/point_cloud.ply", "test/renders/frame_00000.png",
                        "metrics.json", "train_log.jsonl", "training_curve.png"})
    EXPECT_TRUE(fs::exists(dir / "work" / f)) << f;
  // The kept checkpoint is the state of its iteration, not replaced later.
  EXPECT_EQ(read_checkpoint_iteration(dir / "work" / "checkpoints" / "iteration_60.ckpt"), 60);
  o.stop_at = 150;
  o.resume = true;
  EXPECT_EQ(run_training(tiny_scene(), dir / "work", o).iteration, 150);
  o.stop_at = 160;
  o.test_at_end = false;  // a timed run: no test views scored
  EXPECT_EQ(run_training(tiny_scene(), dir / "work", o).test_views, 0u);
}

// Alternating the thread count per iteration (for bench/thread_scaling.sh)
// trains the same model as all threads, and logs each iteration's count.
TEST(TrainRun, AlternatingThreadsTrainsTheSameModelAndLogsEachCount) {
  TempDir dir;
  TrainRunOptions o;
  o.train = quick_options();
  o.stop_at = 160;  // through densification at 150
  o.test_at_end = false;
  run_training(tiny_scene(), dir / "all", o);
  o.alternate_threads = {1, 2, 2};
  run_training(tiny_scene(), dir / "alternating", o);
  EXPECT_EQ(read_file(dir / "alternating" / "checkpoints" / "latest.ckpt"),
            read_file(dir / "all" / "checkpoints" / "latest.ckpt"))
      << "alternating the threads trains another model";
  std::vector<int> logged;
  std::ifstream log(dir / "alternating" / "train_log.jsonl");
  for (std::string line; std::getline(log, line);)
    logged.push_back(nlohmann::json::parse(line).value("threads", 0));
  ASSERT_EQ(logged.size(), 160u);
  for (size_t k = 0; k < logged.size(); ++k)
    EXPECT_EQ(logged[k], k % 3 == 0 ? 1 : 2) << "iteration " << k + 1;
  std::ifstream plain(dir / "all" / "train_log.jsonl");
  std::string first;
  std::getline(plain, first);
  EXPECT_FALSE(nlohmann::json::parse(first).contains("threads"));

  o.alternate_threads = {1, 0};
  EXPECT_THROW(run_training(tiny_scene(), dir / "bad", o), std::invalid_argument);
}

}  // namespace
}  // namespace splat
