// op2gs-render: colour, object masks, label maps and object operations of a
// stage-two model, for chosen views or a camera path.

#include "splat/label/render_run.h"
#include "splat/label/vote_run.h"
#include "splat/ply.h"
#include "stages/common.h"

int main(int argc, char** argv) {
  CLI::App app{"Render RGB, object masks and label maps of an OP2GS model."};
  splat::RenderRunOptions o;
  std::string scene, work, out, model, views = "test", split = "auto", camera_path;
  std::string photo_geometry = "off";
  std::vector<std::string> view_names;
  std::vector<float> background;
  int threads = 0;
  int32_t ply_object = 0, ply_without = 0;
  std::string ply_out;
  float min_sigma = 0.1f;
  app.add_option("scene", scene, "scene folder")->required();
  app.add_option("work", work, "work folder; reads <work>/learn/, writes <work>/render/")
      ->required();
  app.add_option("--model", model,
                 "model: checkpoint or PLY (default <work>/learn/checkpoints/latest.ckpt)");
  app.add_option("--out", out, "output folder (default <work>/render)");
  app.add_option("--views", views, "test, train or all")->capture_default_str();
  app.add_option("--view", view_names, "render these views (image names) instead");
  app.add_option("--camera-path", camera_path,
                 "COLMAP model folder whose images are the cameras to render instead");
  app.add_option("--object", o.objects, "only these object IDs (default: all)");
  app.add_option("--tau", o.tau, "mask threshold on the occupancy S_j")->capture_default_str();
  app.add_flag("--occupancy", o.occupancy, "also write the occupancy maps as grey images");
  app.add_flag("--object-images", o.object_images, "also write each object's masked image");
  app.add_flag("--photo-geometry{on}", photo_geometry,
               "also write masks and label maps in the geometry of the photos (photo/), which "
               "needs the photos' cameras op2gs-sfm records when it undistorts; "
               "--photo-geometry=auto: only when they are there")
      ->check(CLI::IsMember({"on", "off", "auto"}));
  app.add_option("--background", background, "background colour r g b in [0, 1]")->expected(3);
  app.add_option("--ply-object", ply_object, "write a PLY of this object only (to --ply-out)");
  app.add_option("--ply-without", ply_without, "write a PLY of the scene without this object");
  app.add_option("--ply-out", ply_out, "PLY file of --ply-object / --ply-without");
  app.add_option("--min-instance-opacity", min_sigma,
                 "an object's Gaussians have its label and sigma* at least this")
      ->capture_default_str();
  stages::add_scene_options(app, o.scene, split, threads);
  return stages::run_stage(app, argc, argv, [&] {
    const stages::ThreadLimit limit(threads);
    const std::filesystem::path w = work;
    o.model =
        model.empty() ? w / "learn" / "checkpoints" / "latest.ckpt" : std::filesystem::path(model);
    if (ply_object || ply_without) {
      if (ply_out.empty()) throw std::invalid_argument("--ply-out is required");
      const splat::GaussianModel m = splat::read_model_file(o.model).model;
      const splat::GaussianModel part = ply_object
                                            ? splat::select_object(m, ply_object, min_sigma)
                                            : splat::remove_object(m, ply_without, min_sigma);
      splat::write_gaussian_ply(ply_out, part);
      spdlog::info("{} of {} Gaussians written to {}", part.size(), m.size(), ply_out);
      return;
    }
    o.split = stages::parse_split(split);
    o.view_names = view_names;
    o.camera_path = camera_path;
    if (views != "test" && views != "train" && views != "all")
      throw std::invalid_argument("--views must be test, train or all");
    o.views = views == "test"    ? splat::RenderViews::kTest
              : views == "train" ? splat::RenderViews::kTrain
                                 : splat::RenderViews::kAll;
    o.photo_geometry = photo_geometry == "on"     ? splat::PhotoGeometryMode::kOn
                       : photo_geometry == "auto" ? splat::PhotoGeometryMode::kAuto
                                                  : splat::PhotoGeometryMode::kOff;
    if (!background.empty()) std::copy_n(background.begin(), 3, o.background);
    const std::filesystem::path dir = out.empty() ? w / "render" : std::filesystem::path(out);
    const splat::RenderTiming t = splat::run_render(scene, dir, o);
    spdlog::info(
        "{} views: colour {:.1f} ms, all-object masks {:.1f} ms ({:.2f}x), instance "
        "label map {:.1f} ms per view",
        t.views, t.color_ms, t.masks_ms, t.color_ms > 0 ? t.masks_ms / t.color_ms : 0,
        t.label_map_ms);
    spdlog::info("outputs in {}", dir.string());
  });
}
