#pragma once
// What a training run shows and leaves behind: a progress line on the
// terminal, a JSON-lines log for plots, and a PNG of the training curve.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "splat/train/trainer.h"

namespace splat {

// Appends one JSON object per line. On resume, lines past the checkpoint's
// iteration (work that was lost) are dropped first.
class TrainingLog {
 public:
  TrainingLog(const std::filesystem::path& file, int resume_iteration);
  void record(const IterationStats& s, double elapsed_seconds);
  void record_test(int iteration, const std::vector<ViewMetrics>& metrics);

 private:
  void append(const std::string& line);
  std::filesystem::path file_;
  std::string kept_;  // the lines of a resumed run up to its checkpoint
  bool started_ = false;
};

// Loss and PSNR against iteration from a JSON-lines log, as a PNG.
void plot_training_curve(const std::filesystem::path& jsonl, const std::filesystem::path& png);

// A one-line progress bar: iteration, loss, PSNR, Gaussians, it/s, ETA.
// Redraws in place on a terminal; prints a line every `every` iterations
// otherwise (logs, CI). On stdout: a stage's stderr carries its messages
// only (docs/reliability.md).
class ProgressBar {
 public:
  ProgressBar(int start, int end, std::FILE* out = stdout);
  void update(const IterationStats& s);
  void finish();

 private:
  int start_, end_;
  std::FILE* out_;
  bool tty_;
  double ema_loss_ = 0, ema_psnr_ = 0;
  std::chrono::steady_clock::time_point t0_;
};

}  // namespace splat
