#include "eval/floaters/floaters_run.h"

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

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
  FloaterReport r = measure_floaters(model.model, world, views, o.floaters);
  r.view_names = view_names;
  eval::write_floater_report(out_file, r);
  return r;
}

}  // namespace study
