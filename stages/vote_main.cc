// op2gs-vote: label every Gaussian of the stage-one model by majority vote of
// the scene's ID maps (SAM2 masks), and render the ablation's baseline masks.

#include "splat/label/vote_run.h"
#include "splat/pose_file.h"
#include "stages/common.h"

int main(int argc, char** argv) {
  CLI::App app{"Give every Gaussian an object label by majority vote of precomputed ID maps."};
  splat::VoteRunOptions o;
  std::string scene, work, split = "auto", visibility = "depth", model;
  int threads = 0;
  app.add_option("scene", scene, "scene folder (images/, sparse/0/, sam2/)")->required();
  app.add_option("work", work, "work folder of stage one; writes <work>/vote/")->required();
  app.add_option("--model", model,
                 "stage-one model: checkpoint or PLY (default <work>/checkpoints/latest.ckpt)");
  app.add_option("--id-maps", o.id_maps,
                 "ID map folder inside the scene (auto: object_mask/ for LERF-Mask, sam2/ for "
                 "photos, whichever exists)")
      ->capture_default_str();
  app.add_option("--visibility", visibility,
                 "depth: in the image and not occluded; frustum: in the image only")
      ->capture_default_str();
  app.add_option("--depth-tolerance", o.vote.depth_tolerance,
                 "occluded when deeper than (1 + this) times the rendered depth")
      ->capture_default_str();
  app.add_option("--depth-max-width", o.vote.depth_max_width,
                 "render the occlusion depth at most this wide (0: the ID map's size)")
      ->capture_default_str();
  app.add_flag("--allow-missing", o.allow_missing,
               "skip training views without an ID map (with a warning)");
  app.add_flag("--join-switched-ids", o.join_switched_ids,
               "join the IDs a video segmenter gave one object after losing its track (IDs "
               "never seen together that label the same Gaussians) before the majority vote");
  app.add_flag("--find-merges", o.find_merges,
               "find the views' segments that cover a second object (a segmenter's merge) for "
               "op2gs-learn to leave out (a second pass over the views)");
  app.add_option("--id-association", o.track_ids.min_association,
                 "with --join-switched-ids: the least share of views in which one ID's "
                 "Gaussians carry the other")
      ->capture_default_str();
  app.add_option("--previews", o.preview_views, "training views with a label preview")
      ->capture_default_str();
  stages::add_scene_options(app, o.scene, split, threads,
                            "downscale factor 1, 2, 4 or 8 of the baseline maps and previews");
  std::string poses;
  stages::add_poses_option(app, poses);
  return stages::run_stage(app, argc, argv, [&] {
    const stages::ThreadLimit limit(threads);
    const splat::WorkLayout w{work};
    o.scene.poses = splat::choose_pose_file(poses, w.refined_poses_of_stage_one_model());
    o.model = stages::or_default(model, w.stage_one().latest_checkpoint());
    o.split = stages::parse_split(split);
    o.vote.visibility = stages::parse_choice<splat::VoteVisibility>(
        "--visibility", visibility,
        {{"depth", splat::VoteVisibility::kDepth}, {"frustum", splat::VoteVisibility::kFrustum}});
    const splat::VoteRunResult r = stages::write_staged(
        "", w.vote(),
        [&](const std::filesystem::path& to) { return splat::run_voting(scene, to, o); });
    spdlog::info(
        "{} Gaussians labelled from {} views: {} objects, {:.1f}% background "
        "({:.1f}% seen in no view), vote agreement {:.1f}%, {:.1f} s",
        r.gaussians, r.views_used, r.objects, 100 * r.background_share, 100 * r.unseen_share,
        100 * r.vote_agreement, r.seconds);
    spdlog::info("outputs in {}", w.vote().string());
  });
}
