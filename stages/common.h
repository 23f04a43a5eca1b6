#pragma once
// What every stage's main does around the library call: one-line errors on
// stderr and a non-zero exit for bad input, logging set up the same way.

#include <fcntl.h>
#include <spdlog/sinks/ansicolor_sink.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/view_split.h"
#include "splat/work_layout.h"

namespace stages {

// Peak resident memory of this process so far, in MiB.
inline double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
}

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
// (op2gs-train --refine-poses), "none" for the model's own.
inline void add_poses_option(CLI::App& app, std::string& poses) {
  app.add_option("--poses", poses,
                 "refined camera poses to use instead of the COLMAP model's (default: the "
                 "work folder's refined_poses.txt if a stage wrote one; none: the model's)");
}

// The pose file to use: the one given, else the first of the defaults that
// exists (logged), else none.
inline std::filesystem::path resolve_poses(const std::string& poses,
                                           const std::vector<std::filesystem::path>& defaults) {
  if (poses == "none") return {};
  if (!poses.empty()) return poses;
  for (const auto& file : defaults)
    if (std::filesystem::exists(file)) {
      spdlog::info("using the refined camera poses of {}", file.string());
      return file;
    }
  return {};
}

// Where op2gs-embed and op2gs-query look for the CLIP files when --clip is
// not given: $OP2GS_CLIP_DIR, else ~/.cache/op2gs/clip-vit-base-patch16
// (scripts/get_clip.sh downloads them there).
inline std::string default_clip_dir() {
  if (const char* dir = std::getenv("OP2GS_CLIP_DIR"); dir && *dir) return dir;
  const char* home = std::getenv("HOME");
  return std::string(home ? home : ".") + "/.cache/op2gs/clip-vit-base-patch16";
}

// Where a stage's output goes while it runs: its own messages (spdlog) to the
// terminal's stderr, one line each; what libraries print there themselves
// (libpng's "libpng error: ...", decoders' warnings) to the file named by
// $OP2GS_LIBRARY_LOG (pipeline/run_stage.sh sets it to the stage log), or
// nowhere: the stage's own error line already says what went wrong.
class StageOutput {
 public:
  StageOutput() : terminal_(::dup(2)) {
    if (terminal_ < 0) return;
    FILE* terminal = ::fdopen(terminal_, "w");
    if (!terminal) return;
    auto sink = std::make_shared<spdlog::sinks::ansicolor_sink<spdlog::details::console_mutex>>(
        terminal, spdlog::color_mode::automatic);
    spdlog::set_default_logger(std::make_shared<spdlog::logger>("op2gs", std::move(sink)));
    const char* log = std::getenv("OP2GS_LIBRARY_LOG");
    const int libraries = log && *log ? ::open(log, O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644)
                                      : ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (libraries >= 0) ::dup2(libraries, 2), ::close(libraries);
  }
  ~StageOutput() {
    std::fflush(stderr);
    spdlog::default_logger()->flush();
    if (terminal_ >= 0) ::dup2(terminal_, 2);
  }
  StageOutput(const StageOutput&) = delete;
  StageOutput& operator=(const StageOutput&) = delete;

 private:
  int terminal_;
};

// A message as one line: libraries' own error texts (OpenImageIO's) may
// hold several.
inline std::string one_line(std::string message) {
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  for (size_t p; (p = message.find('\n')) != std::string::npos;) message.replace(p, 1, "; ");
  return message;
}

// Parses the command line and runs body; returns the process exit code:
// 0 on success, 1 for bad input or a failed run, 2 for bad options.
inline int run_stage(CLI::App& app, int argc, char** argv, const std::function<void()>& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  const StageOutput output;
  spdlog::set_pattern("[%H:%M:%S] %v");
  try {
    body();
    spdlog::info("peak memory {:.0f} MiB", peak_rss_mib());
    return 0;
  } catch (const splat::InputError& e) {
    spdlog::error("{}", one_line(e.what()));
  } catch (const std::invalid_argument& e) {
    spdlog::error("invalid option: {}", one_line(e.what()));
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    spdlog::error("{}: {}", e.path1().string(), e.code().message());
  } catch (const std::exception& e) {
    spdlog::error("{}", one_line(e.what()));
  }
  return 1;
}

}  // namespace stages
