// op2gs-render: colour, object masks, label maps and object operations of a
// stage-two model, for chosen views or a camera path.

#include "splat/label/object_ply.h"
#include "splat/label/render_run.h"
#include "splat/pose_file.h"
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
  splat::ObjectPlyOptions ply;
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
               "--photo-geometry=auto: only when they are there");
  app.add_option("--background", background, "background colour r g b in [0, 1]")->expected(3);
  app.add_option("--ply-object", ply_object, "write a PLY of this object only (to --ply-out)");
  app.add_option("--ply-without", ply_without, "write a PLY of the scene without this object");
  app.add_option("--ply-out", ply.out, "PLY file of --ply-object / --ply-without");
  app.add_option("--min-instance-opacity", ply.min_instance_opacity,
                 "an object's Gaussians have its label and sigma* at least this")
      ->capture_default_str();
  stages::add_scene_options(app, o.scene, split, threads);
  std::string poses;
  stages::add_poses_option(app, poses);
  app.add_option("--fit-poses", o.fit_poses.iterations,
                 "fit the camera of every view without a refined pose (the test views) to its "
                 "photo with this many steps before rendering it (0: off)")
      ->capture_default_str();
  return stages::run_stage(app, argc, argv, [&] {
    const stages::ThreadLimit limit(threads);
    const splat::WorkLayout w{work};
    o.scene.poses = splat::choose_pose_file(poses, w.refined_poses_of_stage_two_model());
    o.model = stages::or_default(model, w.stage_two().latest_checkpoint());
    if (ply_object || ply_without) {
      ply.model = o.model;
      ply.object = ply_object ? ply_object : ply_without;
      ply.without = !ply_object;
      const splat::ObjectPlyResult r = splat::write_object_ply(ply);
      spdlog::info("{} of {} Gaussians written to {}", r.written, r.total, ply.out.string());
      return;
    }
    o.split = stages::parse_split(split);
    o.view_names = view_names;
    o.camera_path = camera_path;
    o.views = stages::parse_choice<splat::RenderViews>("--views", views,
                                                       {{"test", splat::RenderViews::kTest},
                                                        {"train", splat::RenderViews::kTrain},
                                                        {"all", splat::RenderViews::kAll}});
    o.photo_geometry =
        stages::parse_choice<splat::PhotoGeometryMode>("--photo-geometry", photo_geometry,
                                                       {{"off", splat::PhotoGeometryMode::kOff},
                                                        {"on", splat::PhotoGeometryMode::kOn},
                                                        {"auto", splat::PhotoGeometryMode::kAuto}});
    if (!background.empty()) std::copy_n(background.begin(), 3, o.background);
    const std::filesystem::path dir = stages::or_default(out, w.render());
    const splat::RenderTiming t = stages::write_staged(
        out, w.render(),
        [&](const std::filesystem::path& to) { return splat::run_render(scene, to, o); });
    spdlog::info(
        "{} views: colour {:.1f} ms, all-object masks {:.1f} ms ({:.2f}x), instance "
        "label map {:.1f} ms per view",
        t.views, t.color_ms, t.masks_ms, t.color_ms > 0 ? t.masks_ms / t.color_ms : 0,
        t.label_map_ms);
    spdlog::info("outputs in {}", dir.string());
  });
}
