#include "splat/train/training_log.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/image.h"
#include "tests/test_util.h"

namespace splat {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::vector<json> read_lines(const fs::path& file) {
  std::vector<json> lines;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
  return lines;
}

IterationStats stats(int iteration) {
  IterationStats s;
  s.iteration = iteration;
  s.loss.total = 0.5 / iteration;
  s.psnr = 20 + iteration * 0.01;
  s.gaussians = 1000 + size_t(iteration);
  return s;
}

TEST(TrainingLog, OneJsonObjectPerIterationAndTestEvaluation) {
  const testing_util::TempDir tmp;
  const fs::path file = tmp / "train_log.jsonl";
  {
    TrainingLog log(file, 0);
    IterationStats s = stats(1);
    s.opacity_reset = true;
    s.densified.cloned = 4;
    s.objects = {2, 5};
    s.object_loss = 0.25;
    log.record(s, 0.5);
    log.record(stats(2), 1.0);
    log.record_test(2, {{"a.png", 30.0, 0.9}, {"b.png", 20.0, 0.7}});
  }
  const std::vector<json> lines = read_lines(file);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0]["iteration"], 1);
  EXPECT_TRUE(lines[0]["opacity_reset"].get<bool>());
  EXPECT_EQ(lines[0]["densify"]["cloned"], 4);
  EXPECT_EQ(lines[0]["objects"], json({2, 5}));
  EXPECT_FALSE(lines[1].contains("opacity_reset"));
  EXPECT_FALSE(lines[1].contains("densify"));
  EXPECT_EQ(lines[1]["gaussians"], 1002);
  EXPECT_DOUBLE_EQ(lines[2]["test_psnr"].get<double>(), 25.0);
  EXPECT_DOUBLE_EQ(lines[2]["test_ssim"].get<double>(), 0.8);
}

TEST(TrainingLog, ResumeDropsWhatCameAfterTheCheckpointAndAPartialLine) {
  const testing_util::TempDir tmp;
  const fs::path file = tmp / "train_log.jsonl";
  {
    TrainingLog log(file, 0);
    for (int i = 1; i <= 5; ++i) log.record(stats(i), i);
  }
  std::ofstream(file, std::ios::app) << R"({"iteration": 6, "lo)";  // killed mid-write
  {
    const std::string before = splat::read_text_file(file);
    TrainingLog resumed(file, 3);
    EXPECT_EQ(splat::read_text_file(file), before);  // untouched until the resumed run records
    resumed.record(stats(4), 4);
  }
  const std::vector<json> lines = read_lines(file);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[2]["iteration"], 3);
  EXPECT_EQ(lines.back()["iteration"], 4);
  {  // a new run starts an empty log, once it has done an iteration
    TrainingLog fresh(file, 0);
    EXPECT_EQ(read_lines(file).size(), 4u);  // a run that fails at its start loses nothing
    fresh.record(stats(1), 1);
  }
  EXPECT_EQ(read_lines(file).size(), 1u);
}

TEST(TrainingLog, PlotsTheCurveAsAnImage) {
  const testing_util::TempDir tmp;
  {
    TrainingLog log(tmp / "train_log.jsonl", 0);
    for (int i = 1; i <= 50; ++i) log.record(stats(i), i);
    log.record_test(50, {{"a.png", 24.0, 0.8}});
  }
  plot_training_curve(tmp / "train_log.jsonl", tmp / "curve.png");
  const ImageRGB image = read_image_rgb(tmp / "curve.png");
  EXPECT_EQ(image.width, 900);
  EXPECT_EQ(image.height, 420);
  size_t coloured = 0;  // the curves are drawn in colour on white
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const float* p = image.pixel(x, y);
      coloured += std::abs(p[0] - p[2]) > 0.3f;
    }
  EXPECT_GT(coloured, 100u);
}

TEST(ProgressBar, PrintsALineEvery500IterationsAndAtTheEndWhenNotATerminal) {
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  ProgressBar bar(0, 1200, out);
  for (int i = 1; i <= 1200; ++i) bar.update(stats(i));
  bar.finish();
  std::rewind(out);
  std::string text;
  for (int c; (c = std::fgetc(out)) != EOF;) text += char(c);
  std::fclose(out);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 3);  // 500, 1000, 1200
  EXPECT_NE(text.find("500/1200"), std::string::npos);
  EXPECT_NE(text.find("1200/1200"), std::string::npos);
  EXPECT_NE(text.find("[########################]"), std::string::npos);
  EXPECT_EQ(text.find('\r'), std::string::npos);
}

}  // namespace
}  // namespace splat
