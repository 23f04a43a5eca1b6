#include "eval/report/scene_data.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <filesystem>

#include "splat/atomic_file.h"
#include "splat/error.h"

namespace eval {
namespace fs = std::filesystem;

double percent(const json& v) { return v.is_number() ? 100 * v.get<double>() : NAN; }

std::string cell(double v) { return std::isfinite(v) ? fmt::format("{:.1f}", v) : "–"; }

SceneData load_scene(const SceneReportInput& in) {
  SceneData s;
  s.input = in;
  try {
    s.metrics = json::parse(splat::read_text_file(in.metrics));
    s.protocol = s.metrics.value("protocol", "");
    for (const char* section : {"results", "query_results"}) {
      if (!s.metrics.contains(section)) continue;
      for (const auto& [name, scores] : s.metrics[section].items()) {
        Row r;
        r.prediction = name;
        r.mode = std::string(section) == "results" ? "oracle" : "query";
        r.miou = percent(scores.at("miou"));
        s.boundary = scores.contains("mbiou");
        r.second = percent(s.boundary ? scores.at("mbiou") : scores.at("accuracy"));
        r.scores = scores;
        s.rows.push_back(std::move(r));
      }
    }
  } catch (const json::exception& e) {
    throw splat::InputError(in.metrics, std::string("not an op2gs-eval metrics file: ") + e.what());
  }
  if (s.rows.empty()) throw splat::InputError(in.metrics, "holds no mask scores");
  if (s.metrics.contains("layout")) s.layout = s.metrics["layout"].value("description", "");
  s.without_truth = s.metrics.value("test_views_without_ground_truth", std::vector<std::string>{});
  if (s.metrics.contains("query_mode") && !s.metrics["query_mode"].value("available", true))
    s.query_mode_unavailable = s.metrics["query_mode"].value("reason", "") + ". " +
                               s.metrics["query_mode"].value("fetch", "") + ".";
  return s;
}

bool not_available(const SceneData& s, const std::string& key) {
  if (s.query_mode_unavailable.empty()) return false;
  for (const Row& r : s.rows)
    if (r.mode == "oracle" && key == r.prediction + " (query)") return true;
  return false;
}

std::string query_mode_note(const SceneData& s) {
  if (s.query_mode_unavailable.empty()) return "";
  return std::string("Query mode: not available (") + kNotAvailable +
         "): " + s.query_mode_unavailable;
}

std::string scene_notes(const SceneData& s) {
  std::string note;
  if (!s.layout.empty()) note = "Scene folder: " + s.layout + ".";
  if (!s.without_truth.empty())
    note += fmt::format(
        " Test views without ground truth (not scored, as the reference script "
        "skips them): {}.",
        fmt::join(s.without_truth, ", "));
  return note;
}

std::string query_mode_note(const std::vector<SceneData>& scenes) {
  for (const SceneData& s : scenes)
    if (std::string note = query_mode_note(s); !note.empty()) return note;
  return "";
}

namespace {

// Stage two's metrics.json, or an empty object when it is not given.
json training_metrics(const SceneReportInput& in) {
  if (in.training_metrics.empty() || !fs::exists(in.training_metrics)) return json::object();
  return json::parse(splat::read_text_file(in.training_metrics));
}

}  // namespace

std::string fitted_psnr_note(const SceneReportInput& in) {
  const json m = training_metrics(in);
  if (!m.contains("psnr_fitted_right_half") || !m["psnr_fitted_right_half"].is_number()) return "";
  return fmt::format(
      "Test PSNR after a colour transform fitted on each test view's left half, scored on its "
      "right half (NeRF in the Wild's protocol for models that compensate exposure): {:.2f} dB "
      "(without the fit, whole views: {:.2f} dB).",
      m["psnr_fitted_right_half"].get<double>(), m.value("psnr", NAN));
}

std::string object_loss_note(const SceneReportInput& in) {
  const json m = training_metrics(in);
  if (!m.contains("object_loss")) return "";
  const json& loss = m["object_loss"];
  std::string what, recipe;
  if (loss.value("pixel_loss", "") == "cross-entropy") {
    what = "the paper's binary cross-entropy";
    recipe = "paper";
  } else if (loss.contains("cross_entropy_near_model_outline")) {
    // Within the band: the paper's cross-entropy, or a q of its own (--outline-q).
    const double band_q = loss.value("q_near_model_outline", 0.0);
    what = fmt::format(
        "the generalized cross-entropy (q = {:g}), and {} within {} pixels of the outline of the "
        "model's own mask",
        loss.value("q", NAN),
        band_q > 0 ? fmt::format("q = {:g}", band_q) : "the paper's cross-entropy",
        loss["cross_entropy_near_model_outline"].get<int>());
    recipe = band_q > 0 ? fmt::format("robust-outline --outline-q {:g}", band_q) : "robust-outline";
  } else {
    what = fmt::format("the generalized cross-entropy (q = {:g})", loss.value("q", NAN));
    recipe = "robust";
  }
  if (!loss.value("reshapes_geometry", true)) what += ", reaching sigma* only";
  std::string note =
      fmt::format("Stage two's object loss: {} (op2gs-learn --recipe {})", what, recipe);
  if (recipe != "paper") note += "; the paper's recipe is --recipe paper";
  return note + ".";
}

const Row* find_row(const SceneData& s, const std::string& key) {
  for (const Row& r : s.rows)
    if (r.key() == key) return &r;
  return nullptr;
}

std::vector<std::string> row_keys(const std::vector<SceneData>& scenes) {
  std::vector<std::string> keys;
  const auto add = [&](const std::string& key) {
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
  };
  for (const SceneData& s : scenes)
    for (const Row& r : s.rows) add(r.key());
  for (const SceneData& s : scenes)
    for (const Row& r : s.rows)
      if (!s.query_mode_unavailable.empty() && r.mode == "oracle") add(r.prediction + " (query)");
  return keys;
}

}  // namespace eval
