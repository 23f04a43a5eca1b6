#include "eval/metrics/lerf_mask.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "eval/metrics/ovs.h"
#include "splat/error.h"

namespace eval {
namespace fs = std::filesystem;

LerfMaskGroundTruth read_lerf_mask_ground_truth(const fs::path& scene) {
  const fs::path masks = scene / "test_mask";
  if (!fs::is_directory(masks)) throw splat::InputError(masks, "no test_mask/ folder");
  LerfMaskGroundTruth gt;
  std::set<std::string> train;
  if (fs::is_directory(scene / "images_train"))
    for (const auto& f : fs::directory_iterator(scene / "images_train"))
      train.insert(f.path().filename().string());
  for (const auto& f : fs::directory_iterator(scene / "images"))
    if (f.is_regular_file() && !train.count(f.path().filename().string()))
      gt.test_views.push_back(f.path().filename().string());
  std::sort(gt.test_views.begin(), gt.test_views.end());
  gt.masks.resize(gt.test_views.size());
  std::set<std::string> queries;
  for (const auto& dir : fs::directory_iterator(masks)) {
    if (!dir.is_directory()) continue;
    const std::string name = dir.path().filename().string();
    size_t k = 0;
    try {
      size_t used = 0;
      k = std::stoul(name, &used);
      if (used != name.size()) throw std::invalid_argument(name);
    } catch (const std::exception&) {
      throw splat::InputError(dir.path(), "test_mask/ folders must be test view indices");
    }
    if (k >= gt.test_views.size())
      throw splat::InputError(dir.path(), "no test view with this index (the scene has " +
                                              std::to_string(gt.test_views.size()) + ")");
    for (const auto& f : fs::directory_iterator(dir.path())) {
      if (f.path().extension() != ".png") continue;
      const std::string query = f.path().stem().string();
      gt.masks[k][query] = f.path();
      queries.insert(query);
    }
  }
  gt.queries.assign(queries.begin(), queries.end());
  for (size_t k = 0; k < gt.masks.size(); ++k)
    if (gt.masks[k].empty()) gt.without_truth.push_back(gt.test_views[k]);
  return gt;
}

ObjectMasks masks_from_label_map(const std::vector<int32_t>& labels, int width, int height) {
  ObjectMasks masks;
  for (size_t p = 0; p < labels.size(); ++p) {
    if (labels[p] <= 0) continue;
    auto it = masks.find(labels[p]);
    if (it == masks.end()) it = masks.emplace(labels[p], Mask(width, height)).first;
    it->second.on[p] = 1;
  }
  return masks;
}

namespace {

Mask read_truth(const fs::path& file, int truth_width) {
  Mask truth = read_mask(file);
  if (truth_width > 0 && truth.width != truth_width)
    truth = resize_mask_nearest(
        truth, truth_width,
        std::max(1, int(std::lround(double(truth.height) * truth_width / truth.width))));
  return truth;
}

}  // namespace

TruthMasks::Entry& TruthMasks::entry(const fs::path& file) {
  auto it = masks_.find(file);
  if (it != masks_.end()) return it->second;
  return masks_.emplace(file, Entry{read_truth(file, truth_width_), {}, false}).first->second;
}

void TruthMasks::prefetch(const std::vector<fs::path>& files) {
  std::vector<fs::path> missing;
  for (const fs::path& f : files)
    if (!masks_.count(f)) missing.push_back(f);
  std::vector<Mask> decoded(missing.size());
  tbb::parallel_for(size_t(0), missing.size(),
                    [&](size_t i) { decoded[i] = read_truth(missing[i], truth_width_); });
  for (size_t i = 0; i < missing.size(); ++i)
    masks_.emplace(missing[i], Entry{std::move(decoded[i]), {}, false});
}

const Mask& TruthMasks::get(const fs::path& file) { return entry(file).mask; }

const Mask& TruthMasks::boundary(const fs::path& file) {
  Entry& e = entry(file);
  if (!e.has_boundary) {
    e.boundary = mask_boundary(e.mask, boundary_width(e.mask.width, e.mask.height));
    e.has_boundary = true;
  }
  return e.boundary;
}

namespace {

// Scores every query with the object choose() picks on the first view where
// the query has ground truth.
using ChooseObject =
    std::function<int32_t(const std::string& query, const ObjectMasks& predicted,
                          const std::function<Mask(int32_t id)>& mask_of, const Mask& truth)>;

SceneScore score_queries(const LerfMaskGroundTruth& gt,
                         const std::function<ObjectMasks(size_t k)>& masks_of, int truth_width,
                         TruthMasks* truths, const ChooseObject& choose) {
  TruthMasks local(truth_width);
  TruthMasks& truth_masks = truths ? *truths : local;
  std::map<size_t, ObjectMasks> predictions;  // loaded once per view
  auto predicted = [&](size_t k) -> const ObjectMasks& {
    auto it = predictions.find(k);
    if (it == predictions.end()) it = predictions.emplace(k, masks_of(k)).first;
    return it->second;
  };
  auto object_mask = [&](size_t k, int32_t id, int w, int h) {
    const ObjectMasks& m = predicted(k);
    const auto it = m.find(id);
    return it == m.end() ? Mask(w, h) : resize_mask_nearest(it->second, w, h);
  };
  SceneScore scene;
  for (const std::string& query : gt.queries) {
    QueryScore q;
    q.query = query;
    for (size_t k = 0; k < gt.masks.size(); ++k) {
      const auto f = gt.masks[k].find(query);
      if (f == gt.masks[k].end()) continue;
      const Mask& truth = truth_masks.get(f->second);
      if (q.object < 0)
        q.object = choose(
            query, predicted(k),
            [&](int32_t id) { return object_mask(k, id, truth.width, truth.height); }, truth);
      const Mask pred = object_mask(k, q.object, truth.width, truth.height);
      q.views.push_back(k);
      q.iou.push_back(mask_iou(truth, pred));
      q.biou.push_back(mask_iou(truth_masks.boundary(f->second),
                                mask_boundary(pred, boundary_width(pred.width, pred.height))));
    }
    if (q.views.empty()) continue;
    for (size_t i = 0; i < q.views.size(); ++i) q.mean_iou += q.iou[i], q.mean_biou += q.biou[i];
    q.mean_iou /= double(q.views.size());
    q.mean_biou /= double(q.views.size());
    scene.miou += q.mean_iou;
    scene.mbiou += q.mean_biou;
    scene.queries.push_back(q);
  }
  const double n = double(scene.queries.size());
  scene.miou = n ? scene.miou / n : std::numeric_limits<double>::quiet_NaN();
  scene.mbiou = n ? scene.mbiou / n : std::numeric_limits<double>::quiet_NaN();
  return scene;
}

}  // namespace

SceneScore score_oracle(const LerfMaskGroundTruth& gt,
                        const std::function<ObjectMasks(size_t k)>& masks_of, int truth_width,
                        TruthMasks* truths) {
  return score_queries(gt, masks_of, truth_width, truths,
                       [](const std::string&, const ObjectMasks& predicted,
                          const std::function<Mask(int32_t)>& mask_of, const Mask& truth) {
                         int32_t object = 0;  // nothing predicted at all: no object
                         double best = -1;
                         for (const auto& [id, _] : predicted) {
                           const double iou = mask_iou(truth, mask_of(id));
                           if (iou > best) best = iou, object = id;
                         }
                         return object;
                       });
}

SceneScore score_selected(const LerfMaskGroundTruth& gt, const QueryObjects& objects,
                          const std::function<ObjectMasks(size_t k)>& masks_of, int truth_width,
                          TruthMasks* truths) {
  return score_queries(gt, masks_of, truth_width, truths,
                       [&](const std::string& query, const ObjectMasks&,
                           const std::function<Mask(int32_t)>&, const Mask&) {
                         const auto it = objects.find(query);
                         if (it == objects.end())
                           throw std::invalid_argument("no object selected for query " + query);
                         return it->second;
                       });
}

LerfMaskGroundTruth lerf_mask_from_ovs(const OvsGroundTruth& ovs, TruthMasks* truths) {
  TruthMasks local;
  TruthMasks& truth_masks = truths ? *truths : local;
  std::vector<fs::path> files;
  for (const auto& view : ovs.masks)
    for (const fs::path& f : view)
      if (!f.empty()) files.push_back(f);
  truth_masks.prefetch(files);
  LerfMaskGroundTruth gt;
  gt.queries = ovs.classes;
  for (size_t i = 0; i < ovs.views.size(); ++i) {
    gt.test_views.push_back(ovs.images[ovs.views[i]]);
    std::map<std::string, fs::path> masks;
    for (size_t c = 0; c < ovs.classes.size(); ++c) {
      // A class absent from a view (an empty mask) is not a pair to score:
      // the LERF-Mask script would give it NaN and poison every mean.
      if (ovs.masks[i][c].empty() || truth_masks.get(ovs.masks[i][c]).count() == 0) continue;
      masks[ovs.classes[c]] = ovs.masks[i][c];
    }
    gt.masks.push_back(masks);
  }
  return gt;
}

}  // namespace eval
