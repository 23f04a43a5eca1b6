#include "splat/label/render_run.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "splat/atomic_file.h"
#include "splat/checkpoint.h"
#include "splat/colmap_model.h"
#include "splat/error.h"
#include "splat/label/palette.h"
#include "splat/label/vote_run.h"
#include "splat/photo_cameras.h"
#include "splat/pose_file.h"
#include "splat/render/renderer.h"

namespace splat {
namespace fs = std::filesystem;
using json = nlohmann::json;

void RenderRunOptions::Check() const {
  scene.Check();
  if (!(tau > 0 && tau < 1)) throw std::invalid_argument("tau must be in (0, 1)");
  for (int32_t id : objects)
    if (id <= 0) throw std::invalid_argument("object IDs must be > 0");
  fit_poses.Check();
}

namespace {

// A named camera to render.
struct Shot {
  std::string stem;
  Camera camera;
  int view = -1;  // index into the scene's views, -1 for a camera path
};

std::vector<Shot> shots_of(const Scene& scene, const RenderRunOptions& o) {
  std::vector<Shot> shots;
  if (!o.camera_path.empty()) {
    const ColmapModel path = read_colmap_model(o.camera_path);
    for (const auto& [id, image] : path.images)
      shots.push_back(
          {fs::path(image.name).stem().string(), pinhole_camera(path, image, o.camera_path), -1});
    std::sort(shots.begin(), shots.end(),
              [](const Shot& a, const Shot& b) { return a.stem < b.stem; });
    return shots;
  }
  std::vector<size_t> views;
  if (!o.view_names.empty()) {
    for (const std::string& name : o.view_names) {
      const int v = scene.find_view(name);
      if (v < 0) throw InputError(scene.root() / o.scene.images_dir / name, "no such view");
      views.push_back(size_t(v));
    }
  } else {
    const ViewSplit split = split_views(scene, o.split);
    if (o.views != RenderViews::kTrain) views = split.test;
    if (o.views != RenderViews::kTest)
      views.insert(views.end(), split.train.begin(), split.train.end());
    std::sort(views.begin(), views.end());
  }
  for (size_t v : views)
    shots.push_back(
        {fs::path(scene.views()[v].name).stem().string(), scene.views()[v].camera, int(v)});
  return shots;
}

ImageRGB to_image(std::span<const float> color, int w, int h) {
  ImageRGB image(w, h);
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = std::clamp(color[i], 0.f, 1.f);
  return image;
}

// Every mask and image of one shot.
void write_shot(const fs::path& out, const Shot& shot, const RenderOutput& r,
                const RenderRunOptions& o) {
  const int W = r.width, H = r.height;
  const size_t pixels = size_t(W) * H;
  const ImageRGB rgb = to_image(r.color, W, H);
  write_image_rgb(out / "rgb" / (shot.stem + ".png"), rgb);
  ImageRGB overlay = rgb;
  for (float& v : overlay.data) v *= 0.4f;
  for (size_t m = 0; m < r.instance_map_labels.size(); ++m) {
    const int32_t id = r.instance_map_labels[m];
    const float* S = &r.instance_maps[m * pixels];
    std::vector<uint8_t> inside(pixels);
    for (size_t p = 0; p < pixels; ++p) inside[p] = S[p] > o.tau;
    const std::string name = fmt::format("{}.png", id);
    write_mask_png(out / "masks" / shot.stem / name, W, H, inside);
    const auto c = label_color(id);
    for (size_t p = 0; p < pixels; ++p)
      if (inside[p])
        for (int k = 0; k < 3; ++k)
          overlay.data[3 * p + k] = 0.5f * overlay.data[3 * p + k] + 0.5f * c[k];
    if (o.occupancy) {
      ImageRGB grey(W, H);
      for (size_t p = 0; p < pixels; ++p)
        grey.data[3 * p] = grey.data[3 * p + 1] = grey.data[3 * p + 2] = std::clamp(S[p], 0.f, 1.f);
      write_image_rgb(out / "occupancy" / shot.stem / name, grey);
    }
    if (o.object_images) {
      ImageRGB object(W, H);
      for (size_t p = 0; p < pixels; ++p)
        if (inside[p]) std::copy_n(&rgb.data[3 * p], 3, &object.data[3 * p]);
      write_image_rgb(out / "objects" / shot.stem / name, object);
    }
  }
  write_image_rgb(out / "masks_color" / (shot.stem + ".png"), overlay);
  write_label_map(out / "instance_labels", shot.stem, r.instance_label, W, H);
  write_label_map(out / "baseline_labels", shot.stem, r.baseline_label, W, H);
}

// The masks and the instance label map of a shot, moved into the geometry of
// its photo (--photo-geometry).
void write_photo_shot(const fs::path& out, const Shot& shot, const std::string& image_name,
                      const RenderOutput& r, const PhotoCameras& photos, float tau) {
  const auto s = photos.sampling(image_name, r.width, r.height);
  if (!s) {
    spdlog::warn("{}: not among the photos' cameras; no photo-geometry masks", image_name);
    return;
  }
  const size_t pixels = size_t(r.width) * r.height;
  for (size_t m = 0; m < r.instance_map_labels.size(); ++m) {
    const std::vector<float> S =
        s->gather(std::span<const float>(&r.instance_maps[m * pixels], pixels));
    std::vector<uint8_t> inside(S.size());
    for (size_t i = 0; i < S.size(); ++i) inside[i] = S[i] > tau;
    write_mask_png(out / "masks" / shot.stem / fmt::format("{}.png", r.instance_map_labels[m]),
                   s->width, s->height, inside);
  }
  write_label_map(out / "instance_labels", shot.stem, s->gather<int32_t>(r.instance_label),
                  s->width, s->height);
}

double milliseconds_of(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The photos' cameras to write photo-geometry masks for; none when they are
// not wanted, or when auto finds none.
PhotoCameras photo_cameras_to_use(const fs::path& scene_dir, PhotoGeometryMode mode) {
  if (mode == PhotoGeometryMode::kOff) return {};
  PhotoCameras photos = PhotoCameras::load(scene_dir);
  if (!photos.empty()) return photos;
  if (mode == PhotoGeometryMode::kOn)
    throw InputError(scene_dir / kPhotoCamerasDir,
                     "no photos' cameras: op2gs-sfm records them when it undistorts the photos; "
                     "without them the views are the photos");
  spdlog::info("no photos' cameras in {}: the views are the photos, so no photo/ masks",
               scene_dir.string());
  return {};
}

// Fits the cameras of the shots of scene views without a refined pose to
// their photos, and writes the fitted poses to out/fitted_poses.txt.
void fit_shot_poses(Scene& scene, const GaussianModel& model, const Renderer& renderer,
                    const RenderSettings& settings, const RenderRunOptions& o, const fs::path& out,
                    std::vector<Shot>& shots) {
  std::set<std::string> refined;
  if (!o.scene.poses.empty())
    for (const NamedPose& p : read_pose_file(o.scene.poses)) refined.insert(p.name);
  std::vector<NamedPose> fitted;
  for (Shot& shot : shots) {
    if (shot.view < 0) continue;
    const std::string& name = scene.views()[size_t(shot.view)].name;
    if (refined.count(name)) continue;
    shot.camera = fit_camera_to_photo(renderer, model, shot.camera, *scene.image(size_t(shot.view)),
                                      settings, scene.extent(), o.fit_poses);
    fitted.push_back({name, shot.camera.R, shot.camera.t});
  }
  write_pose_file(out / "fitted_poses.txt", fitted);
  spdlog::info("fitted the poses of {} views to their photos ({} steps each)", fitted.size(),
               o.fit_poses.iterations);
}

}  // namespace

RenderTiming run_render(const fs::path& scene_dir, const fs::path& out, const RenderRunOptions& o) {
  o.Check();
  const CheckpointModel stage_two = read_model_file(o.model);
  const GaussianModel& model = stage_two.model;
  if (!model.has_labels)
    throw InputError(o.model, "the model has no labels (run op2gs-vote and op2gs-learn)");
  if (!model.has_instance_opacity)
    spdlog::warn("{} has no instance opacity: masks use sigma (the model of op2gs-vote)",
                 o.model.string());
  const auto scene = Scene::load(scene_dir, o.scene);
  std::vector<Shot> shots = shots_of(*scene, o);
  const PhotoCameras photos = photo_cameras_to_use(scene_dir, o.photo_geometry);
  const CpuRenderer renderer;

  RenderSettings all;
  std::copy_n(o.background, 3, all.background);
  all.sh_degree = std::min(stage_two.sh_degree, kMaxShDegree);
  all.instance_labels = o.objects;
  all.all_instance_labels = o.objects.empty();
  all.instance_label_map = all.baseline_label_map = true;
  RenderSettings color_only = all, masks_only = all, label_map_only = all;
  color_only.instance_labels.clear();
  color_only.all_instance_labels = color_only.instance_label_map = color_only.baseline_label_map =
      false;
  masks_only.color = masks_only.depth = false;
  masks_only.instance_label_map = masks_only.baseline_label_map = false;
  label_map_only.color = label_map_only.depth = false;
  label_map_only.instance_labels.clear();
  label_map_only.all_instance_labels = label_map_only.baseline_label_map = false;

  if (o.fit_poses.iterations > 0)
    fit_shot_poses(*scene, model, renderer, color_only, o, out, shots);

  RenderTiming timing;
  RenderOutput r, scratch;
  for (const Shot& shot : shots) {
    renderer.render(model, shot.camera, all, r);
    write_shot(out, shot, r, o);
    if (!photos.empty() && shot.view >= 0)
      write_photo_shot(out / "photo", shot, scene->views()[size_t(shot.view)].name, r, photos,
                       o.tau);
    // The paper's runtime comparison: the same view rendered three ways.
    timing.color_ms +=
        milliseconds_of([&] { renderer.render(model, shot.camera, color_only, scratch); });
    timing.masks_ms +=
        milliseconds_of([&] { renderer.render(model, shot.camera, masks_only, scratch); });
    timing.label_map_ms +=
        milliseconds_of([&] { renderer.render(model, shot.camera, label_map_only, scratch); });
    ++timing.views;
  }
  if (timing.views) {
    timing.color_ms /= double(timing.views);
    timing.masks_ms /= double(timing.views);
    timing.label_map_ms /= double(timing.views);
  }
  const json t = {{"views", timing.views},
                  {"gaussians", model.size()},
                  {"objects", r.instance_map_labels},
                  {"color_ms", timing.color_ms},
                  {"all_object_masks_ms", timing.masks_ms},
                  {"instance_label_map_ms", timing.label_map_ms}};
  write_text_atomically(out / "timing.json", t.dump(2) + "\n");
  return timing;
}

}  // namespace splat
