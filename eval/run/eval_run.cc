#include "eval/run/eval_run.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "eval/metrics/predictions.h"
#include "splat/atomic_file.h"

namespace eval {
namespace fs = std::filesystem;
using json = nlohmann::json;

void EvalRunOptions::Check() const {
  if (predictions.empty()) throw std::invalid_argument("no predictions to score");
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

EvalRunResult run_evaluation(const fs::path& scene, const fs::path& out, const EvalRunOptions& o) {
  o.Check();
  const LerfMaskGroundTruth gt = read_lerf_mask_ground_truth(scene);
  EvalRunResult r;
  json results = json::object();
  for (const NamedPredictions& p : o.predictions) {
    const SceneScore s = score_oracle(
        gt, [&](size_t k) { return read_view_predictions(p.folder, gt.test_views[k]); });
    r.names.push_back(p.name);
    r.scores.push_back(s);
    json j = score_json(gt, s);
    j["folder"] = p.folder.string();
    results[p.name] = j;
  }
  const json metrics = {{"scene", scene.string()},
                        {"protocol", "lerf-mask (IoU and boundary IoU, dilation ratio 0.02)"},
                        {"mode", "oracle"},
                        {"test_views", gt.test_views},
                        {"results", results}};
  splat::write_text_atomically(out, metrics.dump(2) + "\n");
  return r;
}

}  // namespace eval
