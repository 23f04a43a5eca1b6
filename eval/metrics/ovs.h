#pragma once
// The 3DOVS metric as its reference computes it (docs/evaluation.md):
// classes sorted alphabetically; per test view, the prediction is a one-hot
// class map (each pixel gets the argmax class of the predicted scores, so
// every pixel gets some class); IoU per class over all pixels (an empty union
// scores 0); mIoU is the mean over all (view, class) pairs; a pixel is right
// for the accuracy only if its whole one-hot row matches the ground truth's
// (pixels without a ground-truth class are always wrong).

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "eval/metrics/lerf_mask.h"
#include "eval/metrics/mask_metrics.h"

namespace eval {

struct OvsGroundTruth {
  std::vector<std::string> classes;  // sorted
  std::vector<std::string> images;   // the scene's images, sorted
  // views[i] = index into images of the i-th evaluated view (the folder
  // name under segmentations/), masks[i][c] the file of class c or empty.
  std::vector<size_t> views;
  std::vector<std::vector<std::filesystem::path>> masks;
};

// Reads <scene>/segmentations/classes.txt and <scene>/segmentations/<NN>/.
// Throws splat::InputError naming the file for a missing or malformed layout.
OvsGroundTruth read_ovs_ground_truth(const std::filesystem::path& scene);

// Ground truth of one class as the reference reads it: grey, nearest-resized
// to width x height, foreground where the value is exactly 255. A missing
// file is an empty mask.
Mask read_ovs_mask(const std::filesystem::path& file, int width, int height);

struct OvsViewScore {
  std::vector<double> iou;  // per class
  double accuracy = 0;
};

// scores[c] is class c's predicted score per pixel (width * height), e.g.
// the occupancy S_j of the object chosen for it.
OvsViewScore score_ovs_view(const std::vector<Mask>& truth,
                            const std::vector<std::vector<float>>& scores, int width, int height);

struct OvsScore {
  std::vector<int32_t> objects;     // per class: the object whose masks were scored (-1: none)
  std::vector<OvsViewScore> views;  // per evaluated view
  double miou = 0;                  // mean over (view, class) pairs, in [0, 1]
  double accuracy = 0;              // mean over views
};

// Oracle mode: each class takes the object whose predicted mask has the
// highest IoU on the first evaluated view where the class has ground truth;
// that object's mask (1 inside, 0 outside) is the class's score. masks_of(i)
// gives the predictions of the i-th evaluated view; the ground truth is
// resized to their size.
OvsScore score_ovs_oracle(const OvsGroundTruth& gt,
                          const std::function<ObjectMasks(size_t i)>& masks_of);

// Query mode: each class's object is given (by text retrieval). Throws
// std::invalid_argument for a class without one.
OvsScore score_ovs_selected(const OvsGroundTruth& gt, const QueryObjects& objects,
                            const std::function<ObjectMasks(size_t i)>& masks_of);

}  // namespace eval
