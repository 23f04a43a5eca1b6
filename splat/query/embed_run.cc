#include "splat/query/embed_run.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/checkpoint.h"
#include "splat/clip/clip_model.h"
#include "splat/error.h"
#include "splat/json_integer.h"
#include "splat/render/renderer.h"

namespace splat {
namespace fs = std::filesystem;
using json = nlohmann::json;

void EmbedRunOptions::Check() const {
  scene.Check();
  if (views_per_object < 1) throw std::invalid_argument("views per object must be at least 1");
  if (!(tau > 0 && tau < 1)) throw std::invalid_argument("tau must be in (0, 1)");
  if (!(margin >= 0 && margin <= 2)) throw std::invalid_argument("margin must be in [0, 2]");
  if (min_mask_pixels < 1) throw std::invalid_argument("the minimum mask area must be >= 1");
  for (int32_t id : objects)
    if (id <= 0) throw std::invalid_argument("object IDs must be > 0");
}

ImageRGB masked_square_crop(const ImageRGB& image, const std::vector<uint8_t>& mask, float margin,
                            const std::array<float, 3>& background) {
  const int W = image.width, H = image.height;
  int x0 = W, y0 = H, x1 = -1, y1 = -1;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      if (mask[size_t(y) * W + x])
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  if (x1 < 0) throw std::invalid_argument("masked_square_crop: empty mask");
  const int side =
      std::max(1, int(std::lround(std::max(x1 - x0 + 1, y1 - y0 + 1) * (1 + 2 * margin))));
  // Top-left corner so that the square is centred on the box.
  const int left = int(std::floor((x0 + x1 + 1) / 2.0 - side / 2.0));
  const int top = int(std::floor((y0 + y1 + 1) / 2.0 - side / 2.0));
  ImageRGB crop(side, side);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const int sx = left + x, sy = top + y;
      const bool inside = sx >= 0 && sy >= 0 && sx < W && sy < H && mask[size_t(sy) * W + sx];
      for (int c = 0; c < 3; ++c)
        crop.data[3 * (size_t(y) * side + x) + c] =
            inside ? image.data[3 * (size_t(sy) * W + sx) + c] : background[c];
    }
  return crop;
}

namespace {

struct Candidate {
  int64_t area;
  size_t view;
};

RenderSettings mask_settings(const CheckpointModel& m, const EmbedRunOptions& o) {
  RenderSettings s;
  s.color = s.depth = false;
  s.sh_degree = std::min(m.sh_degree, kMaxShDegree);
  s.instance_labels = o.objects;
  s.all_instance_labels = o.objects.empty();
  return s;
}

// For every object, its training views by mask area, the largest first (at
// most N, each with at least the minimum area).
std::map<int32_t, std::vector<Candidate>> choose_views(const GaussianModel& model, Scene& scene,
                                                       const std::vector<size_t>& views,
                                                       const RenderSettings& settings,
                                                       const EmbedRunOptions& o) {
  const CpuRenderer renderer;
  std::map<int32_t, std::vector<Candidate>> chosen;
  RenderOutput r;
  for (size_t v : views) {
    renderer.render(model, scene.views()[v].camera, settings, r);
    const size_t pixels = size_t(r.width) * r.height;
    for (size_t m = 0; m < r.instance_map_labels.size(); ++m) {
      const float* S = &r.instance_maps[m * pixels];
      const int64_t area = std::count_if(S, S + pixels, [&](float s) { return s > o.tau; });
      if (area >= o.min_mask_pixels) chosen[r.instance_map_labels[m]].push_back({area, v});
    }
  }
  for (auto& [id, list] : chosen) {
    std::stable_sort(list.begin(), list.end(),
                     [](const Candidate& a, const Candidate& b) { return a.area > b.area; });
    if (list.size() > size_t(o.views_per_object)) list.resize(size_t(o.views_per_object));
  }
  return chosen;
}

struct Crop {
  int32_t object;
  size_t slot;  // index into the object's views
  ClipPixels pixels;
};

json to_json(const ObjectEmbeddings& e, const EmbedRunOptions& o, const fs::path& model) {
  json objects = json::array();
  for (const ObjectEmbedding& obj : e.objects) {
    json views = json::array();
    for (const ObjectView& v : obj.views)
      views.push_back({{"view", v.view}, {"area", v.area}, {"crop", v.crop}});
    objects.push_back(
        {{"id", obj.id},
         {"views", views},
         {"embedding",
          std::vector<float>(obj.embedding.data(), obj.embedding.data() + obj.embedding.size())}});
  }
  return {{"clip", e.clip_dir.string()},
          {"model", model.string()},
          {"tau", o.tau},
          {"views_per_object", o.views_per_object},
          {"margin", o.margin},
          {"crop_background", o.crop_background},
          {"objects", objects},
          {"unseen", e.unseen}};
}

}  // namespace

ObjectEmbeddings run_embed(const fs::path& scene_dir, const fs::path& out,
                           const EmbedRunOptions& o) {
  o.Check();
  const ClipFiles clip_files = ClipFiles::in(o.clip_dir);  // missing files: fail at once
  const CheckpointModel checkpoint = read_model_file(o.model);
  if (!checkpoint.model.has_labels)
    throw InputError(o.model, "the model has no labels (run op2gs-vote and op2gs-learn)");
  if (!checkpoint.model.has_instance_opacity)
    spdlog::warn("{} has no instance opacity: masks use sigma", o.model.string());
  const auto scene = Scene::load(scene_dir, o.scene);
  const std::vector<size_t> train = split_views(*scene, o.split).train;
  const RenderSettings settings = mask_settings(checkpoint, o);
  const ClipModel clip = ClipModel::load(clip_files);

  spdlog::info("embed: rendering object masks in {} training views", train.size());
  const auto chosen = choose_views(checkpoint.model, *scene, train, settings, o);

  // Crops, view by view, so that each chosen view is rendered once more.
  std::map<size_t, std::vector<std::pair<int32_t, size_t>>> by_view;  // view -> (object, slot)
  for (const auto& [id, list] : chosen)
    for (size_t k = 0; k < list.size(); ++k) by_view[list[k].view].push_back({id, k});
  ObjectEmbeddings result;
  result.clip_dir = o.clip_dir;
  std::map<int32_t, ObjectEmbedding> objects;
  std::vector<Crop> crops;
  const CpuRenderer renderer;
  RenderOutput r;
  for (const auto& [v, entries] : by_view) {
    const View& view = scene->views()[v];
    renderer.render(checkpoint.model, view.camera, settings, r);
    const std::shared_ptr<const ImageRGB> image = scene->image(v);
    const size_t pixels = size_t(r.width) * r.height;
    for (const auto& [id, slot] : entries) {
      const size_t plane =
          size_t(std::find(r.instance_map_labels.begin(), r.instance_map_labels.end(), id) -
                 r.instance_map_labels.begin());
      const float* S = &r.instance_maps[plane * pixels];
      std::vector<uint8_t> mask(pixels);
      for (size_t p = 0; p < pixels; ++p) mask[p] = S[p] > o.tau;
      const ImageRGB crop = masked_square_crop(*image, mask, o.margin, o.crop_background);
      const std::string file =
          fmt::format("crops/{}/{}.png", id, fs::path(view.name).stem().string());
      write_image_rgb(out / file, crop);
      ObjectEmbedding& obj = objects[id];
      obj.id = id;
      obj.views.resize(chosen.at(id).size());
      obj.views[slot] = {view.name, chosen.at(id)[slot].area, file};
      crops.push_back({id, slot, clip_preprocess(crop, clip.image_size())});
    }
  }

  spdlog::info("embed: CLIP on {} crops of {} objects", crops.size(), objects.size());
  std::vector<Eigen::VectorXf> features(crops.size());
  tbb::parallel_for(size_t(0), crops.size(), [&](size_t i) {
    features[i] = clip.encode_image(crops[i].pixels).normalized();
  });
  for (size_t i = 0; i < crops.size(); ++i) {
    Eigen::VectorXf& e = objects[crops[i].object].embedding;
    if (e.size() == 0) e = Eigen::VectorXf::Zero(features[i].size());
    e += features[i];
  }
  for (auto& [id, obj] : objects) {
    obj.embedding.normalize();
    result.objects.push_back(std::move(obj));
  }
  std::vector<int32_t> labels = o.objects;
  if (labels.empty()) {
    labels = checkpoint.model.labels;
    std::sort(labels.begin(), labels.end());
    labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
  }
  for (int32_t id : labels)
    if (id > 0 && !objects.count(id)) result.unseen.push_back(id);
  if (!result.unseen.empty())
    spdlog::warn("embed: no training view shows objects {} (mask under {} pixels)",
                 fmt::join(result.unseen, ", "), o.min_mask_pixels);
  write_text_atomically(out / "embeddings.json", to_json(result, o, o.model).dump() + "\n");
  return result;
}

}  // namespace splat
