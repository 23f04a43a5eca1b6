#pragma once
// op2gs-query: open-vocabulary retrieval (paper, "Open-Vocabulary Query").
// Each text query is embedded with CLIP's text encoder and compared by cosine
// similarity with every object embedding of op2gs-embed; the object with the
// highest similarity is the answer. Writes query.json (per query: the chosen
// object, its similarity, and the similarity to every object) and
// similarity.csv (the same table, one row per query).
//
// Prompt handling: the query text goes through CLIP's tokenizer (ClipTokenizer:
// NFC, HTML unescaping, whitespace clean-up, lower-casing, 77 tokens at most).
// By default the text is embedded as typed, as LERF, LangSplat and the works
// the paper follows do; with templates (CLIP's "a photo of a {}."), each
// template is filled with the query, and the normalised text embeddings are
// averaged (CLIP's prompt ensembling).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace splat {

struct QueryRunOptions {
  std::filesystem::path embeddings;  // embeddings.json of op2gs-embed
  std::filesystem::path clip_dir;    // as for op2gs-embed
  std::vector<std::string> queries;
  std::vector<std::string> templates = {"{}"};  // "{}" stands for the query
  void Check() const;                           // throws std::invalid_argument
};

struct QueryAnswer {
  std::string query;
  int32_t object = 0;
  float similarity = 0;
  std::vector<float> similarities;  // per object of QueryResults::objects
};

struct QueryResults {
  std::vector<int32_t> objects;
  std::vector<QueryAnswer> answers;
  // Whether the answers come from a CLIP of a released size
  // (ClipModel::is_full_size); the tiny test CLIP's are not to be scored.
  bool full_size_clip = true;
  // The object chosen for a query, or -1 when the query was not asked.
  int32_t object_for(const std::string& query) const;
};

// Answers every query and writes query.json and similarity.csv into out.
QueryResults run_query(const std::filesystem::path& out, const QueryRunOptions& options);

// Reads query.json. Throws InputError naming the file when malformed.
QueryResults read_query_results(const std::filesystem::path& file);

}  // namespace splat
