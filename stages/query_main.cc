// op2gs-query: answer text queries with the object whose CLIP embedding is
// most similar (cosine) to the query's CLIP text embedding.

#include <fstream>

#include "eval/run/eval_run.h"
#include "splat/clip/clip_model.h"
#include "splat/error.h"
#include "splat/query/query_run.h"
#include "stages/common.h"

namespace {

std::vector<std::string> read_lines(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw splat::InputError(file, "cannot open the query list");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) lines.push_back(line);
  }
  if (lines.empty()) throw splat::InputError(file, "the query list is empty (one query a line)");
  return lines;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Select the object of each text query by CLIP similarity."};
  splat::QueryRunOptions o;
  std::string work, embeddings, out, queries_file, scene, clip = splat::default_clip_dir().string();
  std::vector<std::string> templates;
  app.add_option("work", work, "work folder; reads <work>/embed/, writes <work>/query/")
      ->required();
  app.add_option("--query,-q", o.queries, "a text query (repeatable)");
  app.add_option("--queries", queries_file, "a file of queries, one a line");
  app.add_option("--scene", scene,
                 "a benchmark scene: its queries (LERF-Mask test_mask/ names, 3DOVS classes)");
  app.add_option("--template", templates,
                 "prompt template with {} for the query, e.g. \"a photo of a {}.\" (repeatable: "
                 "averaged); default: the query as typed");
  app.add_option("--embeddings", embeddings, "embeddings.json (default <work>/embed/)");
  app.add_option("--out", out, "output folder (default <work>/query)");
  app.add_option("--clip", clip, "CLIP folder, as for op2gs-embed")->capture_default_str();
  return stages::run_stage(app, argc, argv, [&] {
    const splat::WorkLayout w{work};
    if (!queries_file.empty())
      for (const std::string& q : read_lines(queries_file)) o.queries.push_back(q);
    if (!scene.empty())
      for (const std::string& q : eval::benchmark_queries(scene)) o.queries.push_back(q);
    if (!templates.empty()) o.templates = templates;
    o.embeddings = stages::or_default(embeddings, w.embeddings());
    o.clip_dir = clip;
    const std::filesystem::path dir = stages::or_default(out, w.query());
    const splat::QueryResults r = stages::write_staged(
        out, w.query(), [&](const std::filesystem::path& to) { return splat::run_query(to, o); });
    size_t width = 5;
    for (const auto& a : r.answers) width = std::max(width, a.query.size());
    fmt::print("{:<{}}  object  similarity\n", "query", width);
    for (const auto& a : r.answers)
      fmt::print("{:<{}}  {:>6}  {:>10.4f}\n", a.query, width, a.object, a.similarity);
    spdlog::info("{} queries over {} objects; outputs in {}", r.answers.size(), r.objects.size(),
                 dir.string());
  });
}
