// op2gs-report: an HTML report (self-contained) and a Markdown summary of one
// scene or a dataset run, from the scenes' op2gs-eval metrics.

#include <array>

#include "eval/report/report.h"
#include "eval/report/viewer.h"
#include "stages/common.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{"Write the HTML and Markdown report of evaluated scenes."};
  eval::ReportOptions o;
  // One NAME SCENE_DIR WORK_DIR triple per --scene; an array type makes CLI11
  // take each occurrence as three values and accept the option repeated.
  std::vector<std::array<std::string, 3>> scenes;
  std::string out, metrics = "eval/metrics.json";
  bool no_figures = false, no_viewer = false;
  app.add_option("--scene", scenes,
                 "NAME SCENE_DIR WORK_DIR (repeatable): reads WORK_DIR/eval/metrics.json, "
                 "render/, query/query.json, the training curves")
      ->required();
  app.add_option("--out", out, "output folder (report.html, report.md)")->required();
  app.add_option("--title", o.title, "report title")->capture_default_str();
  app.add_option("--dataset", o.dataset,
                 "lerf-mask or 3dovs: the paper's figures beside ours (default: from the scene "
                 "names)");
  app.add_option("--metrics", metrics, "metrics file inside each work folder")
      ->capture_default_str();
  app.add_option("--thumbnail-width", o.thumbnail_width, "figure width in pixels")
      ->capture_default_str();
  app.add_flag("--no-figures", no_figures, "tables only");
  app.add_flag("--no-viewer", no_viewer, "no 3D viewer (viewer/) of the scenes' models");
  return stages::run_stage(app, argc, argv, [&] {
    o.figures = !no_figures;
    o.viewer = !no_viewer;
    for (const auto& [name, scene, work_dir] : scenes) {
      const splat::WorkLayout work{work_dir};
      eval::SceneReportInput s;
      s.name = name;
      s.scene = scene;
      s.metrics = work.root / metrics;
      s.render = work.render();
      s.curves = {work.stage_one().curve(), work.stage_two().curve()};
      s.queries = work.query_results();
      s.training_metrics = work.stage_two().metrics();
      s.floaters = work.root / "floaters.json";
      if (fs::exists(work.sfm_scene())) s.viewer_scene = work.sfm_scene();
      if (fs::exists(work.stage_two().latest_checkpoint())) {
        s.model = work.stage_two().latest_checkpoint();
        s.model_ply = eval::latest_point_cloud(work.stage_two().point_clouds());
      }
      o.scenes.push_back(s);
    }
    splat::StagedFolder outputs(out, splat::StagedFolder::Target::kShared);
    const eval::ReportFiles f = eval::write_report(outputs.path(), o);
    outputs.commit();
    spdlog::info("report: {} and {}", (outputs.target() / f.html.filename()).string(),
                 (outputs.target() / f.markdown.filename()).string());
  });
}
