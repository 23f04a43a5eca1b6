#pragma once
// The LERF-Mask benchmark layout and its scoring (docs/evaluation.md):
// test views are the images of images/ that are not in images_train/, sorted
// by name; test_mask/<k>/<query>.png is the ground truth of query <query> in
// the k-th test view (some k may be missing).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "eval/metrics/mask_metrics.h"

namespace eval {

struct LerfMaskGroundTruth {
  std::vector<std::string> test_views;  // image names, sorted; index k
  std::vector<std::string> queries;     // sorted names (file stems)
  // masks[k][query] = file, for the pairs that exist.
  std::vector<std::map<std::string, std::filesystem::path>> masks;
  // Test views with no test_mask/<k>/ masks (teatime's view 1 as
  // downloaded): skipped, as the reference script skips missing files.
  std::vector<std::string> without_truth;
};

// Reads the layout of a scene folder. Throws splat::InputError when there is
// no test_mask/ folder or a folder in it is not a test view index.
LerfMaskGroundTruth read_lerf_mask_ground_truth(const std::filesystem::path& scene);

struct QueryScore {
  std::string query;
  int32_t object = -1;        // the object ID whose masks were scored
  std::vector<size_t> views;  // k of the scored views
  std::vector<double> iou, biou;
  double mean_iou = 0, mean_biou = 0;  // NaN if any view's union was empty
};

struct SceneScore {
  std::vector<QueryScore> queries;
  double miou = 0, mbiou = 0;  // mean over queries, in [0, 1]
};

// Predicted object masks of one test view, by object ID.
using ObjectMasks = std::map<int32_t, Mask>;

// Ground-truth masks read (and resized to truth_width) once, however many
// prediction folders and modes are scored against them.
class TruthMasks {
 public:
  explicit TruthMasks(int truth_width = 0) : truth_width_(truth_width) {}
  const Mask& get(const std::filesystem::path& file);
  // Reads these files now, in parallel.
  void prefetch(const std::vector<std::filesystem::path>& files);
  // Its boundary for the boundary IoU (dilation ratio 0.02).
  const Mask& boundary(const std::filesystem::path& file);

 private:
  struct Entry {
    Mask mask, boundary;
    bool has_boundary = false;
  };
  Entry& entry(const std::filesystem::path& file);
  int truth_width_;
  std::map<std::filesystem::path, Entry> masks_;
};

// Oracle mode: for each query, the object whose mask has the highest IoU on
// the first test view where the query has ground truth (ties: smaller ID);
// that object's masks are scored on every view with ground truth. masks_of(k)
// gives the predictions of test view k (any size: resized to the ground
// truth's with the nearest-neighbour rule). An object missing from a view's
// predictions has an empty mask there.
// truth_width > 0 first resizes each ground-truth mask (nearest neighbour) to
// that width, keeping its aspect ratio: the downsampled evaluation the 3DGS
// papers run on 3DOVS masks (ObjectGS: 1440 x 1080).
// truths, when given, keeps the ground truth read for later calls (its
// truth width is used).
SceneScore score_oracle(const LerfMaskGroundTruth& gt,
                        const std::function<ObjectMasks(size_t k)>& masks_of, int truth_width = 0,
                        TruthMasks* truths = nullptr);

// Query mode: each query's object is given (by text retrieval); its masks are
// scored as in oracle mode. Throws std::invalid_argument for a query of the
// ground truth that has no object.
using QueryObjects = std::map<std::string, int32_t>;
SceneScore score_selected(const LerfMaskGroundTruth& gt, const QueryObjects& objects,
                          const std::function<ObjectMasks(size_t k)>& masks_of, int truth_width = 0,
                          TruthMasks* truths = nullptr);

// The 3DOVS layout as LERF-Mask ground truth: the segmented views as test
// views, the classes as queries, one binary mask per (view, class) where the
// class is present (empty masks are left out: the script would score them NaN).
struct OvsGroundTruth;
// truths, when given, keeps the masks it reads (the emptiness test reads them
// at its truth width).
LerfMaskGroundTruth lerf_mask_from_ovs(const OvsGroundTruth& ovs, TruthMasks* truths = nullptr);

// Masks of every label of a label map (label 0 is background, not an object).
ObjectMasks masks_from_label_map(const std::vector<int32_t>& labels, int width, int height);

}  // namespace eval
