// op2gs-floaters: floaters and wrongly labelled Gaussians of a trained model
// of an op2gs-synth scene, against the scene's true surfaces.

#include "eval/floaters/floaters_run.h"
#include "splat/work_layout.h"
#include "stages/common.h"

int main(int argc, char** argv) {
  CLI::App app{"Measure floaters and label contamination of a model of a synthetic scene."};
  study::FloaterRunOptions o;
  std::string scene, work, model, out, split = "auto";
  int threads = 0;
  bool no_render = false;
  app.add_option("scene", scene, "op2gs-synth scene folder (with surfaces.json)")->required();
  app.add_option("work", work, "work folder of the model")->required();
  app.add_option("--model", model,
                 "labelled model (default: stage two's latest checkpoint, else vote's PLY)");
  app.add_option("--distance", o.floaters.distance,
                 "a Gaussian farther than this from every surface is a floater (world units)")
      ->capture_default_str();
  app.add_option("--out", out, "report file (default <work>/floaters.json)");
  app.add_flag("--no-render", no_render, "skip the opacity and mask shares over the test views");
  stages::add_scene_options(app, o.scene, split, threads, "downscale factor of the test views");
  return stages::run_stage(app, argc, argv, [&] {
    const stages::ThreadLimit limit(threads);
    const splat::WorkLayout w{work};
    const auto stage_two = w.stage_two().latest_checkpoint();
    o.model = !model.empty()                       ? std::filesystem::path(model)
              : std::filesystem::exists(stage_two) ? stage_two
                                                   : w.labelled_model();
    o.split = stages::parse_split(split);
    o.render = !no_render;
    const std::filesystem::path file =
        out.empty() ? w.root / "floaters.json" : std::filesystem::path(out);
    const study::FloaterReport r = study::run_floaters(scene, file, o);
    spdlog::info(
        "{} of {} Gaussians are floaters ({:.1f}%), {} of them labelled; they carry "
        "{:.1f}% of the rendered opacity",
        r.floaters, r.gaussians, 100.0 * r.floaters / std::max<size_t>(r.gaussians, 1),
        r.floaters_labelled, 100 * r.floater_opacity_share);
    spdlog::info(
        "in the object region: {} of {} Gaussians are floaters, carrying {:.1f}% of the "
        "rendered opacity",
        r.region_floaters, r.region_gaussians, 100 * r.region_floater_opacity_share);
    spdlog::info(
        "wrongly labelled Gaussians carry {:.1f}% of the masks with sigma, {:.1f}% "
        "with sigma*",
        100 * r.mask_wrong_share_sigma, 100 * r.mask_wrong_share_sigma_star);
    spdlog::info("report in {}", file.string());
  });
}
