// Scoring a whole dataset run with op2gs-eval's library: 13 scenes of the
// sizes of LERF-Mask (3 scenes, 3 test views at 1440x1080, 7-10 queries, two
// prediction folders of 10 objects each) and 3DOVS (10 scenes, 5 segmented
// views with 4032x3024 ground truth, 4 classes per view, predictions at 1/4
// resolution, scored with the LERF-Mask script at 1440 px wide as the paper's
// table), in oracle and query mode. The files are written once, beforehand.
//
//   build/bench/eval_bench

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <fstream>
#include <random>

#include "eval/run/eval_run.h"
#include "splat/image.h"

namespace {

namespace fs = std::filesystem;

struct BenchScene {
  fs::path dir;
  eval::EvalRunOptions options;
};

// Random ellipses: one object's mask.
std::vector<uint8_t> ellipse_mask(int w, int h, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  const double cx = w * (0.2 + 0.6 * u(rng)), cy = h * (0.2 + 0.6 * u(rng));
  const double rx = w * (0.05 + 0.15 * u(rng)), ry = h * (0.05 + 0.15 * u(rng));
  std::vector<uint8_t> m(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      m[size_t(y) * w + x] = std::pow((x - cx) / rx, 2) + std::pow((y - cy) / ry, 2) < 1;
  return m;
}

void touch(const fs::path& f) {
  fs::create_directories(f.parent_path());
  std::ofstream(f) << "";
}

// Predictions of one view: masks of objects 1..10 at w x h.
void write_predictions(const fs::path& folder, const std::string& stem, int w, int h,
                       std::mt19937& rng) {
  for (int id = 1; id <= 10; ++id)
    splat::write_mask_png(folder / stem / (std::to_string(id) + ".png"), w, h,
                          ellipse_mask(w, h, rng));
}

void write_query_answers(const fs::path& file, const std::vector<std::string>& queries) {
  std::string j = "{\"objects\": [1,2,3,4,5,6,7,8,9,10], \"queries\": [";
  for (size_t i = 0; i < queries.size(); ++i)
    j += fmt::format(R"({}{{"query": "{}", "object": {}, "similarity": 0.3, "similarities": []}})",
                     i ? "," : "", queries[i], 1 + i % 10);
  std::ofstream(file) << j << "]}";
}

BenchScene lerf_scene(const fs::path& dir, int queries, std::mt19937& rng) {
  const int W = 1440, H = 1080;
  std::vector<std::string> names;
  for (int q = 0; q < queries; ++q) names.push_back("query " + std::to_string(q));
  for (int v = 0; v < 30; ++v) {
    const std::string name = "frame_" + std::to_string(1000 + v) + ".jpg";
    touch(dir / "images" / name);
    if (v % 10) touch(dir / "images_train" / name);
  }
  for (int k = 0; k < 3; ++k) {
    const std::string stem = "frame_" + std::to_string(1000 + 10 * k);
    for (const std::string& q : names)
      splat::write_mask_png(dir / "test_mask" / std::to_string(k) / (q + ".png"), W, H,
                            ellipse_mask(W, H, rng));
    write_predictions(dir / "pred_a", stem, W, H, rng);
    write_predictions(dir / "pred_b", stem, W, H, rng);
  }
  write_query_answers(dir / "query.json", names);
  BenchScene s{dir, {}};
  s.options.predictions = {{"dual", dir / "pred_a"}, {"baseline", dir / "pred_b"}};
  s.options.query_results = dir / "query.json";
  return s;
}

BenchScene ovs_scene(const fs::path& dir, std::mt19937& rng) {
  const int W = 4032, H = 3024;
  const std::vector<std::string> classes = {"a", "b", "c", "d"};
  fs::create_directories(dir / "segmentations");
  std::ofstream(dir / "segmentations" / "classes.txt") << "a\nb\nc\nd\n";
  for (int v = 0; v < 30; ++v) touch(dir / "images" / (std::to_string(10 + v) + ".jpg"));
  for (int i = 0; i < 5; ++i) {
    const int v = 6 * i;
    for (const std::string& c : classes)
      splat::write_mask_png(dir / "segmentations" / std::to_string(v) / (c + ".png"), W, H,
                            ellipse_mask(W, H, rng));
    write_predictions(dir / "pred_a", std::to_string(10 + v), W / 4, H / 4, rng);
    write_predictions(dir / "pred_b", std::to_string(10 + v), W / 4, H / 4, rng);
  }
  write_query_answers(dir / "query.json", classes);
  BenchScene s{dir, {}};
  s.options.predictions = {{"dual", dir / "pred_a"}, {"baseline", dir / "pred_b"}};
  s.options.query_results = dir / "query.json";
  s.options.protocol = eval::Protocol::kOvsLerfMask;
  s.options.truth_width = 1440;
  return s;
}

const std::vector<BenchScene>& dataset() {
  static const std::vector<BenchScene> scenes = [] {
    const fs::path root = fs::temp_directory_path() / "op2gs_eval_bench";
    fs::remove_all(root);
    std::mt19937 rng(3);
    std::vector<BenchScene> s;
    s.push_back(lerf_scene(root / "figurines", 7, rng));
    s.push_back(lerf_scene(root / "ramen", 6, rng));
    s.push_back(lerf_scene(root / "teatime", 10, rng));
    for (int i = 0; i < 10; ++i) s.push_back(ovs_scene(root / ("ovs" + std::to_string(i)), rng));
    return s;
  }();
  return scenes;
}

void BM_ScoreThirteenScenes(benchmark::State& state) {
  const auto& scenes = dataset();
  for (auto _ : state)
    for (const BenchScene& s : scenes)
      benchmark::DoNotOptimize(eval::run_evaluation(s.dir, s.dir / "metrics.json", s.options));
  state.counters["scenes"] = double(scenes.size());
}
BENCHMARK(BM_ScoreThirteenScenes)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
