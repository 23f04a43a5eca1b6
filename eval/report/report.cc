#include "eval/report/report.h"

#include <fmt/format.h>

#include <set>

#include "eval/report/document.h"
#include "eval/report/figures.h"
#include "eval/report/html.h"
#include "eval/report/paper_numbers.h"
#include "eval/report/scene_data.h"
#include "eval/report/tables.h"
#include "eval/report/viewer.h"
#include "splat/atomic_file.h"

namespace eval {
namespace fs = std::filesystem;

void ReportOptions::Check() const {
  if (scenes.empty()) throw std::invalid_argument("no scenes to report");
  if (thumbnail_width < 32) throw std::invalid_argument("thumbnail width must be at least 32");
  std::set<std::string> names;
  for (const SceneReportInput& s : scenes)
    if (!names.insert(s.name).second) throw std::invalid_argument("scene named twice: " + s.name);
}

namespace {

// Writes the scene's 3D viewer into out/viewer/ and links it.
void add_viewer(const fs::path& out, const SceneReportInput& in, ReportDocument& doc) {
  const fs::path page =
      write_viewer(out / "viewer", {.name = in.name,
                                    .scene = in.viewer_scene.empty() ? in.scene : in.viewer_scene,
                                    .model = in.model,
                                    .model_ply = in.model_ply,
                                    .metrics = in.metrics,
                                    .queries = in.queries});
  const std::string serve = fmt::format(
      "python3 -m http.server 8000 in the report's folder, then open http://localhost:8000/{}",
      page.parent_path().generic_string() + "/");
  doc.link("3D viewer: ", page.generic_string(), page.generic_string(),
           " (browsers load it from a local server: " + serve + ")");
}

// One scene's section: its notes, image quality, viewer, tables and figures.
void add_scene(const fs::path& out, const SceneData& s, const ReportOptions& o,
               ReportDocument& doc) {
  doc.heading(2, s.input.name);
  if (const std::string note = scene_notes(s); !note.empty()) doc.paragraph(note);
  if (s.metrics.contains("image_quality"))
    doc.paragraph(fmt::format("Test views: PSNR {:.2f} dB, SSIM {:.4f}",
                              s.metrics["image_quality"]["psnr"].get<double>(),
                              s.metrics["image_quality"]["ssim"].get<double>()));
  if (const std::string fitted = fitted_psnr_note(s.input); !fitted.empty()) doc.paragraph(fitted);
  if (const std::string loss = object_loss_note(s.input); !loss.empty()) doc.paragraph(loss);
  if (o.viewer && !s.input.model.empty()) add_viewer(out, s.input, doc);
  for (const Table& t : floater_tables(s.input)) doc.table(t);
  doc.table(query_table(s));
  if (const std::string note = query_mode_note(s); !note.empty())
    doc.paragraph(note);  // instead of the similarities, which mean nothing
  else if (const auto sim = similarity_table(s))
    doc.table(*sim);
  if (o.figures) {
    doc.html_only("<h3>Masks</h3>\n" + scene_figures(s, o.thumbnail_width));
    doc.html_only(curves_html(s, o.thumbnail_width));
  }
}

}  // namespace

ReportFiles write_report(const fs::path& out, const ReportOptions& o) {
  o.Check();
  std::vector<SceneData> scenes;
  std::vector<std::string> names;
  for (const SceneReportInput& in : o.scenes) {
    scenes.push_back(load_scene(in));
    names.push_back(in.name);
  }
  const Dataset d = o.dataset.empty() ? dataset_of_scenes(names) : dataset_named(o.dataset);
  const std::string protocol = scenes.front().protocol;

  ReportDocument doc(o.title);
  doc.paragraph(
      fmt::format("Protocol: {}. {}", protocol,
                  d == Dataset::kOther
                      ? std::string("Not one of the paper's datasets: no published figures.")
                      : "Paper figures: OP2GS (Liu et al.), " + dataset_title(d) + " tables."));
  doc.table(dataset_table(scenes, d));
  if (const std::string note = query_mode_note(scenes); !note.empty()) doc.paragraph(note);
  if (const auto ablation = ablation_table(scenes, d)) doc.table(*ablation);
  for (const SceneData& s : scenes) add_scene(out, s, o, doc);
  ReportFiles files{out / "report.html", out / "report.md"};
  splat::write_text_atomically(files.html, doc.html());
  splat::write_text_atomically(files.markdown, doc.markdown());
  return files;
}

}  // namespace eval
