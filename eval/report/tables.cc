#include "eval/report/tables.h"

#include <fmt/format.h>

#include <filesystem>
#include <map>
#include <set>

#include "eval/metrics/floater_report.h"
#include "splat/atomic_file.h"

namespace eval {
namespace fs = std::filesystem;

namespace {
std::string second_name(const std::vector<SceneData>& scenes) {
  return scenes.front().boundary ? "mBIoU" : "acc";
}

}  // namespace

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
    t.header.insert(t.header.end(),
                    {"paper mIoU (" + labels_title + ")", "paper mBIoU (" + labels_title + ")"});
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

std::vector<Table> floater_tables(const SceneReportInput& in) {
  if (in.floaters.empty() || !fs::exists(in.floaters)) return {};
  const FloaterReport f = read_floater_report(in.floaters);
  const auto pct = [](double v) { return fmt::format("{:.1f}%", 100 * v); };
  Table summary{fmt::format("Floaters (farther than {} from every true surface) and wrongly "
                            "labelled Gaussians; shares of the test views' rendered opacity "
                            "and of the object masks' occupancy",
                            f.distance),
                {"measure", "value"},
                {}};
  summary.rows = {{"Gaussians", std::to_string(f.gaussians)},
                  {"floaters", fmt::format("{} ({:.1f}%)", f.floaters,
                                           100.0 * f.floaters / std::max<size_t>(f.gaussians, 1))},
                  {"floaters in the object region", std::to_string(f.region_floaters)},
                  {"floaters with an object label", std::to_string(f.floaters_labelled)},
                  {"picture opacity from floaters", pct(f.floater_opacity_share)},
                  {"... from floaters in the object region", pct(f.region_floater_opacity_share)},
                  {"mask occupancy from floaters, sigma / sigma*",
                   pct(f.mask_floater_share_sigma) + " / " + pct(f.mask_floater_share_sigma_star)},
                  {"mask occupancy from wrong labels, sigma / sigma*",
                   pct(f.mask_wrong_share_sigma) + " / " + pct(f.mask_wrong_share_sigma_star)}};
  Table objects{
      "Per object: its Gaussians labelled otherwise, the Gaussians wrongly carrying its "
      "label (floaters, on a border with another object), and their mean opacities",
      {"object", "Gaussians", "labelled otherwise", "wrongly labelled", "floaters", "border",
       "sigma right / wrong", "sigma* right / wrong"},
      {}};
  for (const ObjectContamination& o : f.objects)
    objects.rows.push_back(
        {o.name.empty() ? std::to_string(o.id) : o.name, std::to_string(o.gaussians),
         std::to_string(o.wrong), std::to_string(o.labelled_wrongly),
         std::to_string(o.labelled_floaters), std::to_string(o.labelled_border),
         fmt::format("{:.2f} / {:.2f}", o.mean_sigma_right, o.mean_sigma_wrong),
         fmt::format("{:.2f} / {:.2f}", o.mean_sigma_star_right, o.mean_sigma_star_wrong)});
  Table views{"Per test view: the share of its rendered opacity that floaters carry",
              {"view", "all floaters", "floaters in the object region"},
              {}};
  for (size_t v = 0; v < f.view_names.size(); ++v)
    views.rows.push_back({f.view_names[v], pct(f.view_floater_opacity_share[v]),
                          pct(f.view_region_floater_opacity_share[v])});
  if (views.rows.empty()) return {summary, objects};
  return {summary, objects, views};
}

}  // namespace eval
