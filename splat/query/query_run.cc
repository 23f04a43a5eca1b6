#include "splat/query/query_run.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/clip/clip_model.h"
#include "splat/clip/tokenizer.h"
#include "splat/error.h"
#include "splat/json_integer.h"
#include "splat/query/embed_run.h"

namespace splat {
namespace fs = std::filesystem;
using json = nlohmann::json;

void QueryRunOptions::Check() const {
  if (queries.empty()) throw std::invalid_argument("no queries");
  if (templates.empty()) throw std::invalid_argument("no prompt templates");
  for (const std::string& t : templates)
    if (t.find("{}") == std::string::npos)
      throw std::invalid_argument(fmt::format("template \"{}\" has no {{}} for the query", t));
}

int32_t QueryResults::object_for(const std::string& query) const {
  for (const QueryAnswer& a : answers)
    if (a.query == query) return a.object;
  return -1;
}

namespace {

std::string fill(const std::string& templ, const std::string& query) {
  std::string text = templ;
  for (size_t at = text.find("{}"); at != std::string::npos;
       at = text.find("{}", at + query.size()))
    text.replace(at, 2, query);
  return text;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string quoted = "\"";
  for (char c : s) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace

QueryResults run_query(const fs::path& out, const QueryRunOptions& o) {
  o.Check();
  const ObjectEmbeddings objects = read_object_embeddings(o.embeddings);
  const ClipFiles files = ClipFiles::in(o.clip_dir);
  const ClipModel clip = ClipModel::load(files);
  const ClipTokenizer tokenizer(files.vocab, files.merges);
  if (objects.objects.front().embedding.size() != clip.embedding_size())
    throw InputError(o.embeddings,
                     fmt::format("embeddings have {} values, the CLIP model {}",
                                 objects.objects.front().embedding.size(), clip.embedding_size()));
  QueryResults results;
  results.full_size_clip = clip.is_full_size();
  if (!results.full_size_clip)
    spdlog::warn(
        "{} is far smaller than any released CLIP (the tests' tiny CLIP?): the answers "
        "mean nothing, and op2gs-eval will not score them; scripts/get_clip.sh fetches "
        "CLIP ViT-B/16",
        o.clip_dir.string());
  for (const ObjectEmbedding& obj : objects.objects) results.objects.push_back(obj.id);
  for (const std::string& query : o.queries) {
    Eigen::VectorXf text = Eigen::VectorXf::Zero(clip.embedding_size());
    for (const std::string& t : o.templates)
      text +=
          clip.encode_text(tokenizer.encode(fill(t, query), clip.context_length())).normalized();
    text.normalize();
    QueryAnswer a;
    a.query = query;
    a.similarity = -2;
    for (const ObjectEmbedding& obj : objects.objects) {
      const float s = text.dot(obj.embedding);
      a.similarities.push_back(s);
      if (s > a.similarity) a.similarity = s, a.object = obj.id;
    }
    results.answers.push_back(std::move(a));
  }

  json answers = json::array();
  std::string csv = "query";
  for (int32_t id : results.objects) csv += fmt::format(",{}", id);
  csv += "\n";
  for (const QueryAnswer& a : results.answers) {
    answers.push_back({{"query", a.query},
                       {"object", a.object},
                       {"similarity", a.similarity},
                       {"similarities", a.similarities}});
    csv += csv_field(a.query);
    for (float s : a.similarities) csv += fmt::format(",{:.6f}", s);
    csv += "\n";
  }
  const json j = {
      {"embeddings", o.embeddings.string()},
      {"clip", {{"folder", o.clip_dir.string()}, {"full_size", results.full_size_clip}}},
      {"templates", o.templates},
      {"objects", results.objects},
      {"queries", answers}};
  write_text_atomically(out / "query.json", j.dump(2) + "\n");
  write_text_atomically(out / "similarity.csv", csv);
  return results;
}

}  // namespace splat
