#pragma once
// What a vote found, as op2gs-vote writes it into vote/summary.json (per
// object its Gaussians, views, vote agreement and name), and the objects'
// names: written here from the ID maps' objects.json, read back here by what
// shows the objects (the 3D viewer).

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "splat/gaussians.h"
#include "splat/label/vote.h"
#include "splat/label/vote_run.h"

namespace splat {

// Names of the IDs from the ID maps' objects.json: [{"id": 1, "name": ...}]
// or {"1": "name"}. The file is optional (no names); a file that is there
// must be right (InputError naming it).
std::map<int, std::string> read_object_names(const std::filesystem::path& objects_json);

// summary.json's content; fills r's counts and shares.
nlohmann::json vote_summary_json(const GaussianModel& model, const LabelVotes& votes,
                                 const std::map<int, size_t>& views_per_id,
                                 const std::map<int, std::string>& names, VoteRunResult& r);

// The names in a vote's summary.json (none when there is no such file).
// Throws InputError naming a file that is not valid JSON.
std::map<int, std::string> read_vote_object_names(const std::filesystem::path& summary_json);

}  // namespace splat
