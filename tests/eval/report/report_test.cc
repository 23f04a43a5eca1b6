// op2gs-report from a scene scored by op2gs-eval: both files written, the
// scene's figures in them, nothing fetched from outside.

#include "eval/report/report.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "eval/run/eval_run.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "tests/tiny_scene.h"

namespace eval {
namespace {

namespace fs = std::filesystem;

struct ScoredScene {
  fs::path scene, metrics;
  EvalRunResult result;
};

const ScoredScene& scored() {
  static const ScoredScene s = [] {
    const fs::path d = testing_util::process_temp_dir("report");
    testing_util::generate_small_scene_in_both_layouts(d);
    EvalRunOptions o;
    o.predictions = {{"exact", d / "lerf" / "instance_gt"}, {"sam2-like", d / "lerf" / "sam2"}};
    ScoredScene out{d / "lerf", d / "work" / "eval" / "metrics.json", {}};
    fs::create_directories(out.metrics.parent_path());
    out.result = run_evaluation(out.scene, out.metrics, o);
    return out;
  }();
  return s;
}

TEST(Report, WritesHtmlAndMarkdownWithTheScenesFigures) {
  const testing_util::TempDir tmp;
  ReportOptions o;
  o.title = "test report";
  o.scenes = {{"tiny", scored().scene, scored().metrics, {}, {}, {}}};
  const ReportFiles f = write_report(tmp / "report", o);
  const std::string html = splat::read_text_file(f.html);
  const std::string md = splat::read_text_file(f.markdown);
  for (const std::string* text : {&html, &md}) {
    EXPECT_NE(text->find("test report"), std::string::npos);
    EXPECT_NE(text->find("tiny"), std::string::npos);
    EXPECT_NE(text->find("exact"), std::string::npos);
    EXPECT_NE(text->find("sam2-like"), std::string::npos);
    EXPECT_NE(text->find(fmt::format("{:.1f}", 100 * scored().result.miou[0])), std::string::npos);
  }
  // What the scene's folder was read as.
  EXPECT_NE(md.find("Scene folder: LERF-Mask layout"), std::string::npos) << md;
  // Self-contained: opens offline, from any folder.
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("href=\"http"), std::string::npos);
}

TEST(Report, ShowsFloatersAndTheColourFittedPsnrWhenMeasured) {
  const testing_util::TempDir tmp;
  const nlohmann::json floaters = {
      {"distance", 0.05},
      {"gaussians", 1000},
      {"floaters", 120},
      {"floater_share", 0.12},
      {"floaters_labelled", 7},
      {"region", {{"gaussians", 600}, {"floaters", 40}, {"floater_opacity_share", 0.031}}},
      {"views", 5},
      {"floater_opacity_share", 0.083},
      {"per_view",
       {{{"view", "frame_00004.jpg"},
         {"floater_opacity_share", 0.12},
         {"region_floater_opacity_share", 0.045}}}},
      {"mask_floater_share", {{"sigma", 0.021}, {"sigma_star", 0.004}}},
      {"mask_wrong_share", {{"sigma", 0.061}, {"sigma_star", 0.017}}},
      {"objects",
       {{{"id", 1},
         {"name", "red ball"},
         {"gaussians", 300},
         {"wrong", 4},
         {"labelled", 310},
         {"labelled_wrongly", 14},
         {"labelled_floaters", 3},
         {"labelled_border", 9},
         {"sigma", {{"right", 0.8}, {"wrong", 0.6}}},
         {"sigma_star", {{"right", 0.85}, {"wrong", 0.1}}}}}}};
  splat::write_text_atomically(tmp / "floaters.json", floaters.dump());
  splat::write_text_atomically(tmp / "learn.json",
                               R"({"psnr": 24.5, "psnr_fitted_right_half": 27.25})");
  ReportOptions o;
  SceneReportInput s{"tiny", scored().scene, scored().metrics, {}, {}, {}};
  s.floaters = tmp / "floaters.json";
  s.training_metrics = tmp / "learn.json";
  o.scenes = {s};
  const std::string md = splat::read_text_file(write_report(tmp / "report", o).markdown);
  EXPECT_NE(md.find("| floaters | 120 (12.0%) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| mask occupancy from wrong labels, sigma / sigma* | 6.1% / 1.7% |"),
            std::string::npos);
  EXPECT_NE(md.find("| red ball | 300 | 4 | 14 | 3 | 9 | 0.80 / 0.60 | 0.85 / 0.10 |"),
            std::string::npos);
  EXPECT_NE(md.find("| frame_00004.jpg | 12.0% | 4.5% |"), std::string::npos) << md;
  EXPECT_NE(md.find("27.25 dB"), std::string::npos);
  EXPECT_NE(md.find("NeRF in the Wild"), std::string::npos);
}

// The default object loss is not the paper's, so a report beside the paper's
// figures says which one made sigma* (stage two's metrics.json, as written by
// splat/train/train_run.cc).
TEST(Report, NamesTheObjectLossThatMadeSigmaStar) {
  const testing_util::TempDir tmp;
  const auto note = [&](const std::string& learn_metrics) {
    splat::write_text_atomically(tmp / "learn.json", learn_metrics);
    ReportOptions o;
    SceneReportInput s{"tiny", scored().scene, scored().metrics, {}, {}, {}};
    s.training_metrics = tmp / "learn.json";
    o.scenes = {s};
    o.figures = false;
    const std::string md = splat::read_text_file(write_report(tmp / "report", o).markdown);
    const size_t at = md.find("Stage two's object loss: ");
    return at == std::string::npos ? std::string() : md.substr(at, md.find('\n', at) - at);
  };
  EXPECT_EQ(note(R"({"psnr": 24.5, "object_loss": {"pixel_loss": "cross-entropy"}})"),
            "Stage two's object loss: the paper's binary cross-entropy (op2gs-learn --recipe "
            "paper).");
  EXPECT_EQ(note(R"({"object_loss": {"pixel_loss": "generalized cross-entropy",
                  "q": 0.699999988079071, "cross_entropy_near_model_outline": 3}})"),
            "Stage two's object loss: the generalized cross-entropy (q = 0.7), and the paper's "
            "cross-entropy within 3 pixels of the outline of the model's own mask (op2gs-learn "
            "--recipe robust-outline); the paper's recipe is --recipe paper.");
  EXPECT_EQ(note(R"({"object_loss": {"pixel_loss": "generalized cross-entropy", "q": 0.7,
                  "cross_entropy_near_model_outline": 3, "q_near_model_outline": 0.35}})"),
            "Stage two's object loss: the generalized cross-entropy (q = 0.7), and q = 0.35 "
            "within 3 pixels of the outline of the model's own mask (op2gs-learn --recipe "
            "robust-outline --outline-q 0.35); the paper's recipe is --recipe paper.");
  EXPECT_EQ(note(R"({"object_loss": {"pixel_loss": "generalized cross-entropy", "q": 0.5,
                  "reshapes_geometry": false}})"),
            "Stage two's object loss: the generalized cross-entropy (q = 0.5), reaching sigma* "
            "only (op2gs-learn --recipe robust); the paper's recipe is --recipe paper.");
  // Stage one's metrics, or stage two's from before the record: nothing said.
  EXPECT_EQ(note(R"({"psnr": 24.5})"), "");
}

TEST(Report, SaysWhichTestViewsHaveNoGroundTruth) {
  const testing_util::TempDir tmp;
  nlohmann::json m = nlohmann::json::parse(splat::read_text_file(scored().metrics));
  m["test_views_without_ground_truth"] = {"frame_00009.jpg"};
  splat::write_text_atomically(tmp / "metrics.json", m.dump());
  ReportOptions o;
  o.scenes = {{"teatime", scored().scene, tmp / "metrics.json", {}, {}, {}}};
  const std::string md = splat::read_text_file(write_report(tmp / "report", o).markdown);
  EXPECT_NE(md.find("Test views without ground truth (not scored, as the reference script skips "
                    "them): frame_00009.jpg."),
            std::string::npos)
      << md;
}

// A run that voted from LERF-Mask's DEVA maps (object_mask/) is set beside
// the paper's SAM+DEVA row, one that voted from SAM2 maps beside its SAM2 row.
TEST(Report, SetsThePapersFiguresOfTheSamePseudoLabelsBeside) {
  const testing_util::TempDir tmp;
  ReportOptions o;
  o.dataset = "lerf-mask";
  nlohmann::json m = nlohmann::json::parse(splat::read_text_file(scored().metrics));
  m["id_maps"] = {{"folder", "object_mask"}};
  splat::write_text_atomically(tmp / "deva.json", m.dump());
  m["id_maps"] = {{"folder", "sam2"}};
  splat::write_text_atomically(tmp / "sam2.json", m.dump());
  o.scenes = {{"figurines", scored().scene, tmp / "deva.json", {}, {}, {}}};
  std::string md = splat::read_text_file(write_report(tmp / "deva", o).markdown);
  EXPECT_NE(md.find("paper mIoU (SAM+DEVA)"), std::string::npos) << md;
  EXPECT_NE(md.find("91.2"), std::string::npos) << md;
  EXPECT_EQ(md.find("92.3"), std::string::npos) << md;
  o.scenes = {{"figurines", scored().scene, tmp / "sam2.json", {}, {}, {}}};
  md = splat::read_text_file(write_report(tmp / "sam2", o).markdown);
  EXPECT_NE(md.find("paper mIoU (SAM2)"), std::string::npos) << md;
  EXPECT_NE(md.find("92.3"), std::string::npos) << md;
}

// op2gs-eval records the ID map folder a run used, "auto" resolved.
TEST(Report, EvaluationRecordsTheIdMapsUsed) {
  const testing_util::TempDir tmp;
  EvalRunOptions o;
  o.predictions = {{"exact", scored().scene / "instance_gt"}};
  o.id_maps = "auto";
  run_evaluation(scored().scene, tmp / "metrics.json", o);
  const auto m = nlohmann::json::parse(splat::read_text_file(tmp / "metrics.json"));
  EXPECT_EQ(m["id_maps"]["folder"], "sam2");
}

TEST(Report, MissingMetricsNameTheFile) {
  const testing_util::TempDir tmp;
  ReportOptions o;
  o.scenes = {{"tiny", scored().scene, tmp / "absent" / "metrics.json", {}, {}, {}}};
  try {
    write_report(tmp / "report", o);
    FAIL() << "expected InputError";
  } catch (const splat::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("absent"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(tmp / "report" / "report.html"));
}

}  // namespace
}  // namespace eval
