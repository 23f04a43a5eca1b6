// op2gs-embed: one CLIP image embedding per object of a stage-two model, from
// masked crops of the training views where the object is largest.

#include <chrono>

#include "splat/clip/clip_model.h"
#include "splat/pose_file.h"
#include "splat/query/embed_run.h"
#include "stages/common.h"

int main(int argc, char** argv) {
  CLI::App app{"Embed every object of an OP2GS model with CLIP (masked crops, N views)."};
  splat::EmbedRunOptions o;
  std::string scene, work, model, out, split = "auto", clip = splat::default_clip_dir().string();
  std::vector<float> background;
  int threads = 0;
  app.add_option("scene", scene, "scene folder")->required();
  app.add_option("work", work, "work folder; reads <work>/learn/, writes <work>/embed/")
      ->required();
  app.add_option("--model", model,
                 "model: checkpoint or PLY (default <work>/learn/checkpoints/latest.ckpt)");
  app.add_option("--out", out, "output folder (default <work>/embed)");
  app.add_option("--clip", clip,
                 "folder with model.safetensors, config.json, vocab.json, merges.txt of "
                 "openai/clip-vit-base-patch16 (default $OP2GS_CLIP_DIR or "
                 "~/.cache/op2gs/clip-vit-base-patch16)")
      ->capture_default_str();
  app.add_option("--views-per-object", o.views_per_object,
                 "N: training views per object, those where its mask is largest")
      ->capture_default_str();
  app.add_option("--tau", o.tau, "mask threshold on the occupancy S_j")->capture_default_str();
  app.add_option("--margin", o.margin, "crop margin on each side, relative to the mask's box")
      ->capture_default_str();
  app.add_option("--min-mask-pixels", o.min_mask_pixels, "smaller masks are not used")
      ->capture_default_str();
  app.add_option("--crop-background", background, "colour r g b in [0, 1] outside the mask")
      ->expected(3);
  app.add_option("--object", o.objects, "only these object IDs (default: all)");
  stages::add_scene_options(app, o.scene, split, threads);
  std::string poses;
  stages::add_poses_option(app, poses);
  return stages::run_stage(app, argc, argv, [&] {
    const stages::ThreadLimit limit(threads);
    const splat::WorkLayout w{work};
    o.scene.poses = splat::choose_pose_file(poses, w.refined_poses_of_stage_two_model());
    o.model = stages::or_default(model, w.stage_two().latest_checkpoint());
    o.clip_dir = clip;
    o.split = stages::parse_split(split);
    if (!background.empty()) std::copy_n(background.begin(), 3, o.crop_background.begin());
    const std::filesystem::path dir = stages::or_default(out, w.embed());
    const auto start = std::chrono::steady_clock::now();
    const splat::ObjectEmbeddings e = stages::write_staged(
        out, w.embed(),
        [&](const std::filesystem::path& to) { return splat::run_embed(scene, to, o); });
    size_t crops = 0;
    for (const auto& obj : e.objects) crops += obj.views.size();
    spdlog::info("{} objects embedded from {} crops in {:.1f} s; outputs in {}", e.objects.size(),
                 crops,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                 dir.string());
  });
}
