// op2gs-eval: score predicted object masks of a scene (LERF-Mask protocol or
// the 3DOVS metric; oracle mode, and query mode given op2gs-query's answers),
// into metrics.json and a table on the terminal.

#include <fmt/format.h>

#include "eval/run/eval_run.h"
#include "stages/common.h"

int main(int argc, char** argv) {
  CLI::App app{"Score predicted object masks against a scene's ground truth (LERF-Mask layout)."};
  std::string scene, out;
  std::vector<std::string> predictions;
  app.add_option("scene", scene, "scene folder with test_mask/ (LERF-Mask layout)")->required();
  app.add_option("--pred", predictions,
                 "NAME=FOLDER of predictions: <stem>.png label maps or <stem>/<id>.png masks");
  app.add_option("--out", out, "metrics file to write")->required();
  std::string protocol = "auto";
  app.add_option("--protocol", protocol,
                 "lerf (test_mask/), 3dovs (segmentations/: the 3DOVS reference metric), "
                 "3dovs-lerf (the LERF-Mask script on 3DOVS masks, as the 3DGS papers), or auto")
      ->capture_default_str();
  int truth_width = 0;
  app.add_option("--truth-width", truth_width,
                 "LERF-Mask scoring: resize the ground truth to this width first (ObjectGS "
                 "scores 3DOVS at 1440)");
  std::string queries;
  app.add_option("--queries", queries,
                 "query.json of op2gs-query: also score in query mode (objects chosen by text)");
  std::string query_unavailable;
  app.add_option("--query-unavailable", query_unavailable,
                 "without --queries: why query mode could not run (reported as n/a)");
  std::string id_maps;
  app.add_option("--id-maps", id_maps,
                 "the ID map folder the run voted from (auto: as the stages choose), recorded in "
                 "metrics.json for the report to compare with the paper's matching figures");
  std::string renders, poses, true_poses;
  app.add_option("--renders", renders,
                 "rendered test views (<stem>.png): PSNR and SSIM against the scene's images/");
  app.add_option("--poses", poses, "a reconstruction (COLMAP model) to score against --true-poses");
  app.add_option("--true-poses", true_poses, "the true cameras (COLMAP model)");
  return stages::run_stage(app, argc, argv, [&] {
    eval::EvalRunOptions o;
    for (const std::string& p : predictions) {
      const size_t eq = p.find('=');
      if (eq == std::string::npos || eq == 0)
        throw std::invalid_argument("--pred must be NAME=FOLDER, not " + p);
      o.predictions.push_back({p.substr(0, eq), p.substr(eq + 1)});
    }
    o.protocol =
        stages::parse_choice<eval::Protocol>("--protocol", protocol,
                                             {{"auto", eval::Protocol::kAuto},
                                              {"lerf", eval::Protocol::kLerfMask},
                                              {"3dovs", eval::Protocol::kOvs},
                                              {"3dovs-lerf", eval::Protocol::kOvsLerfMask}});
    o.truth_width = truth_width;
    o.renders = renders;
    o.query_results = queries;
    o.query_unavailable = query_unavailable;
    o.id_maps = id_maps;
    o.poses = poses;
    o.true_poses = true_poses;
    if (poses.empty() != true_poses.empty())
      throw std::invalid_argument("--poses and --true-poses go together");
    const eval::EvalRunResult r = eval::run_evaluation(scene, out, o);
    const bool lerf = r.protocol != eval::Protocol::kOvs;
    if (!r.names.empty())
      fmt::print("{:<24} {:<7} {:>8} {:>8}   ({})\n", "predictions", "mode", "mIoU",
                 lerf ? "mBIoU" : "acc",
                 r.protocol == eval::Protocol::kOvs           ? "3DOVS reference metric"
                 : r.protocol == eval::Protocol::kOvsLerfMask ? "LERF-Mask script on 3DOVS masks"
                                                              : "LERF-Mask protocol");
    for (size_t i = 0; i < r.names.size(); ++i)
      fmt::print("{:<24} {:<7} {:>8.1f} {:>8.1f}\n", r.names[i], r.modes[i], 100 * r.miou[i],
                 100 * r.second[i]);
    if (!r.query_mode_unavailable.empty()) {
      for (size_t i = 0; i < r.names.size(); ++i)
        fmt::print("{:<24} {:<7} {:>8} {:>8}\n", r.names[i], "query", "n/a", "n/a");
      fmt::print("query mode not available: {}; scripts/get_clip.sh fetches CLIP ViT-B/16\n",
                 r.query_mode_unavailable);
    }
    if (r.psnr >= 0) fmt::print("test views: PSNR {:.2f} dB, SSIM {:.4f}\n", r.psnr, r.ssim);
    if (r.center_rmse >= 0)
      fmt::print("poses: camera-centre RMSE {:.5f}, rotation error {:.3f} deg\n", r.center_rmse,
                 r.rotation_error_deg);
    spdlog::info("per-view figures in {}", out);
  });
}
