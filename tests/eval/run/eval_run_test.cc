// op2gs-eval's run on a small generated scene: its exact instance maps as
// predictions score perfectly, wrong query answers do not, and every figure
// lands in metrics.json.

#include "eval/run/eval_run.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "tests/tiny_scene.h"

namespace eval {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const fs::path& scenes() {
  static const fs::path dir = [] {
    const fs::path d = testing_util::process_temp_dir("eval_run");
    testing_util::generate_small_scene_in_both_layouts(d);
    return d;
  }();
  return dir;
}

// query.json as op2gs-query writes it; `shift` adds to every right answer.
fs::path write_answers(const fs::path& file, int shift) {
  const json objects = json::parse(splat::read_text_file(scenes() / "lerf" / "objects.json"));
  json queries = json::array();
  std::vector<int> ids;
  for (const json& o : objects) {
    queries.push_back({{"query", o.at("name")},
                       {"object", o.at("id").get<int>() + shift},
                       {"similarity", 0.3},
                       {"similarities", json::array()}});
    ids.push_back(o.at("id").get<int>());
  }
  splat::write_text_atomically(file, json{{"objects", ids}, {"queries", queries}}.dump());
  return file;
}

TEST(EvalRun, ExactPredictionsScorePerfectlyInBothModes) {
  const testing_util::TempDir tmp;
  EvalRunOptions o;
  o.predictions = {{"exact", scenes() / "lerf" / "instance_gt"}};
  o.query_results = write_answers(tmp / "query.json", 0);
  o.renders = scenes() / "lerf" / "images";
  const EvalRunResult r = run_evaluation(scenes() / "lerf", tmp / "metrics.json", o);
  EXPECT_EQ(r.protocol, Protocol::kLerfMask);
  ASSERT_EQ(r.names, (std::vector<std::string>{"exact", "exact"}));
  EXPECT_EQ(r.modes, (std::vector<std::string>{"oracle", "query"}));
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_GT(r.miou[i], 0.999) << r.modes[i];
    EXPECT_GT(r.second[i], 0.999) << r.modes[i];
  }
  EXPECT_GT(r.psnr, 60);  // the photos against themselves
  EXPECT_NEAR(r.ssim, 1.0, 1e-6);

  const json m = json::parse(splat::read_text_file(tmp / "metrics.json"));
  EXPECT_EQ(m["modes"], json({"oracle", "query"}));
  EXPECT_EQ(m["mask_geometry"], "views");
  EXPECT_DOUBLE_EQ(m["results"]["exact"]["miou"].get<double>(), r.miou[0]);
  EXPECT_DOUBLE_EQ(m["query_results"]["exact"]["miou"].get<double>(), r.miou[1]);
  EXPECT_EQ(m["test_views"].size(), 1u);  // views 0 of 6 (every 8th)
  EXPECT_TRUE(m.contains("image_quality"));
  EXPECT_EQ(m["layout"]["name"], "lerf-mask");
  EXPECT_FALSE(m.contains("test_views_without_ground_truth"));
}

// A test view whose test_mask/<k>/ is missing (teatime's view 1 as
// downloaded) is not scored, and metrics.json lists it.
TEST(EvalRun, TestViewWithoutGroundTruthIsListedNotScored) {
  const testing_util::TempDir tmp;
  const fs::path scene = tmp / "scene";
  fs::create_directories(scene);
  for (const char* d : {"images", "images_train", "test_mask", "instance_gt"})
    fs::create_directory_symlink(scenes() / "lerf" / d, scene / d);
  // A second test view, without ground truth: images/ gains a view that is
  // not in images_train/.
  fs::remove(scene / "images");
  fs::create_directories(scene / "images");
  for (const auto& f : fs::directory_iterator(scenes() / "lerf" / "images"))
    fs::create_symlink(f.path(), scene / "images" / f.path().filename());
  fs::create_symlink(scenes() / "lerf/images/frame_00001.png", scene / "images/frame_00001b.png");
  EvalRunOptions o;
  o.predictions = {{"exact", scenes() / "lerf" / "instance_gt"}};
  const EvalRunResult r = run_evaluation(scene, tmp / "metrics.json", o);
  EXPECT_GT(r.miou[0], 0.999);
  const json m = json::parse(splat::read_text_file(tmp / "metrics.json"));
  EXPECT_EQ(m["test_views"].size(), 2u);
  EXPECT_EQ(m["test_views_without_ground_truth"], json({"frame_00001b.png"}));
}

TEST(EvalRun, WrongQueryAnswersLowerOnlyTheQueryMode) {
  const testing_util::TempDir tmp;
  EvalRunOptions o;
  o.predictions = {{"exact", scenes() / "lerf" / "instance_gt"}};
  o.query_results = write_answers(tmp / "query.json", 1000);  // objects that do not exist
  const EvalRunResult r = run_evaluation(scenes() / "lerf", tmp / "metrics.json", o);
  ASSERT_EQ(r.miou.size(), 2u);
  EXPECT_GT(r.miou[0], 0.999);
  EXPECT_LT(r.miou[1], 0.01);
}

TEST(EvalRun, ScoresTheOvsLayoutWithItsReferenceMetric) {
  const testing_util::TempDir tmp;
  EvalRunOptions o;
  o.predictions = {{"exact", scenes() / "lerf" / "instance_gt"}};
  EXPECT_FALSE(benchmark_queries(scenes() / "ovs").empty());
  // The 3DOVS layout names its images NN.png; the LERF-layout maps do not
  // match them, which is an error naming what is missing rather than a score.
  EXPECT_THROW(run_evaluation(scenes() / "ovs", tmp / "metrics.json", o), splat::InputError);
  EXPECT_FALSE(fs::exists(tmp / "metrics.json"));
}

TEST(EvalRun, SceneWithoutGroundTruthIsAnErrorNamingIt) {
  const testing_util::TempDir tmp;
  fs::create_directories(tmp / "scene" / "images");
  EvalRunOptions o;
  o.predictions = {{"x", tmp / "pred"}};
  try {
    run_evaluation(tmp / "scene", tmp / "metrics.json", o);
    FAIL() << "expected InputError";
  } catch (const splat::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no ground truth"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(tmp / "metrics.json"));
}

}  // namespace
}  // namespace eval
