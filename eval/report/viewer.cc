#include "eval/report/viewer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/checkpoint.h"
#include "splat/error.h"
#include "splat/label/object_ply.h"
#include "splat/label/palette.h"
#include "splat/label/vote_summary.h"
#include "splat/ply.h"
#include "splat/scene.h"
#include "splat/spz.h"

// The page files, bundled into the program by viewer_assets.S.
extern "C" {
extern const char op2gs_viewer_index_html[], op2gs_viewer_index_html_end[];
extern const char op2gs_viewer_viewer_js[], op2gs_viewer_viewer_js_end[];
extern const char op2gs_viewer_vendor_js[], op2gs_viewer_vendor_js_end[];
}

namespace eval {
namespace fs = std::filesystem;
using json = nlohmann::json;

std::vector<ViewerAsset> viewer_assets() {
  const auto bytes = [](const char* begin, const char* end) {
    return std::string_view(begin, size_t(end - begin));
  };
  return {{"index.html", bytes(op2gs_viewer_index_html, op2gs_viewer_index_html_end)},
          {"viewer.js", bytes(op2gs_viewer_viewer_js, op2gs_viewer_viewer_js_end)},
          {"vendor.min.js", bytes(op2gs_viewer_vendor_js, op2gs_viewer_vendor_js_end)}};
}

namespace {

void write_bytes(const fs::path& file, std::string_view bytes) {
  splat::write_atomically(file, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    out.close();
    if (!out) splat::throw_write_error(file);
  });
}

json camera_json(const splat::View& v, bool test) {
  const splat::Camera& c = v.camera;
  json r = json::array(), t = json::array();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r.push_back(c.R(i, j));
    t.push_back(c.t(i));
  }
  return {{"name", v.name}, {"width", c.width}, {"height", c.height}, {"fx", c.fx},
          {"fy", c.fy},     {"cx", c.cx},       {"cy", c.cy},         {"R", r},
          {"t", t},         {"test", test}};
}

json read_json_or_null(const fs::path& file) {
  if (file.empty() || !fs::exists(file)) return nullptr;
  try {
    return json::parse(splat::read_text_file(file));
  } catch (const json::exception& e) {
    throw splat::InputError(file, std::string("not valid JSON: ") + e.what());
  }
}

// j[key] when it is an integer (get<int>() of a float is undefined beyond
// int's range), else otherwise.
int integer_or(const json& j, const char* key, int otherwise) {
  const auto it = j.find(key);
  return it != j.end() && it->is_number_integer() ? int(it->get<int64_t>()) : otherwise;
}

// Per label: its name, the oracle queries it answers (with their IoU in each
// method) and the queries query mode chose it for.
json objects_json(const splat::GaussianModel& m, const json& metrics, const json& queries,
                  const std::map<int, std::string>& names) {
  std::map<int, size_t> counts;
  for (int32_t l : m.labels) ++counts[l];
  std::map<int, json> objects;
  for (const auto& [label, n] : counts) {
    const auto c = splat::label_color(label);
    objects[label] = {
        {"label", label},
        {"gaussians", n},
        {"color", {std::lround(255 * c[0]), std::lround(255 * c[1]), std::lround(255 * c[2])}},
        {"queries", json::array()},
        {"answers", json::array()}};
    if (names.count(label)) objects[label]["name"] = names.at(label);
  }
  if (metrics.is_object() && metrics.contains("results")) {
    for (const auto& [method, result] : metrics["results"].items()) {
      for (const json& q : result.value("queries", json::array())) {
        const int label = integer_or(q, "object", -1);
        if (!objects.count(label)) continue;
        json& list = objects[label]["queries"];
        auto it = std::find_if(list.begin(), list.end(),
                               [&](const json& e) { return e["query"] == q["query"]; });
        if (it == list.end()) it = list.insert(list.end(), json{{"query", q["query"]}});
        (*it)[method] = q.value("miou", 0.0);
      }
    }
  }
  if (queries.is_object() && queries.contains("queries")) {
    for (const json& q : queries["queries"]) {
      const int label = integer_or(q, "object", -1);
      if (objects.count(label)) objects[label]["answers"].push_back(q.value("query", ""));
    }
  }
  json out = json::array();
  for (auto& [label, o] : objects) out.push_back(std::move(o));
  return out;
}

// Per Gaussian: its label (uint16) and its sigma* (uint8), as gaussians.bin.
std::string label_bytes(const splat::GaussianModel& m) {
  std::string b(3 * m.size(), '\0');
  for (size_t i = 0; i < m.size(); ++i) {
    const uint16_t l = uint16_t(std::clamp(m.labels[i], 0, 65535));
    b[2 * i] = char(l & 0xff);
    b[2 * i + 1] = char(l >> 8);
    const float s = m.has_instance_opacity ? splat::sigmoid(m.instance_opacity_logits[i])
                                           : splat::sigmoid(m.opacity_logits[i]);
    b[2 * m.size() + i] = char(std::lround(255 * s));
  }
  return b;
}

// model.ply: a hard link to the stage-two PLY where it is the same model
// (no copy of a file that may hold a million Gaussians), else written.
void place_model_ply(const fs::path& target, const ViewerInput& in, const splat::GaussianModel& m) {
  std::error_code ec;
  if (!in.model_ply.empty() && fs::exists(in.model_ply) &&
      splat::read_gaussian_ply(in.model_ply) == m) {
    fs::remove(target, ec);
    fs::create_hard_link(in.model_ply, target, ec);
    if (!ec) return;
  }
  splat::write_gaussian_ply(target, m);
}

}  // namespace

fs::path latest_point_cloud(const fs::path& point_clouds) {
  fs::path best;
  long best_iteration = -1;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(point_clouds, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("iteration_", 0) != 0) continue;
    const long iteration = std::strtol(name.c_str() + 10, nullptr, 10);
    if (iteration > best_iteration && fs::exists(entry.path() / "point_cloud.ply")) {
      best_iteration = iteration;
      best = entry.path() / "point_cloud.ply";
    }
  }
  return best;
}

fs::path write_viewer(const fs::path& out, const ViewerInput& in) {
  splat::GaussianModel m = splat::read_model_file(in.model).model;
  if (!m.has_labels) throw splat::InputError(in.model, "the model has no labels (run op2gs-vote)");
  const auto scene = splat::Scene::load(in.scene, splat::SceneOptions{});
  const json metrics = read_json_or_null(in.metrics);
  std::map<std::string, bool> test;
  if (metrics.is_object())
    for (const json& v : metrics.value("test_views", json::array()))
      test[v.get<std::string>()] = true;

  const fs::path dir = out / in.name;
  fs::create_directories(dir);
  for (const ViewerAsset& a : viewer_assets())
    write_bytes(a.name == std::string("vendor.min.js") ? out / a.name : dir / a.name, a.bytes);
  splat::write_spz(dir / "model.spz", m);
  write_bytes(dir / "gaussians.bin", label_bytes(m));
  place_model_ply(dir / "model.ply", in, m);

  json cameras = json::array();
  for (const splat::View& v : scene->views()) cameras.push_back(camera_json(v, test.count(v.name)));
  const json about = {{"name", in.name},
                      {"gaussians", m.size()},
                      {"min_instance_opacity", splat::ObjectPlyOptions{}.min_instance_opacity},
                      {"background", {0, 0, 0}},
                      {"cameras", cameras},
                      {"objects", objects_json(m, metrics, read_json_or_null(in.queries),
                                               splat::read_vote_object_names(in.vote_summary))}};
  splat::write_text_atomically(dir / "scene.json", about.dump(1) + "\n");
  return fs::path("viewer") / in.name / "index.html";
}

}  // namespace eval
