#include "eval/floaters/floaters_run.h"

#include <fmt/format.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "splat/atomic_file.h"
#include "splat/checkpoint.h"
#include "splat/error.h"

namespace study {
namespace fs = std::filesystem;
using json = nlohmann::json;

void FloaterRunOptions::Check() const {
  scene.Check();
  floaters.Check();
  if (model.empty()) throw std::invalid_argument("the model is not set");
}

namespace {

synth::World read_surfaces(const fs::path& file) {
  if (!fs::exists(file))
    throw splat::InputError(file, "missing: floaters are measured on op2gs-synth scenes only");
  try {
    std::ifstream in(file);
    return synth::world_from_json(json::parse(in));
  } catch (const std::exception& e) {
    throw splat::InputError(file, e.what());
  }
}

json report_json(const FloaterReport& r, const synth::World& world,
                 const std::vector<std::string>& view_names) {
  std::map<int32_t, std::string> names;
  for (const synth::SceneObject& o : world.objects) names[o.id] = o.name;
  json objects = json::array();
  for (const ObjectContamination& c : r.objects) {
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
    if (names.count(c.id)) o["name"] = names[c.id];
    objects.push_back(o);
  }
  json per_view = json::array();
  for (size_t v = 0; v < r.view_floater_opacity_share.size(); ++v)
    per_view.push_back({{"view", view_names.at(v)},
                        {"floater_opacity_share", r.view_floater_opacity_share[v]},
                        {"region_floater_opacity_share", r.view_region_floater_opacity_share[v]}});
  return {
      {"distance", r.distance},
      {"gaussians", r.gaussians},
      {"floaters", r.floaters},
      {"floater_share", r.gaussians ? double(r.floaters) / r.gaussians : 0.0},
      {"floaters_labelled", r.floaters_labelled},
      {"region",
       {{"gaussians", r.region_gaussians},
        {"floaters", r.region_floaters},
        {"floater_opacity_share", r.region_floater_opacity_share}}},
      {"views", view_names.size()},
      {"floater_opacity_share", r.floater_opacity_share},
      {"per_view", per_view},
      {"mask_floater_share",
       {{"sigma", r.mask_floater_share_sigma}, {"sigma_star", r.mask_floater_share_sigma_star}}},
      {"mask_wrong_share",
       {{"sigma", r.mask_wrong_share_sigma}, {"sigma_star", r.mask_wrong_share_sigma_star}}},
      {"objects", objects}};
}

}  // namespace

FloaterReport run_floaters(const fs::path& scene_dir, const fs::path& out_file,
                           const FloaterRunOptions& o) {
  o.Check();
  const synth::World world = read_surfaces(scene_dir / "surfaces.json");
  const splat::CheckpointModel model = splat::read_model_file(o.model);
  if (!model.model.has_labels)
    throw splat::InputError(o.model, "the model has no labels (run op2gs-vote first)");
  std::vector<splat::Camera> views;
  std::vector<std::string> view_names;
  if (o.render) {
    const auto scene = splat::Scene::load(scene_dir, o.scene);
    for (size_t v : splat::split_views(*scene, o.split).test) {
      views.push_back(scene->views()[v].camera);
      view_names.push_back(scene->views()[v].name);
    }
  }
  const FloaterReport r = measure_floaters(model.model, world, views, o.floaters);
  splat::write_text_atomically(out_file, report_json(r, world, view_names).dump(2) + "\n");
  return r;
}

}  // namespace study
