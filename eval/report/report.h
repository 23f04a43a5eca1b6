#pragma once
// op2gs-report: one self-contained HTML file (images embedded) and a Markdown
// summary, for one scene or a whole dataset run, from op2gs-eval's
// metrics.json files:
//   - the dataset table in the layout of the paper's tables (per scene mIoU /
//     mBIoU, mean), with the paper's published figures beside ours when the
//     dataset is one of the paper's, and the paper's ablation layout
//     (baseline / dual opacity, oracle / query);
//   - per scene: the per-query rows (object chosen, mIoU, mBIoU, per view);
//   - figures: per test view and query, the photo, the ground truth, and each
//     prediction's mask coloured by error (green: right, red: predicted but
//     not true, blue: true but missed); the instance label map; the training
//     curves;
//   - for synthetic scenes measured by op2gs-floaters: floaters and wrongly
//     labelled Gaussians, and their share of the picture and of the masks.

#include <filesystem>
#include <string>
#include <vector>

namespace eval {

struct SceneReportInput {
  std::string name;
  std::filesystem::path scene;    // the scene folder (photos and ground truth)
  std::filesystem::path metrics;  // metrics.json of op2gs-eval
  // Optional: op2gs-render's folder (instance_labels_color/), training curve
  // PNGs, op2gs-query's query.json (the similarity table).
  std::filesystem::path render;
  std::vector<std::filesystem::path> curves;
  std::filesystem::path queries;
  // Optional: the 3D viewer's inputs (viewer.h): the scene folder the stages
  // read (cameras), stage two's model, and the same model's PLY.
  std::filesystem::path viewer_scene = {}, model = {}, model_ply = {};
  // Optional: stage two's metrics.json (the colour-fitted test PSNR) and
  // op2gs-floaters' report (synthetic scenes: floaters and contamination).
  std::filesystem::path training_metrics = {}, floaters = {};
};

struct ReportOptions {
  std::string title = "op2gs report";
  std::string dataset;  // "lerf-mask", "3dovs", other; empty: from the scene names
  std::vector<SceneReportInput> scenes;
  int thumbnail_width = 320;  // figure panels, pixels
  bool figures = true;
  bool viewer = true;  // a 3D viewer per scene with a model (viewer.h)
  void Check() const;  // throws std::invalid_argument
};

struct ReportFiles {
  std::filesystem::path html, markdown;
};

// Writes report.html and report.md into out (atomically), and out/viewer/.
ReportFiles write_report(const std::filesystem::path& out, const ReportOptions& options);

}  // namespace eval
