// op2gs-viewer: the 3D viewer of one scene's labelled model, without a report.
// A report needs scores, and a scene of your own photos has no ground truth to
// score against; this stage gives it the same viewer (eval/report/viewer.h):
// the model, its objects by name (the ID maps' objects.json, through
// op2gs-vote), and the answers to its queries when op2gs-query ran.

#include "eval/report/viewer.h"
#include "stages/common.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{"Write the 3D viewer of a scene's stage-two model."};
  std::string scene, work_dir, out, name;
  app.add_option("scene", scene, "scene folder (the cameras)")->required();
  app.add_option("work", work_dir, "work folder (learn/, vote/, query/)")->required();
  app.add_option("--out", out, "output folder (default <work>/viewer)");
  app.add_option("--name", name, "the scene's name in the page (default: the work folder's)");
  return stages::run_stage(app, argc, argv, [&] {
    const splat::WorkLayout work{work_dir};
    eval::ViewerInput in;
    in.name = name.empty() ? fs::absolute(work.root).lexically_normal().filename().string() : name;
    if (in.name.empty()) in.name = "scene";
    in.scene = scene;
    in.model = work.stage_two().latest_checkpoint();
    if (!fs::exists(in.model))
      throw splat::InputError(in.model, "no stage-two checkpoint (run op2gs-learn first)");
    in.model_ply = eval::latest_point_cloud(work.stage_two().point_clouds());
    in.queries = work.query_results();
    in.vote_summary = work.vote_summary();
    const fs::path target = stages::or_default(out, work.viewer());
    stages::write_staged(out, work.viewer(),
                         [&](const fs::path& to) { eval::write_viewer(to, in); });
    const fs::path served = target.parent_path();
    spdlog::info("viewer: {}", (target / in.name / "index.html").string());
    spdlog::info(
        "browsers load it from a local web server: python3 -m http.server -d {} 8000, "
        "then open http://localhost:8000/{}/{}/",
        served.string(), target.filename().string(), in.name);
  });
}
