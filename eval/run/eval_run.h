#pragma once
// op2gs-eval's run: scores prediction folders of a scene with the LERF-Mask
// protocol (test_mask/) or the 3DOVS reference metric (segmentations/), in
// oracle mode and, given op2gs-query's answers, in query mode, and writes
// every per-view figure to metrics.json.

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
  // Image quality: rendered test views (<stem>.png) against the scene's
  // images/ (area-resized to the renders' size), PSNR and SSIM.
  std::filesystem::path renders;
  // Pose accuracy: a reconstruction against the true cameras (COLMAP models),
  // after a similarity alignment.
  std::filesystem::path poses, true_poses;
  // Query mode as well: query.json of op2gs-query, whose answers name the
  // object of each query (class).
  std::filesystem::path query_results;
  // Without query results: why query mode could not run (a dataset run
  // without the CLIP files), to be reported as n/a with that reason.
  std::string query_unavailable;
  // The ID map folder the run voted and learned from ("auto" resolves as the
  // stages resolve it), recorded in metrics.json so that the report sets the
  // paper's figures of the same pseudo-labels beside it; empty: not recorded.
  std::string id_maps;
  void Check() const;  // throws std::invalid_argument
};

struct EvalRunResult {
  Protocol protocol = Protocol::kLerfMask;
  // One row per (prediction folder, mode), in the order scored.
  std::vector<std::string> names;
  std::vector<std::string> modes;  // "oracle" or "query"
  // Per prediction folder, in [0, 1]: mIoU, and mBIoU (LERF-Mask scoring) or
  // pixel accuracy (the 3DOVS reference metric).
  std::vector<double> miou, second;
  double psnr = -1, ssim = -1;  // -1 without renders
  // Not empty when query mode was asked for but not scored, and why: the
  // answers came from the tests' tiny CLIP (QueryResults::full_size_clip).
  std::string query_mode_unavailable;
  double center_rmse = -1;  // -1 without poses
  double rotation_error_deg = -1;
};

// The queries of a benchmark scene: the LERF-Mask query names (test_mask/),
// or the 3DOVS classes (segmentations/classes.txt).
std::vector<std::string> benchmark_queries(const std::filesystem::path& scene);

// Scores every prediction folder; writes metrics.json (atomically) to `out`.
EvalRunResult run_evaluation(const std::filesystem::path& scene, const std::filesystem::path& out,
                             const EvalRunOptions& options);

}  // namespace eval
