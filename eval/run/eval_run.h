#pragma once
// op2gs-eval's run: scores prediction folders of a scene with the LERF-Mask
// protocol (oracle mode) and writes every per-view figure to metrics.json.

#include <filesystem>
#include <string>
#include <vector>

#include "eval/metrics/lerf_mask.h"

namespace eval {

struct NamedPredictions {
  std::string name;  // "baseline", "dual-opacity", ...
  std::filesystem::path folder;
};

struct EvalRunOptions {
  std::vector<NamedPredictions> predictions;
  void Check() const;  // throws std::invalid_argument
};

struct EvalRunResult {
  std::vector<std::string> names;
  std::vector<SceneScore> scores;  // one per prediction folder
};

// Scores every prediction folder; writes metrics.json (atomically) to `out`.
EvalRunResult run_evaluation(const std::filesystem::path& scene, const std::filesystem::path& out,
                             const EvalRunOptions& options);

}  // namespace eval
