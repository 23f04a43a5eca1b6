// op2gs-eval: score predicted object masks of a scene with the LERF-Mask
// protocol (oracle mode), into metrics.json and a table on the terminal.

#include <fmt/format.h>

#include "eval/run/eval_run.h"
#include "stages/common.h"

int main(int argc, char** argv) {
  CLI::App app{"Score predicted object masks against a scene's ground truth (LERF-Mask layout)."};
  std::string scene, out;
  std::vector<std::string> predictions;
  app.add_option("scene", scene, "scene folder with test_mask/ (LERF-Mask layout)")->required();
  app.add_option("--pred", predictions,
                 "NAME=FOLDER of predictions: <stem>.png label maps or <stem>/<id>.png masks")
      ->required();
  app.add_option("--out", out, "metrics file to write")->required();
  return stages::run_stage(app, argc, argv, [&] {
    eval::EvalRunOptions o;
    for (const std::string& p : predictions) {
      const size_t eq = p.find('=');
      if (eq == std::string::npos || eq == 0)
        throw std::invalid_argument("--pred must be NAME=FOLDER, not " + p);
      o.predictions.push_back({p.substr(0, eq), p.substr(eq + 1)});
    }
    const eval::EvalRunResult r = eval::run_evaluation(scene, out, o);
    fmt::print("{:<24} {:>8} {:>8}\n", "predictions (oracle)", "mIoU", "mBIoU");
    for (size_t i = 0; i < r.names.size(); ++i)
      fmt::print("{:<24} {:>8.1f} {:>8.1f}\n", r.names[i], 100 * r.scores[i].miou,
                 100 * r.scores[i].mbiou);
    spdlog::info("per-view figures in {}", out);
  });
}
