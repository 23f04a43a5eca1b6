#include "eval/run/eval_run.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "eval/metrics/ovs.h"
#include "eval/metrics/photo_geometry.h"
#include "eval/metrics/predictions.h"
#include "splat/atomic_file.h"
#include "splat/colmap_model.h"
#include "splat/dataset_layout.h"
#include "splat/error.h"
#include "splat/image.h"
#include "splat/image_quality.h"
#include "splat/query/query_run.h"
#include "splat/sfm/alignment.h"

namespace eval {
namespace fs = std::filesystem;
using json = nlohmann::ordered_json;  // keys in the order written: predictions as given

void EvalRunOptions::Check() const {
  if (predictions.empty() && renders.empty() && poses.empty())
    throw std::invalid_argument("nothing to score: give predictions, renders or poses");
  std::set<std::string> names;
  for (const auto& p : predictions)
    if (!names.insert(p.name).second)
      throw std::invalid_argument("prediction name given twice: " + p.name);
}

namespace {
json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json score_json(const LerfMaskGroundTruth& gt, const SceneScore& s) {
  json queries = json::array();
  for (const QueryScore& q : s.queries) {
    json views = json::array();
    for (size_t i = 0; i < q.views.size(); ++i)
      views.push_back({{"k", q.views[i]},
                       {"view", gt.test_views[q.views[i]]},
                       {"iou", number(q.iou[i])},
                       {"biou", number(q.biou[i])}});
    queries.push_back({{"query", q.query},
                       {"object", q.object},
                       {"miou", number(q.mean_iou)},
                       {"mbiou", number(q.mean_biou)},
                       {"views", views}});
  }
  return {{"miou", number(s.miou)}, {"mbiou", number(s.mbiou)}, {"queries", queries}};
}
}  // namespace

namespace {

json ovs_json(const OvsGroundTruth& gt, const OvsScore& s) {
  json classes = json::array();
  for (size_t c = 0; c < gt.classes.size(); ++c) {
    json views = json::array();
    for (size_t i = 0; i < s.views.size(); ++i)
      views.push_back({{"view", gt.images[gt.views[i]]}, {"iou", s.views[i].iou[c]}});
    classes.push_back({{"class", gt.classes[c]}, {"object", s.objects[c]}, {"views", views}});
  }
  json accuracy = json::array();
  for (const auto& v : s.views) accuracy.push_back(v.accuracy);
  return {{"miou", s.miou},
          {"accuracy", s.accuracy},
          {"classes", classes},
          {"view_accuracy", accuracy}};
}

// PSNR and SSIM of every render in `renders` whose image is in the scene.
json image_quality(const fs::path& scene, const fs::path& renders, EvalRunResult& r) {
  json views = json::array();
  double psnr = 0, ssim = 0;
  std::vector<fs::path> files;
  for (const auto& f : fs::directory_iterator(renders))
    if (f.path().extension() == ".png") files.push_back(f.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& f : files) {
    fs::path truth;
    for (const char* ext : {".png", ".jpg", ".JPG", ".jpeg"})
      if (fs::exists(scene / "images" / (f.stem().string() + ext)))
        truth = scene / "images" / (f.stem().string() + ext);
    if (truth.empty()) continue;
    const splat::ImageRGB render = splat::read_image_rgb(f);
    splat::ImageRGB target = splat::read_image_rgb(truth);
    if (target.width != render.width || target.height != render.height)
      target = splat::resize_area(target, render.width, render.height);
    const double p = splat::psnr(render.data, target.data);
    const double s = splat::ssim(render.data, target.data, render.width, render.height);
    views.push_back({{"view", truth.filename().string()}, {"psnr", p}, {"ssim", s}});
    psnr += p, ssim += s;
  }
  if (views.empty()) throw splat::InputError(renders, "no render matches an image of the scene");
  r.psnr = psnr / double(views.size());
  r.ssim = ssim / double(views.size());
  return {{"psnr", r.psnr}, {"ssim", r.ssim}, {"views", views}};
}

Protocol protocol_of(const fs::path& scene, Protocol p) {
  if (p != Protocol::kAuto) return p;
  if (fs::is_directory(scene / "test_mask")) return Protocol::kLerfMask;
  if (fs::is_directory(scene / "segmentations")) return Protocol::kOvs;
  throw splat::InputError(scene, "no ground truth (neither test_mask/ nor segmentations/)");
}

constexpr char kTestClip[] =
    "the queries were answered with the tests' tiny random CLIP, which stands in when the real "
    "CLIP files are absent, so their choices mean nothing";
constexpr char kFetchClip[] =
    "scripts/get_clip.sh fetches CLIP ViT-B/16; then run op2gs-embed and op2gs-query again";

// The mask scoring of every set of predictions in every mode (oracle, and
// query when the query answers are given): the result rows and each mode's
// scores, for the LERF-Mask protocol or the 3DOVS metric.
class MaskScoring {
 public:
  MaskScoring(const fs::path& scene, const EvalRunOptions& o, EvalRunResult& r)
      : scene_(scene), o_(o), r_(r), photos_(scene) {
    modes_.push_back({"oracle", nullptr});
    if (o.query_results.empty()) {
      r.query_mode_unavailable = o.query_unavailable;
      return;
    }
    const splat::QueryResults answers = splat::read_query_results(o.query_results);
    if (!answers.full_size_clip) {
      r.query_mode_unavailable = kTestClip;
      return;
    }
    for (const splat::QueryAnswer& a : answers.answers) selected_[a.query] = a.object;
    modes_.push_back({"query", &selected_});
  }

  // Whether query mode is scored.
  bool query_mode() const { return modes_.size() > 1; }

  // LERF-Mask's script on test_mask/, or on the 3DOVS masks (on_ovs). Returns
  // the protocol's description for metrics.json.
  json score_lerf_mask(bool on_ovs) {
    TruthMasks truths(o_.truth_width);
    const LerfMaskGroundTruth gt = on_ovs
                                       ? lerf_mask_from_ovs(read_ovs_ground_truth(scene_), &truths)
                                       : read_lerf_mask_ground_truth(scene_);
    std::vector<fs::path> truth_files;
    for (const auto& view : gt.masks)
      for (const auto& [query, file] : view) truth_files.push_back(file);
    truths.prefetch(truth_files);
    for (const NamedPredictions& p : o_.predictions) {
      std::map<size_t, ObjectMasks> read;  // each view's predictions, read once for both modes
      const auto masks_of = [&](size_t k) {
        auto it = read.find(k);
        if (it == read.end()) {
          const std::string& view = gt.test_views[k];
          it = read.emplace(k, photos_.to_photo(view, read_view_predictions(p.folder, view))).first;
        }
        return it->second;
      };
      for (const auto& [mode, objects] : modes_) {
        const SceneScore s = objects
                                 ? score_selected(gt, *objects, masks_of, o_.truth_width, &truths)
                                 : score_oracle(gt, masks_of, o_.truth_width, &truths);
        add_row(p, mode, s.miou, s.mbiou, score_json(gt, s));
      }
    }
    json about = {{"protocol", on_ovs ? "lerf-mask script on 3dovs masks (IoU and boundary IoU)"
                                      : "lerf-mask (IoU and boundary IoU, dilation ratio 0.02)"},
                  {"truth_width", o_.truth_width},
                  {"test_views", gt.test_views}};
    if (!on_ovs && !gt.without_truth.empty()) {
      spdlog::warn(
          "{} of {} test views have no ground truth in test_mask/ and are not scored, as "
          "the reference script skips them: {}",
          gt.without_truth.size(), gt.test_views.size(), fmt::join(gt.without_truth, ", "));
      about["test_views_without_ground_truth"] = gt.without_truth;
    }
    return about;
  }

  // The 3DOVS reference metric on segmentations/.
  json score_ovs() {
    const OvsGroundTruth gt = read_ovs_ground_truth(scene_);
    std::vector<std::string> views;
    for (size_t v : gt.views) views.push_back(gt.images[v]);
    for (const NamedPredictions& p : o_.predictions)
      for (const auto& [mode, objects] : modes_) {
        const auto masks_of = [&](size_t i) {
          return photos_.to_photo(views[i], read_view_predictions(p.folder, views[i]));
        };
        const OvsScore s =
            objects ? score_ovs_selected(gt, *objects, masks_of) : score_ovs_oracle(gt, masks_of);
        add_row(p, mode, s.miou, s.accuracy, ovs_json(gt, s));
      }
    return {{"protocol", "3dovs reference (one-hot argmax, per-class IoU, pixel accuracy)"},
            {"test_views", views},
            {"classes", gt.classes}};
  }

  const PhotoGeometry& photos() const { return photos_; }
  const json& results() const { return results_; }
  const json& query_results() const { return query_results_; }

 private:
  void add_row(const NamedPredictions& p, const std::string& mode, double miou, double second,
               json scores) {
    r_.names.push_back(p.name);
    r_.modes.push_back(mode);
    r_.miou.push_back(miou);
    r_.second.push_back(second);
    scores["folder"] = p.folder.string();
    (mode == "oracle" ? results_ : query_results_)[p.name] = scores;
  }

  const fs::path& scene_;
  const EvalRunOptions& o_;
  EvalRunResult& r_;
  const PhotoGeometry photos_;
  QueryObjects selected_;
  std::vector<std::pair<std::string, const QueryObjects*>> modes_;
  json results_ = json::object(), query_results_ = json::object();
};

// The reconstruction's cameras against the true ones, after alignment.
json pose_accuracy_json(const EvalRunOptions& o, EvalRunResult& r) {
  const splat::PoseAccuracy acc = splat::pose_accuracy(splat::read_colmap_model(o.poses),
                                                       splat::read_colmap_model(o.true_poses));
  r.center_rmse = acc.center_rmse;
  r.rotation_error_deg = acc.rotation_error_deg;
  return {{"matched", acc.matched},
          {"center_rmse", acc.center_rmse},
          {"rotation_error_deg", acc.rotation_error_deg}};
}

}  // namespace

std::vector<std::string> benchmark_queries(const fs::path& scene) {
  if (protocol_of(scene, Protocol::kAuto) == Protocol::kLerfMask)
    return read_lerf_mask_ground_truth(scene).queries;
  return read_ovs_ground_truth(scene).classes;
}

EvalRunResult run_evaluation(const fs::path& scene, const fs::path& out, const EvalRunOptions& o) {
  o.Check();
  EvalRunResult r;
  MaskScoring scoring(scene, o, r);
  json metrics = json::object();
  if (!o.predictions.empty()) {
    r.protocol = protocol_of(scene, o.protocol);
    metrics = r.protocol == Protocol::kOvs
                  ? scoring.score_ovs()
                  : scoring.score_lerf_mask(r.protocol == Protocol::kOvsLerfMask);
  }
  if (!o.renders.empty()) metrics["image_quality"] = image_quality(scene, o.renders, r);
  if (!o.poses.empty()) metrics["pose_accuracy"] = pose_accuracy_json(o, r);
  metrics["scene"] = scene.string();
  const splat::DatasetLayout layout = splat::detect_dataset_layout(scene);
  metrics["layout"] = {{"name", splat::layout_name(layout)},
                       {"description", splat::layout_description(layout)}};
  if (!o.id_maps.empty())
    metrics["id_maps"] = {{"folder", splat::resolve_id_map_folder(scene, o.id_maps)}};
  metrics["mask_geometry"] =
      scoring.photos().active() ? "photos (renders resampled from the undistorted views)" : "views";
  metrics["modes"] = scoring.query_mode() ? json{"oracle", "query"} : json{"oracle"};
  if (!o.predictions.empty()) metrics["results"] = scoring.results();
  if (!o.query_results.empty()) metrics["queries_from"] = o.query_results.string();
  if (scoring.query_mode()) metrics["query_results"] = scoring.query_results();
  if (!r.query_mode_unavailable.empty())
    metrics["query_mode"] = {
        {"available", false}, {"reason", r.query_mode_unavailable}, {"fetch", kFetchClip}};
  splat::write_text_atomically(out, metrics.dump(2) + "\n");
  return r;
}

}  // namespace eval
