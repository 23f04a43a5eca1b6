// The readers of the files op2gs-embed and op2gs-query write
// (embeddings.json, query.json), apart from the runs that write them: they
// need only the core, so the evaluation, the report and the fuzz harness
// read them without the renderer or CLIP.

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/json_integer.h"
#include "splat/query/embed_run.h"
#include "splat/query/query_run.h"

namespace splat {
namespace fs = std::filesystem;
using json = nlohmann::json;

ObjectEmbeddings read_object_embeddings(const fs::path& file) {
  ObjectEmbeddings e;
  try {
    const json j = json::parse(read_text_file(file));
    e.clip_dir = j.at("clip").get<std::string>();
    for (const json& obj : j.at("objects")) {
      ObjectEmbedding o;
      o.id = json_integer<int32_t>(obj.at("id"), file, "id");
      for (const json& v : obj.at("views"))
        o.views.push_back({v.at("view").get<std::string>(),
                           json_integer<int64_t>(v.at("area"), file, "area"),
                           v.at("crop").get<std::string>()});
      const auto values = obj.at("embedding").get<std::vector<float>>();
      o.embedding = Eigen::Map<const Eigen::VectorXf>(values.data(), Eigen::Index(values.size()));
      e.objects.push_back(std::move(o));
    }
    if (j.contains("unseen")) e.unseen = json_integers<int32_t>(j["unseen"], file, "unseen");
  } catch (const json::exception& ex) {
    throw InputError(file, std::string("not an op2gs-embed embeddings file: ") + ex.what());
  }
  if (e.objects.empty()) throw InputError(file, "holds no object embeddings");
  const Eigen::Index size = e.objects.front().embedding.size();
  for (const ObjectEmbedding& o : e.objects)
    if (o.embedding.size() != size || size == 0)
      throw InputError(file, fmt::format("object {}: embedding size differs", o.id));
  return e;
}

QueryResults read_query_results(const fs::path& file) {
  QueryResults r;
  try {
    const json j = json::parse(read_text_file(file));
    r.objects = json_integers<int32_t>(j.at("objects"), file, "objects");
    if (j.contains("clip")) r.full_size_clip = j["clip"].at("full_size").get<bool>();
    for (const json& q : j.at("queries"))
      r.answers.push_back(
          {q.at("query").get<std::string>(), json_integer<int32_t>(q.at("object"), file, "object"),
           q.at("similarity").get<float>(), q.at("similarities").get<std::vector<float>>()});
  } catch (const json::exception& e) {
    throw InputError(file, std::string("not an op2gs-query result: ") + e.what());
  }
  return r;
}

}  // namespace splat
