#pragma once
// What every stage's main does around the library call: one-line errors on
// stderr and a non-zero exit for bad input, logging set up the same way.

#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <exception>
#include <functional>
#include <optional>

#include "splat/error.h"
#include "splat/train/trainer.h"

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

// The --split option of the stages that read a scene's train/test split.
inline splat::SplitRule parse_split(const std::string& name) {
  if (name == "auto") return splat::SplitRule::kAuto;
  if (name == "lerf") return splat::SplitRule::kLerfMask;
  if (name == "every8") return splat::SplitRule::kEvery8;
  if (name == "all") return splat::SplitRule::kAll;
  throw std::invalid_argument("--split must be auto, lerf, every8 or all");
}

// The options of every stage that reads a scene's views: --resolution,
// --images, --split and --threads.
inline void add_scene_options(
    CLI::App& app, splat::SceneOptions& scene, std::string& split, int& threads,
    const std::string& resolution_help = "downscale factor 1, 2, 4 or 8") {
  app.add_option("--resolution", scene.downscale, resolution_help)->capture_default_str();
  app.add_option("--images", scene.images_dir, "image folder inside the scene")
      ->capture_default_str();
  app.add_option("--split", split, "train/test split: auto, lerf (images_train/), every8, all")
      ->capture_default_str();
  app.add_option("--threads", threads, "worker threads (0: all cores)")->capture_default_str();
}

// Where op2gs-embed and op2gs-query look for the CLIP files when --clip is
// not given: $OP2GS_CLIP_DIR, else ~/.cache/op2gs/clip-vit-base-patch16
// (scripts/get_clip.sh downloads them there).
inline std::string default_clip_dir() {
  if (const char* dir = std::getenv("OP2GS_CLIP_DIR"); dir && *dir) return dir;
  const char* home = std::getenv("HOME");
  return std::string(home ? home : ".") + "/.cache/op2gs/clip-vit-base-patch16";
}

// Parses the command line and runs body; returns the process exit code:
// 0 on success, 1 for bad input or a failed run, 2 for bad options.
inline int run_stage(CLI::App& app, int argc, char** argv, const std::function<void()>& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  spdlog::set_pattern("[%H:%M:%S] %v");
  try {
    body();
    spdlog::info("peak memory {:.0f} MiB", peak_rss_mib());
    return 0;
  } catch (const splat::InputError& e) {
    spdlog::error("{}", e.what());
  } catch (const std::invalid_argument& e) {
    spdlog::error("invalid option: {}", e.what());
    return 2;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
  return 1;
}

}  // namespace stages
