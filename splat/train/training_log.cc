#include "splat/train/training_log.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "splat/atomic_file.h"
#include "splat/image.h"

namespace splat {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {
std::vector<json> read_records(const fs::path& file) {
  std::vector<json> records;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    // A run killed mid-write can leave a partial last line: skip it.
    json j = json::parse(line, nullptr, /*allow_exceptions=*/false);
    if (j.is_object() && j.contains("iteration")) records.push_back(std::move(j));
  }
  return records;
}
}  // namespace

TrainingLog::TrainingLog(const fs::path& file, int resume_iteration) : file_(file) {
  if (resume_iteration > 0)
    for (const json& j : read_records(file))
      if (j["iteration"].get<int>() <= resume_iteration) kept_ += j.dump() + "\n";
}

void TrainingLog::append(const std::string& line) {
  // The previous run's log is replaced only once this run has done an
  // iteration: a run that fails at its start leaves it as it was.
  if (!started_) write_text_atomically(file_, kept_), started_ = true;
  std::ofstream out(file_, std::ios::app);
  out << line << '\n';
}

void TrainingLog::record(const IterationStats& s, double elapsed) {
  json j = {{"iteration", s.iteration},     {"loss", s.loss.total},     {"l1", s.loss.l1},
            {"ssim", s.loss.ssim},          {"psnr", s.psnr},           {"gaussians", s.gaussians},
            {"lr_position", s.lr_position}, {"sh_degree", s.sh_degree}, {"elapsed_s", elapsed}};
  if (s.densified.cloned + s.densified.split + s.densified.pruned > 0)
    j["densify"] = {{"cloned", s.densified.cloned},
                    {"split", s.densified.split},
                    {"pruned", s.densified.pruned}};
  if (s.densified.held_back > 0) j["densify"]["held_back"] = s.densified.held_back;
  if (s.opacity_reset) j["opacity_reset"] = true;
  if (s.downscale != 1) j["downscale"] = s.downscale;
  if (s.half_view) j["half_view"] = true;
  if (s.threads > 0) j["threads"] = s.threads;
  if (!s.objects.empty()) j["object_loss"] = s.object_loss, j["objects"] = s.objects;
  append(j.dump());
}

void TrainingLog::record_test(int iteration, const std::vector<ViewMetrics>& metrics) {
  double p = 0, s = 0;
  for (const auto& m : metrics) p += m.psnr, s += m.ssim;
  const double n = std::max<size_t>(metrics.size(), 1);
  append(json({{"iteration", iteration}, {"test_psnr", p / n}, {"test_ssim", s / n}}).dump());
}

void plot_training_curve(const fs::path& jsonl, const fs::path& png) {
  const std::vector<json> records = read_records(jsonl);
  constexpr int W = 900, H = 420, L = 70, R = 70, T = 40, B = 50;
  cv::Mat canvas(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  std::vector<std::pair<double, double>> loss, train_psnr, test_psnr;
  for (const json& j : records) {
    const double it = j["iteration"].get<double>();
    if (j.contains("loss")) loss.emplace_back(it, j["loss"].get<double>());
    if (j.contains("psnr")) train_psnr.emplace_back(it, j["psnr"].get<double>());
    if (j.contains("test_psnr")) test_psnr.emplace_back(it, j["test_psnr"].get<double>());
  }
  double max_it = 1, max_loss = 1e-6, min_psnr = 1e9, max_psnr = -1e9;
  for (auto& [i, v] : loss) max_it = std::max(max_it, i), max_loss = std::max(max_loss, v);
  for (auto* series : {&train_psnr, &test_psnr})
    for (auto& [i, v] : *series) min_psnr = std::min(min_psnr, v), max_psnr = std::max(max_psnr, v);
  if (min_psnr > max_psnr) min_psnr = 0, max_psnr = 1;
  auto px = [&](double it) { return int(L + (W - L - R) * it / max_it); };
  auto py = [&](double v, double lo, double hi) {
    return int(H - B - (H - T - B) * (v - lo) / std::max(hi - lo, 1e-9));
  };
  cv::rectangle(canvas, {L, T}, {W - R, H - B}, cv::Scalar(0, 0, 0), 1);
  // Smoothed series: one point per ~W/2 iterations bucket.
  auto draw = [&](const std::vector<std::pair<double, double>>& s, double lo, double hi,
                  cv::Scalar color, int thick) {
    const size_t step = std::max<size_t>(1, s.size() / 400);
    std::vector<cv::Point> pts;
    for (size_t k = 0; k < s.size(); k += step) {
      double sum = 0;
      size_t n = 0;
      for (size_t j = k; j < std::min(s.size(), k + step); ++j) sum += s[j].second, ++n;
      pts.emplace_back(px(s[k].first), py(sum / n, lo, hi));
    }
    if (pts.size() > 1) cv::polylines(canvas, pts, false, color, thick, cv::LINE_AA);
    if (pts.size() == 1) cv::circle(canvas, pts[0], 4, color, cv::FILLED);
  };
  draw(loss, 0, max_loss, cv::Scalar(40, 40, 200), 1);
  draw(train_psnr, min_psnr, max_psnr, cv::Scalar(200, 120, 40), 1);
  for (auto& [i, v] : test_psnr)
    cv::circle(canvas, {px(i), py(v, min_psnr, max_psnr)}, 5, cv::Scalar(30, 160, 30), cv::FILLED);
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(canvas,
              "loss (red, left axis), train PSNR (blue) and test PSNR (green dots, right axis)",
              {L, 25}, font, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(canvas, fmt::format("{:.3f}", max_loss), {5, T + 5}, font, 0.45,
              cv::Scalar(40, 40, 200), 1, cv::LINE_AA);
  cv::putText(canvas, "0", {5, H - B}, font, 0.45, cv::Scalar(40, 40, 200), 1, cv::LINE_AA);
  cv::putText(canvas, fmt::format("{:.1f} dB", max_psnr), {W - R + 4, T + 5}, font, 0.45,
              cv::Scalar(200, 120, 40), 1, cv::LINE_AA);
  cv::putText(canvas, fmt::format("{:.1f} dB", min_psnr), {W - R + 4, H - B}, font, 0.45,
              cv::Scalar(200, 120, 40), 1, cv::LINE_AA);
  cv::putText(canvas, "iteration", {W / 2 - 30, H - 15}, font, 0.5, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  cv::putText(canvas, fmt::format("{}", int(max_it)), {W - R - 30, H - B + 18}, font, 0.45,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  ImageRGB image(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const cv::Vec3b bgr = canvas.at<cv::Vec3b>(y, x);
      float* p = image.pixel(x, y);
      p[0] = bgr[2] / 255.f, p[1] = bgr[1] / 255.f, p[2] = bgr[0] / 255.f;
    }
  write_image_rgb(png, image);
}

ProgressBar::ProgressBar(int start, int end, std::FILE* out)
    : start_(start),
      end_(end),
      out_(out),
      tty_(::isatty(::fileno(out))),
      t0_(std::chrono::steady_clock::now()) {}

void ProgressBar::update(const IterationStats& s) {
  ema_loss_ = ema_loss_ == 0 ? s.loss.total : 0.4 * s.loss.total + 0.6 * ema_loss_;
  ema_psnr_ = ema_psnr_ == 0 ? s.psnr : 0.4 * s.psnr + 0.6 * ema_psnr_;
  const int done = s.iteration - start_, total = end_ - start_;
  if (!tty_ && s.iteration % 500 != 0 && s.iteration != end_) return;
  if (tty_ && s.iteration % 10 != 0 && s.iteration != end_) return;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
  const double rate = done / std::max(elapsed, 1e-9);
  const double eta = (end_ - s.iteration) / std::max(rate, 1e-9);
  constexpr int kWidth = 24;
  const int filled = total > 0 ? kWidth * done / total : kWidth;
  const std::string bar = std::string(filled, '#') + std::string(kWidth - filled, '-');
  std::fprintf(out_,
               "%s[%s] %d/%d  loss %.4f  psnr %.2f dB  %zu gaussians  %.1f it/s  ETA %dm%02ds%s",
               tty_ ? "\r" : "", bar.c_str(), s.iteration, end_, ema_loss_, ema_psnr_, s.gaussians,
               rate, int(eta) / 60, int(eta) % 60, tty_ ? "" : "\n");
  std::fflush(out_);
}

void ProgressBar::finish() {
  if (tty_) std::fprintf(out_, "\n");
}

}  // namespace splat
