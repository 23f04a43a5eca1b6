#include "eval/report/report.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "eval/metrics/lerf_mask.h"
#include "eval/metrics/ovs.h"
#include "eval/metrics/predictions.h"
#include "eval/report/html.h"
#include "eval/report/paper_numbers.h"
#include "eval/report/viewer.h"
#include "splat/atomic_file.h"
#include "splat/error.h"

namespace eval {
namespace fs = std::filesystem;
using json = nlohmann::ordered_json;  // keys in the order written: predictions as given

void ReportOptions::Check() const {
  if (scenes.empty()) throw std::invalid_argument("no scenes to report");
  if (thumbnail_width < 32) throw std::invalid_argument("thumbnail width must be at least 32");
  std::set<std::string> names;
  for (const SceneReportInput& s : scenes)
    if (!names.insert(s.name).second) throw std::invalid_argument("scene named twice: " + s.name);
}

namespace {

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

// Whether `key` names a query-mode row that the scene asked for but could not
// score ("<prediction> (query)" of one of its oracle rows).
bool not_available(const SceneData& s, const std::string& key) {
  if (s.query_mode_unavailable.empty()) return false;
  for (const Row& r : s.rows)
    if (r.mode == "oracle" && key == r.prediction + " (query)") return true;
  return false;
}

// The note under a table with query columns of the scene that could not be
// scored; empty when they were.
std::string query_mode_note(const SceneData& s) {
  if (s.query_mode_unavailable.empty()) return "";
  return std::string("Query mode: not available (") + kNotAvailable +
         "): " + s.query_mode_unavailable;
}

// What the scene's folder was read as, and its test views without ground
// truth; empty when there is nothing to say.
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

// The first scene's note, for the tables of all scenes.
std::string query_mode_note(const std::vector<SceneData>& scenes) {
  for (const SceneData& s : scenes)
    if (std::string note = query_mode_note(s); !note.empty()) return note;
  return "";
}

// A note as a paragraph of both reports.
void add_note(const std::string& note, std::string& md, std::string& html) {
  md += note + "\n\n";
  html += "<p>" + html_escape(note) + "</p>\n";
}

const Row* find_row(const SceneData& s, const std::string& key) {
  for (const Row& r : s.rows)
    if (r.key() == key) return &r;
  return nullptr;
}

// Every (prediction, mode) of the scenes, query-mode rows that could not be
// scored included.
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

// ------------------------------------------------------------------ tables

// A table as rows of cells; rendered to HTML and Markdown alike.
struct Table {
  std::string caption;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

std::string to_markdown(const Table& t) {
  std::string md = t.caption.empty() ? "" : t.caption + "\n\n";
  md += "| " + fmt::format("{}", fmt::join(t.header, " | ")) + " |\n|";
  for (size_t i = 0; i < t.header.size(); ++i) md += i ? " ---: |" : " --- |";
  md += "\n";
  for (const auto& row : t.rows) md += "| " + fmt::format("{}", fmt::join(row, " | ")) + " |\n";
  return md + "\n";
}

std::string to_html(const Table& t) {
  std::string h = "<table>";
  if (!t.caption.empty()) h += "<caption>" + html_escape(t.caption) + "</caption>";
  h += "<tr>";
  for (const auto& c : t.header) h += "<th>" + html_escape(c) + "</th>";
  h += "</tr>";
  for (const auto& row : t.rows) {
    h += "<tr>";
    for (const auto& c : row) h += "<td>" + html_escape(c) + "</td>";
    h += "</tr>";
  }
  return h + "</table>\n";
}

std::string second_name(const std::vector<SceneData>& scenes) {
  return scenes.front().boundary ? "mBIoU" : "acc";
}

Table dataset_table(const std::vector<SceneData>& scenes, Dataset d) {
  Table t;
  t.caption = fmt::format("mIoU / {} (%) per scene; the mean is the plain mean of the scenes",
                          second_name(scenes));
  const std::vector<std::string> keys = row_keys(scenes);
  t.header = {"scene"};
  for (const std::string& k : keys) {
    t.header.push_back(k + " mIoU");
    t.header.push_back(k + " " + second_name(scenes));
  }
  const bool paper = d != Dataset::kOther;
  // The paper's figures of the pseudo-labels each scene used (metrics.json's
  // id_maps; SAM2 when not recorded).
  const auto labels_of = [](const SceneData& s) {
    return s.metrics.contains("id_maps")
               ? pseudo_labels_of_folder(s.metrics["id_maps"].value("folder", ""))
               : PseudoLabels::kSam2;
  };
  std::set<std::string> label_names;
  for (const SceneData& s : scenes) label_names.insert(pseudo_labels_name(labels_of(s)));
  const std::string labels_title = label_names.size() == 1 ? *label_names.begin() : "per scene";
  if (paper)
    t.header.insert(t.header.end(), {"paper mIoU (" + labels_title + ")",
                                     "paper mBIoU (" + labels_title + ")"});
  std::vector<double> sums(2 * keys.size() + 2, 0);
  std::vector<int> counts(sums.size(), 0);
  std::vector<bool> not_scored(sums.size(), false);  // a scene's n/a in the column
  const auto add = [&](std::vector<std::string>& row, size_t col, double v) {
    row.push_back(cell(v));
    if (std::isfinite(v)) sums[col] += v, ++counts[col];
  };
  for (const SceneData& s : scenes) {
    std::vector<std::string> row = {s.input.name};
    for (size_t i = 0; i < keys.size(); ++i) {
      if (not_available(s, keys[i])) {
        row.insert(row.end(), {kNotAvailable, kNotAvailable});
        not_scored[2 * i] = not_scored[2 * i + 1] = true;
        continue;
      }
      const Row* r = find_row(s, keys[i]);
      add(row, 2 * i, r ? r->miou : NAN);
      add(row, 2 * i + 1, r ? r->second : NAN);
    }
    if (paper) {
      const auto f = paper_scene_figure(d, s.input.name, labels_of(s));
      add(row, 2 * keys.size(), f ? f->miou : NAN);
      add(row, 2 * keys.size() + 1, f && f->mbiou ? *f->mbiou : NAN);
    }
    t.rows.push_back(row);
  }
  if (scenes.size() > 1) {
    std::vector<std::string> mean = {"mean"};
    for (size_t c = 0; c + (paper ? 0 : 2) < sums.size(); ++c)
      mean.push_back(not_scored[c]                     ? kNotAvailable
                     : counts[c] == int(scenes.size()) ? cell(sums[c] / counts[c])
                                                       : "–");
    t.rows.push_back(mean);
  }
  return t;
}

// The paper's ablation layout: baseline against dual opacity, oracle and
// query mode, means over the scenes.
std::optional<Table> ablation_table(const std::vector<SceneData>& scenes, Dataset d) {
  std::string dual;
  for (const std::string& k : row_keys(scenes)) {
    const std::string name = k.substr(0, k.rfind(" ("));
    if (name != "baseline" && dual.empty()) dual = name;
  }
  if (dual.empty() || row_keys(scenes).size() < 2) return std::nullopt;
  const auto mean = [&](const std::string& key, bool second) -> double {
    double sum = 0;
    for (const SceneData& s : scenes) {
      const Row* r = find_row(s, key);
      if (!r) return NAN;
      sum += second ? r->second : r->miou;
    }
    return sum / double(scenes.size());
  };
  Table t;
  t.caption = "Ablation layout of the paper (mean over scenes, %)";
  t.header = {"mode", "baseline mIoU", "baseline " + second_name(scenes), dual + " mIoU",
              dual + " " + second_name(scenes)};
  const auto paper = paper_ablation(d);
  if (!paper.empty())
    t.header.insert(t.header.end(), {"paper baseline mIoU", "paper baseline mBIoU",
                                     "paper dual mIoU", "paper dual mBIoU"});
  for (const std::string mode : {"oracle", "query"}) {
    const std::string b = "baseline (" + mode + ")", o = dual + " (" + mode + ")";
    const bool na = not_available(scenes.front(), o);
    if (!find_row(scenes.front(), o) && !na) continue;
    std::vector<std::string> row = {mode, cell(mean(b, false)), cell(mean(b, true)),
                                    cell(mean(o, false)), cell(mean(o, true))};
    if (na) std::fill(row.begin() + 1, row.end(), kNotAvailable);
    for (const PaperAblationRow& p : paper)
      if (p.mode == mode)
        row.insert(row.end(), {cell(p.baseline_miou), cell(p.baseline_mbiou), cell(p.dual_miou),
                               cell(p.dual_mbiou)});
    t.rows.push_back(row);
  }
  return t;
}

// Per query (class): the object each row chose and its scores.
Table query_table(const SceneData& s) {
  Table t;
  t.caption = "Per query: object chosen, mIoU / " + std::string(s.boundary ? "mBIoU" : "IoU");
  t.header = {"query"};
  for (const Row& r : s.rows) t.header.insert(t.header.end(), {r.key() + " object", r.key()});
  std::map<std::string, std::vector<std::string>> rows;
  std::vector<std::string> order;
  for (size_t i = 0; i < s.rows.size(); ++i) {
    const json& sc = s.rows[i].scores;
    const bool lerf = sc.contains("queries");
    for (const json& q : lerf ? sc["queries"] : sc["classes"]) {
      const std::string name = q.at(lerf ? "query" : "class");
      if (!rows.count(name)) {
        rows[name] = std::vector<std::string>(1 + 2 * s.rows.size(), "–");
        rows[name][0] = name;
        order.push_back(name);
      }
      double miou = 0;
      if (lerf) {
        miou = percent(q["miou"]);
      } else {
        for (const json& v : q["views"]) miou += percent(v["iou"]);
        miou /= std::max<size_t>(1, q["views"].size());
      }
      rows[name][1 + 2 * i] = fmt::format("{}", q.at("object").get<int>());
      rows[name][2 + 2 * i] = lerf ? cell(miou) + " / " + cell(percent(q["mbiou"])) : cell(miou);
    }
  }
  for (const std::string& name : order) t.rows.push_back(rows[name]);
  return t;
}

std::optional<Table> similarity_table(const SceneData& s) {
  if (s.input.queries.empty() || !fs::exists(s.input.queries)) return std::nullopt;
  const json q = json::parse(splat::read_text_file(s.input.queries));
  Table t;
  t.caption =
      "Text retrieval (op2gs-query): cosine similarity of the chosen object and the runner-up";
  t.header = {"query", "object", "similarity", "runner-up", "similarity "};
  const auto objects = q.at("objects").get<std::vector<int>>();
  for (const json& a : q.at("queries")) {
    const auto sims = a.at("similarities").get<std::vector<double>>();
    int second = -1;
    for (size_t i = 0; i < sims.size() && i < objects.size(); ++i)
      if (objects[i] != a["object"].get<int>() && (second < 0 || sims[i] > sims[size_t(second)]))
        second = int(i);
    t.rows.push_back({a["query"], fmt::format("{}", a["object"].get<int>()),
                      fmt::format("{:.4f}", a["similarity"].get<double>()),
                      second >= 0 ? fmt::format("{}", objects[size_t(second)]) : "–",
                      second >= 0 ? fmt::format("{:.4f}", sims[size_t(second)]) : "–"});
  }
  return t;
}

// ----------------------------------------------------------------- figures

splat::ImageRGB thumbnail(const splat::ImageRGB& image, int width) {
  if (image.width <= width) return image;
  const int height = std::max(1, int(std::lround(double(image.height) * width / image.width)));
  return splat::resize_area(image, width, height);
}

splat::ImageRGB overlay(const splat::ImageRGB& photo, const Mask& truth, const Mask* pred) {
  splat::ImageRGB out = photo;
  for (size_t p = 0; p < truth.on.size(); ++p) {
    float color[3] = {-1, -1, -1};
    const bool t = truth.on[p], e = pred && pred->on[p];
    if (!pred && t) color[0] = 1, color[1] = 0.85f, color[2] = 0;            // ground truth: yellow
    if (pred && t && e) color[0] = 0.1f, color[1] = 0.85f, color[2] = 0.1f;  // right
    if (pred && !t && e) color[0] = 0.95f, color[1] = 0.1f, color[2] = 0.1f;  // false positive
    if (pred && t && !e) color[0] = 0.1f, color[1] = 0.3f, color[2] = 1.0f;   // missed
    for (int c = 0; c < 3; ++c) {
      float& v = out.data[3 * p + c];
      v = color[0] < 0 ? 0.45f * v : 0.4f * v + 0.6f * color[c];
    }
  }
  return out;
}

std::string figure(const std::string& uri, const std::string& caption) {
  return fmt::format("<figure><img src=\"{}\"><figcaption>{}</figcaption></figure>", uri,
                     html_escape(caption));
}

// The (view, query) -> IoU of one row, from metrics.json.
std::map<std::pair<std::string, std::string>, std::pair<int, double>> row_views(const Row& r) {
  std::map<std::pair<std::string, std::string>, std::pair<int, double>> out;
  const bool lerf = r.scores.contains("queries");
  for (const json& q : lerf ? r.scores["queries"] : r.scores["classes"])
    for (const json& v : q["views"])
      out[{v["view"].get<std::string>(), q.at(lerf ? "query" : "class").get<std::string>()}] = {
          q["object"].get<int>(), percent(v["iou"])};
  return out;
}

// Floaters and label contamination (op2gs-floaters), when measured.
std::vector<Table> floater_tables(const SceneReportInput& in) {
  if (in.floaters.empty() || !fs::exists(in.floaters)) return {};
  const json f = json::parse(splat::read_text_file(in.floaters));
  const auto pct = [](const json& v) { return fmt::format("{:.1f}%", 100 * v.get<double>()); };
  Table summary{fmt::format("Floaters (farther than {} from every true surface) and wrongly "
                            "labelled Gaussians; shares of the test views' rendered opacity "
                            "and of the object masks' occupancy",
                            f.at("distance").get<double>()),
                {"measure", "value"},
                {}};
  const size_t n = std::max<size_t>(f.at("gaussians").get<size_t>(), 1);
  summary.rows = {
      {"Gaussians", std::to_string(f.at("gaussians").get<size_t>())},
      {"floaters", fmt::format("{} ({:.1f}%)", f.at("floaters").get<size_t>(),
                               100.0 * f.at("floaters").get<size_t>() / n)},
      {"floaters in the object region", std::to_string(f["region"]["floaters"].get<size_t>())},
      {"floaters with an object label", std::to_string(f.at("floaters_labelled").get<size_t>())},
      {"picture opacity from floaters", pct(f.at("floater_opacity_share"))},
      {"... from floaters in the object region", pct(f["region"]["floater_opacity_share"])},
      {"mask occupancy from floaters, sigma / sigma*",
       pct(f["mask_floater_share"]["sigma"]) + " / " + pct(f["mask_floater_share"]["sigma_star"])},
      {"mask occupancy from wrong labels, sigma / sigma*",
       pct(f["mask_wrong_share"]["sigma"]) + " / " + pct(f["mask_wrong_share"]["sigma_star"])}};
  Table objects{
      "Per object: its Gaussians labelled otherwise, the Gaussians wrongly carrying its "
      "label (floaters, on a border with another object), and their mean opacities",
      {"object", "Gaussians", "labelled otherwise", "wrongly labelled", "floaters", "border",
       "sigma right / wrong", "sigma* right / wrong"},
      {}};
  for (const json& o : f.at("objects")) {
    objects.rows.push_back({o.value("name", std::to_string(o.at("id").get<int>())),
                            std::to_string(o.at("gaussians").get<size_t>()),
                            std::to_string(o.at("wrong").get<size_t>()),
                            std::to_string(o.at("labelled_wrongly").get<size_t>()),
                            std::to_string(o.at("labelled_floaters").get<size_t>()),
                            std::to_string(o.at("labelled_border").get<size_t>()),
                            fmt::format("{:.2f} / {:.2f}", o["sigma"]["right"].get<double>(),
                                        o["sigma"]["wrong"].get<double>()),
                            fmt::format("{:.2f} / {:.2f}", o["sigma_star"]["right"].get<double>(),
                                        o["sigma_star"]["wrong"].get<double>())});
  }
  Table views{"Per test view: the share of its rendered opacity that floaters carry",
              {"view", "all floaters", "floaters in the object region"},
              {}};
  for (const json& v : f.value("per_view", json::array()))
    views.rows.push_back({v.at("view").get<std::string>(), pct(v.at("floater_opacity_share")),
                          pct(v.at("region_floater_opacity_share"))});
  if (views.rows.empty()) return {summary, objects};
  return {summary, objects, views};
}

// The colour-fitted test PSNR of stage two, when its metrics are given.
std::string fitted_psnr_note(const SceneReportInput& in) {
  if (in.training_metrics.empty() || !fs::exists(in.training_metrics)) return "";
  const json m = json::parse(splat::read_text_file(in.training_metrics));
  if (!m.contains("psnr_fitted_right_half") || !m["psnr_fitted_right_half"].is_number()) return "";
  return fmt::format(
      "Test PSNR after a colour transform fitted on each test view's left half, scored on its "
      "right half (NeRF in the Wild's protocol for models that compensate exposure): {:.2f} dB "
      "(without the fit, whole views: {:.2f} dB).",
      m["psnr_fitted_right_half"].get<double>(), m.value("psnr", NAN));
}

std::string scene_figures(const SceneData& s, int width) {
  const bool on_ovs = s.protocol.find("3dovs") != std::string::npos;
  const LerfMaskGroundTruth gt = on_ovs ? lerf_mask_from_ovs(read_ovs_ground_truth(s.input.scene))
                                        : read_lerf_mask_ground_truth(s.input.scene);
  std::vector<std::map<std::pair<std::string, std::string>, std::pair<int, double>>> views;
  for (const Row& r : s.rows) views.push_back(row_views(r));
  std::string h =
      "<p class=\"legend\">Masks coloured by error: <span style=\"color:#1d1\">right</span>, "
      "<span style=\"color:#e22\">predicted, not true</span>, "
      "<span style=\"color:#25f\">true, missed</span>.</p>\n";
  for (size_t k = 0; k < gt.test_views.size(); ++k) {
    const std::string& view = gt.test_views[k];
    const fs::path photo_file = s.input.scene / "images" / view;
    if (!fs::exists(photo_file) || gt.masks[k].empty()) continue;
    const splat::ImageRGB photo_full = splat::read_image_rgb(photo_file);
    h += fmt::format("<h4>{}</h4>\n", html_escape(view));
    const fs::path labels =
        s.input.render / "instance_labels_color" / (fs::path(view).stem().string() + ".png");
    if (!s.input.render.empty() && fs::exists(labels))
      h += "<div class=\"row\">" +
           figure(jpeg_data_uri(thumbnail(splat::read_image_rgb(labels), width)),
                  "instance label map") +
           "</div>\n";
    std::vector<ObjectMasks> predicted;
    for (const Row& r : s.rows)
      predicted.push_back(read_view_predictions(r.scores.at("folder").get<std::string>(), view));
    for (const auto& [query, file] : gt.masks[k]) {
      const Mask truth = read_mask(file);
      splat::ImageRGB photo = photo_full;
      if (photo.width != truth.width || photo.height != truth.height)
        photo = splat::resize_area(photo, truth.width, truth.height);
      h += "<div class=\"row\">" + figure(jpeg_data_uri(thumbnail(photo, width)), query) +
           figure(jpeg_data_uri(thumbnail(overlay(photo, truth, nullptr), width)), "ground truth");
      for (size_t i = 0; i < s.rows.size(); ++i) {
        const auto it = views[i].find({view, query});
        if (it == views[i].end()) continue;
        const auto [object, iou] = it->second;
        const auto m = predicted[i].find(object);
        const Mask pred = m == predicted[i].end()
                              ? Mask(truth.width, truth.height)
                              : resize_mask_nearest(m->second, truth.width, truth.height);
        h += figure(jpeg_data_uri(thumbnail(overlay(photo, truth, &pred), width)),
                    fmt::format("{}: object {}, IoU {}", s.rows[i].key(), object, cell(iou)));
      }
      h += "</div>\n";
    }
  }
  return h;
}

std::string curves_html(const SceneData& s, int width) {
  std::string h;
  for (const fs::path& png : s.input.curves)
    if (fs::exists(png))
      h += figure(jpeg_data_uri(thumbnail(splat::read_image_rgb(png), 3 * width)),
                  png.parent_path().filename().string() + "/" + png.filename().string());
  return h.empty() ? "" : "<h3>Training curves</h3><div class=\"row\">" + h + "</div>\n";
}

constexpr const char* kStyle = R"(<style>
body { font-family: sans-serif; margin: 2em; color: #222; }
table { border-collapse: collapse; margin: 1em 0; font-size: 14px; }
caption { text-align: left; font-weight: bold; padding: 4px 0; }
th, td { border: 1px solid #bbb; padding: 3px 8px; text-align: right; }
th:first-child, td:first-child { text-align: left; }
figure { display: inline-block; margin: 4px; }
figcaption { font-size: 12px; max-width: 320px; }
.row { white-space: nowrap; overflow-x: auto; }
.legend span { font-weight: bold; }
</style>)";

// Writes the scene's 3D viewer into out/viewer/ and links it.
void add_viewer(const fs::path& out, const SceneReportInput& in, std::string& md,
                std::string& html) {
  const fs::path page =
      write_viewer(out / "viewer", {in.name, in.viewer_scene.empty() ? in.scene : in.viewer_scene,
                                    in.model, in.model_ply, in.metrics, in.queries});
  const std::string serve = fmt::format(
      "python3 -m http.server 8000 in the report's folder, then open http://localhost:8000/{}",
      page.parent_path().generic_string() + "/");
  md += fmt::format("3D viewer: [{}]({}) (browsers load it from a local server: {})\n\n",
                    page.generic_string(), page.generic_string(), serve);
  html += fmt::format(
      "<p><a href=\"{}\">Open the 3D viewer</a> of the labelled model (browsers load it only "
      "from a local web server: <code>{}</code>).</p>\n",
      html_escape(page.generic_string()), html_escape(serve));
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

  std::string md = "# " + o.title + "\n\n";
  std::string html = "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>" +
                     html_escape(o.title) + "</title>" + kStyle + "</head><body>\n<h1>" +
                     html_escape(o.title) + "</h1>\n";
  const std::string about = fmt::format(
      "Protocol: {}. {}", protocol,
      d == Dataset::kOther ? std::string("Not one of the paper's datasets: no published figures.")
                           : "Paper figures: OP2GS (Liu et al.), " + dataset_title(d) + " tables.");
  md += about + "\n\n";
  html += "<p>" + html_escape(about) + "</p>\n";
  const Table summary = dataset_table(scenes, d);
  md += to_markdown(summary);
  html += to_html(summary);
  if (const std::string note = query_mode_note(scenes); !note.empty()) add_note(note, md, html);
  if (const auto ablation = ablation_table(scenes, d)) {
    md += to_markdown(*ablation);
    html += to_html(*ablation);
  }
  for (const SceneData& s : scenes) {
    md += "## " + s.input.name + "\n\n";
    html += "<h2>" + html_escape(s.input.name) + "</h2>\n";
    if (const std::string note = scene_notes(s); !note.empty()) add_note(note, md, html);
    if (s.metrics.contains("image_quality")) {
      const std::string q = fmt::format("Test views: PSNR {:.2f} dB, SSIM {:.4f}",
                                        s.metrics["image_quality"]["psnr"].get<double>(),
                                        s.metrics["image_quality"]["ssim"].get<double>());
      md += q + "\n\n";
      html += "<p>" + q + "</p>\n";
    }
    if (const std::string fitted = fitted_psnr_note(s.input); !fitted.empty()) {
      md += fitted + "\n\n";
      html += "<p>" + html_escape(fitted) + "</p>\n";
    }
    if (o.viewer && !s.input.model.empty()) add_viewer(out, s.input, md, html);
    for (const Table& t : floater_tables(s.input)) {
      md += to_markdown(t);
      html += to_html(t);
    }
    const Table queries = query_table(s);
    md += to_markdown(queries);
    html += to_html(queries);
    if (const std::string note = query_mode_note(s); !note.empty()) {
      add_note(note, md, html);  // instead of the similarities, which mean nothing
    } else if (const auto sim = similarity_table(s)) {
      md += to_markdown(*sim);
      html += to_html(*sim);
    }
    if (o.figures) {
      html += "<h3>Masks</h3>\n" + scene_figures(s, o.thumbnail_width);
      html += curves_html(s, o.thumbnail_width);
    }
  }
  html += "</body></html>\n";
  ReportFiles files{out / "report.html", out / "report.md"};
  splat::write_text_atomically(files.html, html);
  splat::write_text_atomically(files.markdown, md);
  return files;
}

}  // namespace eval
