#include "splat/label/vote_summary.h"

#include <fmt/format.h>

#include <fstream>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/json_integer.h"

namespace splat {
namespace fs = std::filesystem;
using json = nlohmann::json;

std::map<int, std::string> read_object_names(const fs::path& file) {
  std::map<int, std::string> names;
  if (!fs::exists(file)) return names;
  try {
    std::ifstream in(file);
    const json j = json::parse(in);
    if (j.is_array())
      for (const auto& o : j)
        names[json_integer<int>(o.at("id"), file, "id")] = o.at("name").get<std::string>();
    else if (j.is_object())
      for (const auto& [k, v] : j.items()) names[std::stoi(k)] = v.get<std::string>();
  } catch (const std::exception& e) {
    throw InputError(file, fmt::format("not a list of object names ([{{\"id\": 1, \"name\": "
                                       "\"mug\"}}] or {{\"1\": \"mug\"}}): {}",
                                       e.what()));
  }
  return names;
}

nlohmann::json vote_summary_json(const GaussianModel& model, const LabelVotes& votes,
                                 const std::map<int, size_t>& views_per_id,
                                 const std::map<int, std::string>& names, VoteRunResult& r) {
  std::map<int, size_t> gaussians_per_label;
  std::map<int, double> agreement_per_label;
  size_t unseen = 0, voted = 0;
  double agreement = 0;
  for (size_t j = 0; j < model.size(); ++j) {
    ++gaussians_per_label[model.labels[j]];
    const uint32_t n = votes.votes(j);
    if (!n) {
      ++unseen;
      continue;
    }
    const double a = double(votes.votes_for_label(j)) / n;
    agreement += a, ++voted;
    agreement_per_label[model.labels[j]] += a;
  }
  const double total = std::max<size_t>(model.size(), 1);
  r.gaussians = model.size();
  r.background_share = gaussians_per_label[0] / total;
  r.unseen_share = unseen / total;
  r.vote_agreement = voted ? agreement / voted : 0;
  nlohmann::json objects = nlohmann::json::array();
  std::map<int, bool> ids;
  for (const auto& [id, n] : views_per_id) ids[id] = true;
  for (const auto& [id, n] : gaussians_per_label) ids[id] = true;
  for (const auto& [id, _] : ids) {
    const size_t n = gaussians_per_label.count(id) ? gaussians_per_label[id] : 0;
    if (id != 0 && n) ++r.objects;
    nlohmann::json o = {{"id", id},
                        {"gaussians", n},
                        {"views", views_per_id.count(id) ? views_per_id.at(id) : 0},
                        {"vote_agreement", n ? nlohmann::json(agreement_per_label[id] / n)
                                             : nlohmann::json(nullptr)}};
    if (names.count(id)) o["name"] = names.at(id);
    objects.push_back(o);
  }
  return {{"gaussians", r.gaussians},
          {"objects_found", r.objects},
          {"background_share", r.background_share},
          {"unseen_share", r.unseen_share},
          {"vote_agreement", r.vote_agreement},
          {"objects", objects}};
}

std::map<int, std::string> read_vote_object_names(const fs::path& summary_json) {
  std::map<int, std::string> names;
  if (!fs::exists(summary_json)) return names;
  json summary;
  try {
    summary = json::parse(read_text_file(summary_json));
  } catch (const json::exception& e) {
    throw InputError(summary_json, std::string("not valid JSON: ") + e.what());
  }
  if (!summary.is_object()) return names;
  for (const json& o : summary.value("objects", json::array()))
    if (o.is_object() && o.contains("id") && o.contains("name") && o["name"].is_string())
      names[json_integer<int>(o["id"], summary_json, "id")] = o["name"].get<std::string>();
  return names;
}

}  // namespace splat
