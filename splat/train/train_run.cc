#include "splat/train/train_run.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/ply.h"
#include "splat/pose_file.h"
#include "splat/train/training_log.h"
#include "splat/work_layout.h"

namespace splat {
namespace fs = std::filesystem;
using json = nlohmann::json;

void TrainRunOptions::Check() const {
  train.Check();
  if (stop_at < 1 || stop_at > train.total_iterations)
    throw std::invalid_argument(fmt::format("the stop iteration {} must be in 1..{} (the schedule)",
                                            stop_at, train.total_iterations));
  if (checkpoint_every < 1) throw std::invalid_argument("checkpoint_every must be >= 1");
  if (!start_checkpoint.empty() && labels_model.empty())
    throw std::invalid_argument("stage two needs the labelled model of op2gs-vote");
  for (int n : alternate_threads)
    if (n < 1) throw std::invalid_argument(fmt::format("alternate thread count {} is not >= 1", n));
}

namespace {

json metrics_json(const std::vector<ViewMetrics>& metrics, int iteration,
                  const std::string& split) {
  json views = json::array();
  double p = 0, s = 0, f = 0;
  for (const auto& m : metrics) {
    views.push_back({{"view", m.name},
                     {"psnr", m.psnr},
                     {"ssim", m.ssim},
                     {"psnr_fitted_right_half", m.psnr_fitted}});
    p += m.psnr, s += m.ssim, f += m.psnr_fitted;
  }
  const double n = std::max<size_t>(metrics.size(), 1);
  return {{"iteration", iteration},
          {"split", split},
          {"test_views", metrics.size()},
          {"psnr", metrics.empty() ? json(nullptr) : json(p / n)},
          {"ssim", metrics.empty() ? json(nullptr) : json(s / n)},
          // NeRF in the Wild's protocol (exposure.h): a colour transform
          // fitted on each view's left half, PSNR of its right half.
          {"psnr_fitted_right_half", metrics.empty() ? json(nullptr) : json(f / n)},
          {"views", views}};
}

void write_ply_at(const Trainer& t, const TrainingLayout& out) {
  write_gaussian_ply(out.point_cloud(t.iteration()), t.model());
}

// The labels of a labelled model, checked against the model they are for.
std::vector<int32_t> read_labels(const fs::path& file, const GaussianModel& model) {
  const GaussianModel labelled = read_gaussian_ply(file);
  if (!labelled.has_labels)
    throw InputError(file, "the model has no label property (run op2gs-vote)");
  if (labelled.size() != model.size() || labelled.means != model.means)
    throw InputError(file, fmt::format("the labels are for another model ({} Gaussians, the "
                                       "checkpoint has {}); run op2gs-vote on this checkpoint",
                                       labelled.size(), model.size()));
  return labelled.labels;
}

}  // namespace

int last_opacity_reset(const fs::path& work, int iteration) {
  const fs::path log = TrainingLayout{work}.log();
  int last = -1;
  if (fs::exists(log)) {
    std::ifstream in(log);
    for (std::string line; std::getline(in, line);) {
      if (line.find("opacity_reset") == std::string::npos) continue;
      const json j = json::parse(line, nullptr, false);
      if (j.is_object() && j.value("opacity_reset", false) && j.value("iteration", 0) <= iteration)
        last = std::max(last, j.value("iteration", 0));
    }
    return last;
  }
  const TrainOptions defaults;
  for (int r = defaults.opacity_reset_every; r < defaults.densify_until && r <= iteration;
       r += defaults.opacity_reset_every)
    last = r;
  return last;
}

// train_until one iteration at a time, each in a task arena of its turn's
// thread count (TrainRunOptions::alternate_threads), the count passed on in
// the iteration's statistics.
void train_alternating_threads(Trainer& t, int until, const std::vector<int>& counts,
                               const std::function<void(const IterationStats&)>& on_iteration) {
  std::vector<std::unique_ptr<tbb::task_arena>> arenas;
  for (int n : counts) arenas.push_back(std::make_unique<tbb::task_arena>(n));
  for (size_t k = 0; t.iteration() < until; ++k) {
    const size_t turn = k % counts.size();
    arenas[turn]->execute([&] {
      t.train_until(t.iteration() + 1, [&](const IterationStats& s) {
        IterationStats logged = s;
        logged.threads = counts[turn];
        on_iteration(logged);
      });
    });
  }
}

// Decodes the training views (and in stage two their ID maps) before the
// first iteration, on all cores: a decode at first use kept the other core
// idle and made each iteration of the first epoch slower.
void preload_training_inputs(Trainer& t) {
  const auto start = std::chrono::steady_clock::now();
  const Trainer::Preloaded p = t.preload_training_inputs();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const size_t n = t.split().train.size();
  spdlog::info("decoded {} of {} training views{} in {:.1f} s{}", p.views, n,
               p.id_maps ? fmt::format(" and {} ID maps", p.id_maps) : "", seconds,
               p.views < n ? " (the view cache holds no more)" : "");
}

TrainRunResult run_training(const fs::path& scene_dir, const fs::path& work,
                            const TrainRunOptions& o) {
  o.Check();
  const auto t0 = std::chrono::steady_clock::now();
  Trainer trainer(scene_dir, o.train);
  const TrainingLayout out{work};
  const fs::path checkpoint = out.latest_checkpoint();
  if (o.resume) {
    if (!fs::exists(checkpoint)) throw InputError(checkpoint, "no checkpoint to resume from");
    trainer.load_checkpoint(checkpoint);
    spdlog::info("resumed at iteration {} with {} Gaussians", trainer.iteration(),
                 trainer.model().size());
  } else if (!o.start_checkpoint.empty()) {
    trainer.load_checkpoint(o.start_checkpoint);
    if (trainer.iteration() >= o.stop_at)
      throw std::invalid_argument(
          fmt::format("the stage-one checkpoint is at iteration {}, not "
                      "before the stop iteration {}",
                      trainer.iteration(), o.stop_at));
    trainer.start_instance_learning(read_labels(o.labels_model, trainer.model()));
    // Stage two continues stage one's random stream, so that the two stages
    // are one run; a seed other than 0 starts another (the spread of stage
    // two alone). A resumed run continues its checkpoint's in either case.
    if (o.train.seed != 0) trainer.reseed(o.train.seed);
    spdlog::info("stage two from iteration {} with {} Gaussians; sigma* initialised from sigma",
                 trainer.iteration(), trainer.model().size());
  } else {
    trainer.initialize_from_sfm();
    spdlog::info("{} Gaussians from the SfM points; {} training and {} test views ({})",
                 trainer.model().size(), trainer.split().train.size(), trainer.split().test.size(),
                 trainer.split().rule);
  }
  preload_training_inputs(trainer);
  fs::create_directories(work);
  remove_abandoned_temporaries(work);
  TrainingLog log(out.log(), trainer.iteration());
  ProgressBar bar(trainer.iteration(), o.stop_at);
  auto is_in = [](const std::vector<int>& v, int it) {
    return std::find(v.begin(), v.end(), it) != v.end();
  };

  // The checkpoint, and beside it the refined poses the later stages read.
  auto save_latest = [&] {
    trainer.save_checkpoint(checkpoint);
    if (trainer.refines_poses()) write_pose_file(out.refined_poses(), trainer.refined_poses());
  };
  const auto on_iteration = [&](const IterationStats& s) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    log.record(s, elapsed);
    bar.update(s);
    if (s.iteration % o.checkpoint_every == 0 && s.iteration != o.stop_at) save_latest();
    if (is_in(o.keep_checkpoint_at, s.iteration))
      trainer.save_checkpoint(out.checkpoint_at(s.iteration));
    if (is_in(o.ply_at, s.iteration) && s.iteration != o.stop_at) write_ply_at(trainer, out);
    if (is_in(o.test_at, s.iteration) && s.iteration != o.stop_at && !trainer.split().test.empty())
      log.record_test(s.iteration, trainer.evaluate(trainer.split().test));
  };
  if (o.alternate_threads.empty())
    trainer.train_until(o.stop_at, on_iteration);
  else
    train_alternating_threads(trainer, o.stop_at, o.alternate_threads, on_iteration);
  bar.finish();
  save_latest();
  write_ply_at(trainer, out);
  if (trainer.refines_poses()) {
    const auto [angle, distance] = trainer.largest_pose_correction();
    spdlog::info("refined poses in {}: the largest correction {:.3f} degrees, {:.4g} scene units",
                 out.refined_poses().string(), angle * 180 / M_PI, distance);
  }

  const std::vector<ViewMetrics> metrics =
      o.test_at_end ? trainer.evaluate(trainer.split().test, out.test_renders())
                    : std::vector<ViewMetrics>{};
  if (!metrics.empty()) log.record_test(trainer.iteration(), metrics);
  json m = metrics_json(metrics, trainer.iteration(), trainer.split().rule);
  if (o.train.object_loss.weight > 0) {  // stage two: which object loss made sigma*
    const PixelLoss& pixel = o.train.object_loss.pixel_loss;
    m["object_loss"] = pixel.kind == PixelLoss::Kind::kGeneralized
                           ? json{{"pixel_loss", "generalized cross-entropy"}, {"q", pixel.q}}
                           : json{{"pixel_loss", "cross-entropy"}};
    if (pixel.kind == PixelLoss::Kind::kGeneralized && pixel.outline_band > 0)
      m["object_loss"]["cross_entropy_near_model_outline"] = pixel.outline_band;
    if (pixel.kind == PixelLoss::Kind::kGeneralized && pixel.outline_band > 0 &&
        pixel.outline_q > 0)
      m["object_loss"]["q_near_model_outline"] = pixel.outline_q;
    if (!o.train.object_loss.reshapes_geometry) m["object_loss"]["reshapes_geometry"] = false;
  }
  // What of the fast or dash recipe made the model (none of it in the paper's).
  if (o.train.sparse_adam) m["sparse_adam"] = true;
  if (const ResolutionScheduleOptions& r = o.train.resolution_schedule; r.enabled())
    m["resolution_schedule"] = {{"start_downscale", r.start_downscale}, {"full_from", r.full_from}};
  if (o.train.half_views.from_iteration > 0)
    m["half_views_from"] = o.train.half_views.from_iteration;
  if (o.train.lr_position_hold_until > 0)
    m["position_lr_hold_until"] = o.train.lr_position_hold_until;
  if (o.train.densify.max_gaussians > 0) m["max_gaussians"] = o.train.densify.max_gaussians;
  write_text_atomically(out.metrics(), m.dump(2) + "\n");
  plot_training_curve(out.log(), out.curve());

  TrainRunResult r;
  r.iteration = trainer.iteration();
  r.gaussians = trainer.model().size();
  r.test_views = metrics.size();
  if (!metrics.empty())
    r.test_psnr = m["psnr"].get<double>(), r.test_ssim = m["ssim"].get<double>();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace splat
