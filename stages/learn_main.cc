// op2gs-learn: stage two of OP2GS. Continues the stage-one checkpoint with
// the labels of op2gs-vote, adds the instance opacity sigma* and learns it
// with the random object loss, to iteration 30,000 by default.

#include "stages/training_cli.h"

namespace {

// The paper's start-step ablation: starting within 1,000 iterations after an
// opacity reset hurts, as the opacities have not recovered yet.
void warn_if_just_after_reset(const std::filesystem::path& checkpoint,
                              const std::filesystem::path& stage_one_work) {
  const int start = splat::read_checkpoint_iteration(checkpoint);
  const int reset = splat::last_opacity_reset(stage_one_work, start);
  if (reset >= 0 && start - reset < 1000)
    spdlog::warn(
        "stage two starts at iteration {}, {} iterations after the opacity reset at {}: the "
        "paper's ablation shows that starting within 1,000 after a reset hurts",
        start, start - reset, reset);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Stage two of OP2GS: learn the instance opacity sigma* with the random object loss."};
  splat::TrainRunOptions o;
  o.stop_at = 30000;
  o.train.object_loss.weight = 0.1f;
  std::string scene, work, checkpoint, labels;
  app.add_option("scene", scene, "scene folder (images/, sparse/0/, sam2/)")->required();
  app.add_option("work", work, "work folder of stage one; writes <work>/learn/")->required();
  stages::TrainingCli common(app, o);
  app.add_option("--checkpoint", checkpoint,
                 "stage-one checkpoint to start from (default <work>/checkpoints/latest.ckpt; "
                 "its iteration is the start step)");
  app.add_option("--labels", labels,
                 "labelled model of op2gs-vote (default <work>/vote/point_cloud.ply)");
  app.add_flag("--resume", o.resume, "continue from <work>/learn/checkpoints/latest.ckpt");
  app.add_option("--lambda-o", o.train.object_loss.weight,
                 "weight of the random object loss (0: continue stage one without it)")
      ->capture_default_str();
  app.add_option("--objects-per-step", o.train.object_loss.objects_per_step,
                 "M, objects sampled per iteration")
      ->capture_default_str();
  app.add_option("--id-maps", o.train.object_loss.id_maps,
                 "ID map folder inside the scene (auto: object_mask/ for LERF-Mask, sam2/ for "
                 "photos, whichever exists)")
      ->capture_default_str();
  app.add_option("--sigma-star-init", o.train.instance_opacity_init,
                 "initial sigma* of every Gaussian in (0, 1); default: each Gaussian's sigma "
                 "(the paper)");
  app.add_option("--protect-agreement", o.train.object_loss.protected_agreement,
                 "Gaussians whose label won at least this share of their votes keep their "
                 "sigma*: the object loss may raise it, not lower it, so masks that miss part "
                 "of an object in some views punch no holes (0: off, the paper)")
      ->capture_default_str();
  bool sigma_star_only = false;
  app.add_flag("--sigma-star-only", sigma_star_only,
               "ablation: the object loss trains sigma* only, not the Gaussians' position and "
               "shape (the paper trains both; docs/benchmarks.md measures what that path is "
               "worth)");
  // robust-outline won or tied the paper's recipe on every condition measured
  // (docs/benchmarks.md, "Where the targets stand"), so it is the default.
  std::string recipe = "robust-outline";
  app.add_option("--recipe", recipe,
                 "robust-outline: the object loss is the generalized cross-entropy (--gce-q), "
                 "which learns the majority of the views' masks instead of their mean, so a "
                 "segmenter's misses and leaks in some views are outvoted, as the vote outvotes "
                 "them, and the paper's binary cross-entropy within 3 pixels of the outline of "
                 "the model's own mask of the object, where the generalized loss would dilate "
                 "the masks; paper: the paper's binary cross-entropy everywhere (the paper's "
                 "recipe exactly); robust: the generalized cross-entropy everywhere")
      ->capture_default_str()
      // The last one given wins, so that the pipeline's LEARN_OPTS overrides its
      // RECIPE.
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--gce-q", o.train.object_loss.pixel_loss.q,
                 "q of the generalized cross-entropy (--recipe robust, robust-outline), in (0, 1]")
      ->capture_default_str();
  app.add_option("--outline-q", o.train.object_loss.pixel_loss.outline_q,
                 "--recipe robust-outline: q of the generalized cross-entropy within the band "
                 "along the model's outline, in [0, 1]; 0: the cross-entropy there. Above 0 it "
                 "sharpens the outline that jittered masks blur, and follows masks that are "
                 "loose in every view outwards, where it loses to 0 (docs/benchmarks.md)")
      ->capture_default_str();
  app.add_option("--lr-instance-opacity", o.train.lr_instance_opacity,
                 "learning rate of sigma* (as a logit)")
      ->capture_default_str();
  return stages::run_stage(app, argc, argv, [&] {
    common.apply();
    o.train.object_loss.pixel_loss.kind = stages::parse_choice<splat::PixelLoss::Kind>(
        "--recipe", recipe,
        {{"paper", splat::PixelLoss::Kind::kCrossEntropy},
         {"robust", splat::PixelLoss::Kind::kGeneralized},
         {"robust-outline", splat::PixelLoss::Kind::kGeneralized}});
    // The masks' outline error is a jitter of a few pixels whatever the
    // object's size (docs/synthetic.md): 3 pixels, fixed before any run.
    if (recipe == "robust-outline") o.train.object_loss.pixel_loss.outline_band = 3;
    o.train.object_loss.reshapes_geometry = !sigma_star_only;
    o.train.densify_until = 0;  // no densification (nor opacity reset) in stage two
    const splat::WorkLayout w{work};
    o.start_checkpoint = stages::or_default(checkpoint, w.stage_one().latest_checkpoint());
    o.labels_model = stages::or_default(labels, w.labelled_model());
    if (o.train.object_loss.protected_agreement > 0)
      o.train.object_loss.label_agreement =
          o.labels_model.parent_path() / w.label_agreement().filename();  // op2gs-vote's, beside
    // The track IDs op2gs-vote joined (--join-switched-ids) are one object
    // here too, and the segments it found covering two objects are not used.
    splat::read_id_corrections(w.vote() / "summary.json", o.train.object_loss);
    if (!o.train.object_loss.id_remap.empty() || !o.train.object_loss.ignored_ids.empty())
      spdlog::info("the ID maps as op2gs-vote corrected them: {} IDs joined, {} segments unused",
                   o.train.object_loss.id_remap.size(), [&] {
                     size_t n = 0;
                     for (const auto& [view, ids] : o.train.object_loss.ignored_ids)
                       n += ids.size();
                     return n;
                   }());
    if (!o.resume) {
      if (!std::filesystem::exists(o.start_checkpoint))
        throw splat::InputError(o.start_checkpoint, "no stage-one checkpoint (run op2gs-train)");
      warn_if_just_after_reset(o.start_checkpoint, w.stage_one().root);
    }
    const std::filesystem::path out = w.stage_two().root;
    stages::TrainingCli::report(splat::run_training(scene, out, o), out.string());
  });
}
