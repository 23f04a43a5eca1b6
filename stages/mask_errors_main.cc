// op2gs-mask-errors: a folder of exact ID maps with a video segmenter's
// errors added (SAM2-like mask errors, and track errors on request), to run
// one scene with exact and with realistic masks side by side
// (docs/synthetic.md).

#include "stages/common.h"
#include "stages/mask_error_options.h"
#include "synth/mask_errors_run.h"

int main(int argc, char** argv) {
  CLI::App app{"Add a video segmenter's errors to a folder of exact ID maps."};
  synth::MaskErrorRunOptions o;
  std::string in, out;
  bool tracks = false;
  app.add_option("in", in, "folder of exact ID maps (<image stem>.png, in video order by name)")
      ->required();
  app.add_option("out", out, "folder to write the maps with errors into")->required();
  app.add_option("--seed", o.seed, "seed of every draw")->capture_default_str();
  stages::add_mask_error_options(app, o.sam2, "");
  app.add_flag("--tracks", tracks,
               "also the track errors of op2gs-synth --capture: ID switches, merges, late objects");
  return stages::run_stage(app, argc, argv, [&] {
    if (tracks) o.tracks = synth::TrackErrorOptions::typical();
    o.Check();
    if (std::filesystem::exists(out) && std::filesystem::equivalent(out, in))
      throw splat::InputError(out, "is the exact maps' own folder: write to another");
    splat::StagedFolder staged(out, splat::StagedFolder::Target::kOwned);
    const synth::MaskErrorRunResult r = synth::add_mask_errors(in, staged.path(), o);
    staged.commit();
    spdlog::info(
        "{} maps, {} objects: {:.2f}% of the pixels changed, object IoU against the "
        "exact masks {:.1f}%{}",
        r.maps, r.objects, 100 * r.changed_share, 100 * r.mean_object_iou,
        r.new_ids ? fmt::format(", {} new IDs from switches", r.new_ids) : "");
    spdlog::info("written to {}", out);
  });
}
