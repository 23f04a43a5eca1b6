#include "eval/metrics/floater_report.h"

#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/error.h"

namespace eval {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

json object_json(const ObjectContamination& c) {
  json o = {
      {"id", c.id},
      {"gaussians", c.gaussians},
      {"wrong", c.wrong},
      {"labelled", c.labelled},
      {"labelled_wrongly", c.labelled_wrongly},
      {"labelled_floaters", c.labelled_floaters},
      {"labelled_border", c.labelled_border},
      {"sigma", {{"right", c.mean_sigma_right}, {"wrong", c.mean_sigma_wrong}}},
      {"sigma_star", {{"right", c.mean_sigma_star_right}, {"wrong", c.mean_sigma_star_wrong}}}};
  if (!c.name.empty()) o["name"] = c.name;
  return o;
}

ObjectContamination object_from_json(const json& o) {
  ObjectContamination c;
  c.id = o.at("id").get<int32_t>();
  c.name = o.value("name", "");
  c.gaussians = o.at("gaussians").get<size_t>();
  c.wrong = o.at("wrong").get<size_t>();
  c.labelled = o.at("labelled").get<size_t>();
  c.labelled_wrongly = o.at("labelled_wrongly").get<size_t>();
  c.labelled_floaters = o.at("labelled_floaters").get<size_t>();
  c.labelled_border = o.at("labelled_border").get<size_t>();
  c.mean_sigma_right = o.at("sigma").at("right").get<double>();
  c.mean_sigma_wrong = o.at("sigma").at("wrong").get<double>();
  c.mean_sigma_star_right = o.at("sigma_star").at("right").get<double>();
  c.mean_sigma_star_wrong = o.at("sigma_star").at("wrong").get<double>();
  return c;
}

}  // namespace

void write_floater_report(const fs::path& file, const FloaterReport& r) {
  json objects = json::array();
  for (const ObjectContamination& c : r.objects) objects.push_back(object_json(c));
  json per_view = json::array();
  for (size_t v = 0; v < r.view_floater_opacity_share.size(); ++v)
    per_view.push_back({{"view", v < r.view_names.size() ? r.view_names[v] : std::to_string(v)},
                        {"floater_opacity_share", r.view_floater_opacity_share[v]},
                        {"region_floater_opacity_share", r.view_region_floater_opacity_share[v]}});
  const json j = {
      {"distance", r.distance},
      {"gaussians", r.gaussians},
      {"floaters", r.floaters},
      {"floater_share", r.gaussians ? double(r.floaters) / r.gaussians : 0.0},
      {"floaters_labelled", r.floaters_labelled},
      {"region",
       {{"gaussians", r.region_gaussians},
        {"floaters", r.region_floaters},
        {"floater_opacity_share", r.region_floater_opacity_share}}},
      {"views", r.view_floater_opacity_share.size()},
      {"floater_opacity_share", r.floater_opacity_share},
      {"per_view", per_view},
      {"mask_floater_share",
       {{"sigma", r.mask_floater_share_sigma}, {"sigma_star", r.mask_floater_share_sigma_star}}},
      {"mask_wrong_share",
       {{"sigma", r.mask_wrong_share_sigma}, {"sigma_star", r.mask_wrong_share_sigma_star}}},
      {"objects", objects}};
  splat::write_text_atomically(file, j.dump(2) + "\n");
}

FloaterReport read_floater_report(const fs::path& file) {
  try {
    const json j = json::parse(splat::read_text_file(file));
    FloaterReport r;
    r.distance = j.at("distance").get<double>();
    r.gaussians = j.at("gaussians").get<size_t>();
    r.floaters = j.at("floaters").get<size_t>();
    r.floaters_labelled = j.at("floaters_labelled").get<size_t>();
    r.region_gaussians = j.at("region").at("gaussians").get<size_t>();
    r.region_floaters = j.at("region").at("floaters").get<size_t>();
    r.region_floater_opacity_share = j.at("region").at("floater_opacity_share").get<double>();
    r.floater_opacity_share = j.at("floater_opacity_share").get<double>();
    r.mask_floater_share_sigma = j.at("mask_floater_share").at("sigma").get<double>();
    r.mask_floater_share_sigma_star = j.at("mask_floater_share").at("sigma_star").get<double>();
    r.mask_wrong_share_sigma = j.at("mask_wrong_share").at("sigma").get<double>();
    r.mask_wrong_share_sigma_star = j.at("mask_wrong_share").at("sigma_star").get<double>();
    for (const json& v : j.value("per_view", json::array())) {
      r.view_names.push_back(v.at("view").get<std::string>());
      r.view_floater_opacity_share.push_back(v.at("floater_opacity_share").get<double>());
      r.view_region_floater_opacity_share.push_back(
          v.at("region_floater_opacity_share").get<double>());
    }
    for (const json& o : j.at("objects")) r.objects.push_back(object_from_json(o));
    return r;
  } catch (const json::exception& e) {
    throw splat::InputError(file, std::string("not an op2gs-floaters report: ") + e.what());
  }
}

}  // namespace eval
