#pragma once
// What the report reads of one scene: op2gs-eval's metrics.json as rows of
// scores (one per prediction folder and mode), and the notes the scene's
// tables carry.

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/report/report.h"

namespace eval {

using json = nlohmann::ordered_json;  // keys in the order written: predictions as given

// One scored (prediction folder, mode) of a scene.
struct Row {
  std::string prediction, mode;
  double miou = NAN, second = NAN;  // in percent; second: mBIoU or pixel accuracy
  json scores;                      // metrics.json's entry
  std::string key() const { return prediction + " (" + mode + ")"; }
};

struct SceneData {
  SceneReportInput input;
  json metrics;
  std::string protocol;
  bool boundary = true;  // the second figure is mBIoU (else pixel accuracy)
  std::vector<Row> rows;
  // Set when query mode was asked for but not scored (metrics.json's
  // query_mode): why, and how to fetch the real CLIP.
  std::string query_mode_unavailable;
  // What the scene's folder was read as, and the test views it has no
  // ground truth for (metrics.json's layout, test_views_without_ground_truth).
  std::string layout;
  std::vector<std::string> without_truth;
};

// The cells of a query-mode figure that was not scored.
constexpr char kNotAvailable[] = "n/a";

// A fraction as percent (NaN when it is not a number), and a figure as a
// table cell ("–" when it is not finite).
double percent(const json& v);
std::string cell(double v);

// Throws InputError naming metrics.json when it is not op2gs-eval's or
// holds no scores.
SceneData load_scene(const SceneReportInput& in);

// Whether `key` names a query-mode row that the scene asked for but could not
// score ("<prediction> (query)" of one of its oracle rows).
bool not_available(const SceneData& s, const std::string& key);

// The note under a table with query columns of the scene that could not be
// scored; empty when they were. The second form: the first scene's note,
// for the tables of all scenes.
std::string query_mode_note(const SceneData& s);
std::string query_mode_note(const std::vector<SceneData>& scenes);

// What the scene's folder was read as, and its test views without ground
// truth; empty when there is nothing to say.
std::string scene_notes(const SceneData& s);

// The colour-fitted test PSNR of stage two, when its metrics are given;
// empty otherwise.
std::string fitted_psnr_note(const SceneReportInput& in);

// Which object loss made sigma* (stage two's metrics.json), so that a run's
// figures set beside the paper's say whether they are the paper's recipe;
// empty when stage two's metrics are not given or predate that record.
std::string object_loss_note(const SceneReportInput& in);

// The scene's row of that key, or null.
const Row* find_row(const SceneData& s, const std::string& key);

// Every (prediction, mode) of the scenes, query-mode rows that could not be
// scored included.
std::vector<std::string> row_keys(const std::vector<SceneData>& scenes);

}  // namespace eval
