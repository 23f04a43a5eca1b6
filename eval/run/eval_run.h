#pragma once
// op2gs-eval's run: scores prediction folders of a scene in oracle mode with
// the LERF-Mask protocol (test_mask/) or the 3DOVS reference metric
// (segmentations/), and writes every per-view figure to metrics.json.

#include <filesystem>
#include <string>
#include <vector>

#include "eval/metrics/lerf_mask.h"

namespace eval {

struct NamedPredictions {
  std::string name;  // "baseline", "dual-opacity", ...
  std::filesystem::path folder;
};

// kOvsLerfMask: the LERF-Mask script on 3DOVS masks, as the 3DGS papers
// (and the OP2GS paper's 3DOVS table) report it.
enum class Protocol { kAuto, kLerfMask, kOvs, kOvsLerfMask };

struct EvalRunOptions {
  std::vector<NamedPredictions> predictions;
  Protocol protocol = Protocol::kAuto;  // auto: from the scene's layout
  int truth_width = 0;  // LERF-Mask scoring at this ground-truth width (0: as stored)
  void Check() const;   // throws std::invalid_argument
};

struct EvalRunResult {
  Protocol protocol = Protocol::kLerfMask;
  std::vector<std::string> names;
  // Per prediction folder, in [0, 1]: mIoU, and mBIoU (LERF-Mask scoring) or
  // pixel accuracy (the 3DOVS reference metric).
  std::vector<double> miou, second;
};

// Scores every prediction folder; writes metrics.json (atomically) to `out`.
EvalRunResult run_evaluation(const std::filesystem::path& scene, const std::filesystem::path& out,
                             const EvalRunOptions& options);

}  // namespace eval
