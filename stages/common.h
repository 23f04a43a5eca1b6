#pragma once
// What every stage's main shares: the process around the library call
// (common.cc, compiled once: one-line errors on stderr and a non-zero exit for
// bad input, logging set up the same way, the peak memory), and the options
// several stages take.

#include <spdlog/spdlog.h>
#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/view_split.h"
#include "splat/work_layout.h"

namespace stages {

// Parses the command line and runs body; returns the process exit code:
// 0 on success, 1 for bad input or a failed run, 2 for bad options. While
// body runs, the stage's own messages go to the terminal one line each, and
// what libraries print there themselves to $OP2GS_LIBRARY_LOG (the stage log
// under make) or nowhere.
int run_stage(CLI::App& app, int argc, char** argv, const std::function<void()>& body);

// Peak resident memory of this process so far, in MiB.
double peak_rss_mib();

// Limits the worker threads of the library's parallel loops for as long as
// it lives (the --threads option; 0: all cores).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads) {
    if (threads > 0) limit_.emplace(tbb::global_control::max_allowed_parallelism, threads);
  }

 private:
  std::optional<tbb::global_control> limit_;
};

// An option that names one of a few choices (an enum): the value whose name
// was given. Throws std::invalid_argument "--option must be a, b or c"
// otherwise, which run_stage turns into exit status 2.
template <typename E>
E parse_choice(const std::string& option, const std::string& name,
               const std::vector<std::pair<std::string, E>>& choices) {
  std::string list;
  for (size_t i = 0; i < choices.size(); ++i) {
    if (choices[i].first == name) return choices[i].second;
    list += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + choices[i].first;
  }
  throw std::invalid_argument(option + " must be " + list);
}

// The --split option of the stages that read a scene's train/test split.
inline splat::SplitRule parse_split(const std::string& name) {
  return parse_choice<splat::SplitRule>("--split", name,
                                        {{"auto", splat::SplitRule::kAuto},
                                         {"lerf", splat::SplitRule::kLerfMask},
                                         {"segmented", splat::SplitRule::kSegmented},
                                         {"every8", splat::SplitRule::kEvery8},
                                         {"all", splat::SplitRule::kAll}});
}

// A path option whose default is a place in the work folder.
inline std::filesystem::path or_default(const std::string& given,
                                        const std::filesystem::path& fallback) {
  return given.empty() ? fallback : std::filesystem::path(given);
}

// An output folder the user named (--out) may hold other files; the default
// one in the work folder is the stage's alone.
inline splat::StagedFolder::Target staged_target(const std::string& given_out) {
  return given_out.empty() ? splat::StagedFolder::Target::kOwned
                           : splat::StagedFolder::Target::kShared;
}

// The options of every stage that reads a scene's views: --resolution,
// --images, --split and --threads.
inline void add_scene_options(
    CLI::App& app, splat::SceneOptions& scene, std::string& split, int& threads,
    const std::string& resolution_help = "downscale factor 1, 2, 4 or 8") {
  app.add_option("--resolution", scene.downscale, resolution_help)->capture_default_str();
  app.add_option("--images", scene.images_dir, "image folder inside the scene")
      ->capture_default_str();
  app.add_option("--split", split,
                 "train/test split: auto (from the scene's layout), lerf (images_train/), "
                 "segmented (3DOVS segmentations/ held out), every8, all")
      ->capture_default_str();
  app.add_option("--threads", threads, "worker threads (0: all cores)")->capture_default_str();
}

// --poses: a pose file (splat/pose_file.h) whose poses replace the COLMAP
// model's, by default the refined poses an earlier stage wrote
// (op2gs-train --refine-poses), "none" for the model's own; resolved by
// splat::choose_pose_file.
inline void add_poses_option(CLI::App& app, std::string& poses) {
  app.add_option("--poses", poses,
                 "refined camera poses to use instead of the COLMAP model's (default: the "
                 "work folder's refined_poses.txt if a stage wrote one; none: the model's)");
}

// Writes a stage's output folder: `write` fills a staging folder, which then
// replaces the target whole. The target is --out when given (a folder the
// user named, which may hold other files: only the entries written are
// replaced), else the stage's own place in the work folder.
template <typename Write>
auto write_staged(const std::string& given_out, const std::filesystem::path& default_out,
                  Write&& write) {
  splat::StagedFolder folder(or_default(given_out, default_out), staged_target(given_out));
  if constexpr (std::is_void_v<decltype(write(folder.path()))>) {
    write(folder.path());
    folder.commit();
  } else {
    auto result = write(folder.path());
    folder.commit();
    return result;
  }
}

}  // namespace stages
