#include "eval/metrics/ovs.h"

#include <algorithm>
#include <fstream>
#include <stdexcept>

#include "splat/dataset_layout.h"
#include "splat/error.h"
#include "splat/id_maps.h"

namespace eval {
namespace fs = std::filesystem;

OvsGroundTruth read_ovs_ground_truth(const fs::path& scene) {
  const fs::path seg = scene / "segmentations", list = seg / "classes.txt";
  std::ifstream in(list);
  if (!in) throw splat::InputError(list, "no class list (3DOVS layout)");
  OvsGroundTruth gt;
  for (std::string line; std::getline(in, line);) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (!line.empty()) gt.classes.push_back(line);
  }
  if (gt.classes.empty()) throw splat::InputError(list, "no classes");
  std::sort(gt.classes.begin(), gt.classes.end());
  gt.images = splat::sorted_image_names(scene);
  for (const splat::SegmentedView& v : splat::segmented_views(scene)) {
    gt.views.push_back(v.index);
    std::vector<fs::path> masks;
    for (const std::string& c : gt.classes) {
      const fs::path f = v.masks / (c + ".png");
      masks.push_back(fs::exists(f) ? f : fs::path());
    }
    gt.masks.push_back(masks);
  }
  return gt;
}

Mask read_ovs_mask(const fs::path& file, int width, int height) {
  if (file.empty()) return Mask(width, height);
  const splat::IdMap grey = read_grey_like_pillow(file);
  const splat::IdMap r = splat::resize_id_map_nearest(grey, width, height);
  Mask m(width, height);
  for (size_t p = 0; p < m.on.size(); ++p) m.on[p] = r.ids[p] == 255;
  return m;
}

OvsViewScore score_ovs_view(const std::vector<Mask>& truth,
                            const std::vector<std::vector<float>>& scores, int width, int height) {
  const size_t classes = truth.size(), pixels = size_t(width) * height;
  if (scores.size() != classes) throw std::invalid_argument("one score map per class");
  std::vector<uint16_t> predicted(pixels, 0);  // argmax; the first class on ties, as numpy
  for (size_t p = 0; p < pixels; ++p) {
    float best = scores[0][p];
    for (size_t c = 1; c < classes; ++c)
      if (scores[c][p] > best) best = scores[c][p], predicted[p] = uint16_t(c);
  }
  OvsViewScore s;
  for (size_t c = 0; c < classes; ++c) {
    size_t inter = 0, uni = 0;
    for (size_t p = 0; p < pixels; ++p) {
      const bool pred = predicted[p] == c, gt = truth[c].on[p];
      inter += pred && gt;
      uni += pred || gt;
    }
    s.iou.push_back(uni ? double(inter) / double(uni) : 0.0);
  }
  size_t right = 0;
  for (size_t p = 0; p < pixels; ++p) {
    bool row_matches = true;  // the ground-truth row must be exactly one-hot at `predicted`
    for (size_t c = 0; c < classes; ++c) row_matches &= bool(truth[c].on[p]) == (predicted[p] == c);
    right += row_matches;
  }
  s.accuracy = double(right) / double(pixels);
  return s;
}

namespace {

// Scores every class with the object choose(c, predicted, truth) picks on the
// first view where the class has ground truth.
using ChooseClassObject =
    std::function<int32_t(size_t c, const ObjectMasks& predicted, const Mask& truth)>;

OvsScore score_ovs_classes(const OvsGroundTruth& gt,
                           const std::function<ObjectMasks(size_t i)>& masks_of,
                           const ChooseClassObject& choose) {
  const size_t classes = gt.classes.size();
  OvsScore score;
  score.objects.assign(classes, -1);
  double iou_sum = 0;
  size_t pairs = 0;
  for (size_t i = 0; i < gt.views.size(); ++i) {
    const ObjectMasks predicted = masks_of(i);
    if (predicted.empty()) throw std::invalid_argument("no predicted masks for a view");
    const int W = predicted.begin()->second.width, H = predicted.begin()->second.height;
    std::vector<Mask> truth;
    for (size_t c = 0; c < classes; ++c) truth.push_back(read_ovs_mask(gt.masks[i][c], W, H));
    std::vector<std::vector<float>> scores(classes, std::vector<float>(size_t(W) * H, 0.f));
    for (size_t c = 0; c < classes; ++c) {
      if (score.objects[c] < 0 && truth[c].count() > 0)
        score.objects[c] = choose(c, predicted, truth[c]);
      const auto it = predicted.find(score.objects[c]);
      if (it == predicted.end()) continue;
      for (size_t p = 0; p < scores[c].size(); ++p) scores[c][p] = it->second.on[p];
    }
    score.views.push_back(score_ovs_view(truth, scores, W, H));
    for (double v : score.views.back().iou) iou_sum += v, ++pairs;
    score.accuracy += score.views.back().accuracy;
  }
  score.miou = pairs ? iou_sum / double(pairs) : 0;
  score.accuracy = score.views.empty() ? 0 : score.accuracy / double(score.views.size());
  return score;
}

}  // namespace

OvsScore score_ovs_oracle(const OvsGroundTruth& gt,
                          const std::function<ObjectMasks(size_t i)>& masks_of) {
  return score_ovs_classes(gt, masks_of,
                           [](size_t, const ObjectMasks& predicted, const Mask& truth) {
                             int32_t object = -1;
                             double best = -1;
                             for (const auto& [id, mask] : predicted) {
                               const double iou = mask_iou(truth, mask);
                               if (iou > best) best = iou, object = id;
                             }
                             return object;
                           });
}

OvsScore score_ovs_selected(const OvsGroundTruth& gt, const QueryObjects& objects,
                            const std::function<ObjectMasks(size_t i)>& masks_of) {
  return score_ovs_classes(gt, masks_of, [&](size_t c, const ObjectMasks&, const Mask&) {
    const auto it = objects.find(gt.classes[c]);
    if (it == objects.end())
      throw std::invalid_argument("no object selected for class " + gt.classes[c]);
    return it->second;
  });
}

}  // namespace eval
