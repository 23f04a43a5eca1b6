// Stage two end to end on a tiny synthetic scene: stage one, voting,
// op2gs-learn's run (with resume), op2gs-render's outputs and the object
// operations.

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/report/report.h"
#include "eval/run/eval_run.h"
#include "splat/colmap_model.h"
#include "splat/dataset_layout.h"
#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/label/object_ply.h"
#include "splat/label/render_run.h"
#include "splat/label/vote_run.h"
#include "splat/npy.h"
#include "splat/photo_cameras.h"
#include "splat/ply.h"
#include "splat/pose_file.h"
#include "splat/query/embed_run.h"
#include "splat/query/query_run.h"
#include "splat/scene.h"
#include "splat/train/object_loss.h"
#include "splat/train/train_run.h"
#include "splat/train/trainer.h"
#include "splat/view_split.h"
#include "splat/work_layout.h"
#include "synth/generator.h"
#include "tests/test_util.h"
#include "tests/tiny_clip.h"
#include "tests/tiny_scene.h"

namespace splat {
namespace {

namespace fs = std::filesystem;
using testing_util::TempDir;

constexpr int kStageOne = 300;

// The tiny scene, stage one to 300 iterations and voting; made once.
const fs::path& stage_one_work() {
  static const fs::path dir = [] {
    const fs::path d = testing_util::generate_tiny_scene("stage_two");
    fs::rename(d, d.string() + "_scene");
    fs::create_directories(d);
    fs::rename(d.string() + "_scene", d / "scene");
    TrainRunOptions t;
    t.stop_at = kStageOne;
    t.train.total_iterations = 1000;
    t.train.densify_from = 100;
    t.train.densify_every = 50;
    run_training(d / "scene", d / "work", t);
    VoteRunOptions vote;
    vote.model = WorkLayout{d / "work"}.stage_one().latest_checkpoint();
    run_voting(d / "scene", WorkLayout{d / "work"}.vote(), vote);
    return d;
  }();
  return dir;
}
fs::path scene() { return stage_one_work() / "scene"; }

TrainRunOptions learn_options(int stop_at) {
  TrainRunOptions o;
  o.stop_at = stop_at;
  o.train.total_iterations = 1000;
  o.train.densify_until = 0;
  o.train.object_loss.weight = 0.1f;
  o.checkpoint_every = 50;
  o.start_checkpoint = stage_one_work() / "work/checkpoints/latest.ckpt";
  o.labels_model = stage_one_work() / "work/vote/point_cloud.ply";
  return o;
}

TEST(StageTwo, LearnsSigmaStarWithTheObjectLossAndResumesExactly) {
  TempDir a, b;
  run_training(scene(), a / "learn", learn_options(400));
  const GaussianModel m = read_gaussian_ply(a / "learn/point_cloud/iteration_400/point_cloud.ply");
  const GaussianModel stage_one = read_gaussian_ply(stage_one_work() / "work/vote/point_cloud.ply");
  ASSERT_TRUE(m.has_instance_opacity && m.has_labels);
  EXPECT_EQ(m.size(), stage_one.size());  // no densification in stage two
  EXPECT_EQ(m.labels, stage_one.labels);
  EXPECT_NE(m.instance_opacity_logits, m.opacity_logits);  // sigma* moved away from sigma
  std::ifstream log(a / "learn/train_log.jsonl");
  std::string line;
  int with_object_loss = 0;
  while (std::getline(log, line))
    with_object_loss += nlohmann::json::parse(line).contains("object_loss");
  EXPECT_EQ(with_object_loss, 100);

  // Stopped at 350 and resumed: the same model as the uninterrupted run.
  run_training(scene(), b / "learn", learn_options(350));
  TrainRunOptions resume = learn_options(400);
  resume.resume = true;
  run_training(scene(), b / "learn", resume);
  EXPECT_EQ(read_gaussian_ply(b / "learn/point_cloud/iteration_400/point_cloud.ply"), m);
}

// A position learning rate hold that reaches past stage one's end holds in
// stage two too, and metrics.json records it.
TEST(StageTwo, KeepsAPositionRateHoldAndRecordsIt) {
  TempDir a;
  TrainRunOptions o = learn_options(320);
  o.train.lr_position_hold_until = 500;
  run_training(scene(), a / "learn", o);
  std::ifstream log(a / "learn/train_log.jsonl");
  std::string line;
  std::vector<double> rates;
  while (std::getline(log, line))
    if (const auto j = nlohmann::json::parse(line); j.contains("lr_position"))
      rates.push_back(j["lr_position"].get<double>());
  ASSERT_EQ(rates.size(), 20u);
  EXPECT_EQ(rates.front(), rates.back());
  const auto metrics = nlohmann::json::parse(std::ifstream(a / "learn/metrics.json"));
  EXPECT_EQ(metrics["position_lr_hold_until"], 500);
}

// Stage two continues stage one's random stream; a seed starts another (the
// views' order and the objects sampled differ), and a resumed run goes on
// with its checkpoint's.
TEST(StageTwo, ASeedStartsAnotherRandomStream) {
  TempDir a, b, c;
  run_training(scene(), a / "learn", learn_options(380));
  TrainRunOptions seeded = learn_options(380);
  seeded.train.seed = 7;
  run_training(scene(), b / "learn", seeded);
  const auto model = [](const TempDir& work) {
    return read_gaussian_ply(work / "learn/point_cloud/iteration_380/point_cloud.ply");
  };
  EXPECT_FALSE(model(a) == model(b));
  seeded.stop_at = 350;  // a checkpoint
  run_training(scene(), c / "learn", seeded);
  seeded.stop_at = 380;
  seeded.resume = true;
  run_training(scene(), c / "learn", seeded);
  EXPECT_EQ(model(c), model(b));
}

// Decoding the views and ID maps up front, on all cores, changes no step.
TEST(StageTwo, PreloadingTheInputsChangesNoStep) {
  const TrainRunOptions o = learn_options(0);
  const std::vector<int32_t> labels = read_gaussian_ply(o.labels_model).labels;
  auto start = [&] {
    auto t = std::make_unique<Trainer>(scene(), o.train);
    t->load_checkpoint(o.start_checkpoint);
    t->start_instance_learning(labels);
    return t;
  };
  const auto preloaded = start(), lazy = start();
  const Trainer::Preloaded p = preloaded->preload_training_inputs();
  EXPECT_EQ(p.views, preloaded->split().train.size());
  EXPECT_EQ(p.id_maps, preloaded->split().train.size());
  EXPECT_EQ(preloaded->scene().cache().loads(), p.views);
  preloaded->train_until(kStageOne + 20);
  lazy->train_until(kStageOne + 20);
  EXPECT_EQ(preloaded->scene().cache().loads(), p.views) << "no view decoded twice";
  EXPECT_TRUE(preloaded->model() == lazy->model());
}

// With --protect-agreement, the sigma* of every Gaussian whose votes agree
// enough stays at least its sigma; the others still learn to leave the
// masks, and a resumed run reads the agreement again.
TEST(StageTwo, ProtectedGaussiansNeverLoseInstanceOpacity) {
  TempDir a;
  TrainRunOptions o = learn_options(350);
  o.train.object_loss.protected_agreement = 0.9f;
  o.train.object_loss.label_agreement = WorkLayout{stage_one_work() / "work"}.label_agreement();
  run_training(scene(), a / "learn", o);
  o.stop_at = 400;
  o.resume = true;
  run_training(scene(), a / "learn", o);
  const GaussianModel m = read_gaussian_ply(a / "learn/point_cloud/iteration_400/point_cloud.ply");
  const std::vector<uint8_t> kept =
      read_protected_gaussians(o.train.object_loss.label_agreement, 0.9f, m.size());
  size_t protected_count = 0, fell = 0;
  for (size_t i = 0; i < m.size(); ++i) {
    if (kept[i]) {
      ++protected_count;
      EXPECT_GE(m.instance_opacity_logits[i], m.opacity_logits[i]) << "Gaussian " << i;
    } else {
      fell += m.instance_opacity_logits[i] < m.opacity_logits[i];
    }
  }
  EXPECT_GT(protected_count, m.size() / 2);
  EXPECT_GT(fell, 0u);  // the unprotected still learn to leave the masks
  // An agreement file of another model is named.
  write_npy_f64(a / "short.npy", {1.0, 1.0}, {2});
  o.resume = false;
  o.stop_at = 350;
  o.train.object_loss.label_agreement = a / "short.npy";
  EXPECT_THROW(run_training(scene(), a / "other", o), InputError);
}

// With --sigma-star-only the masks reach sigma* alone. Two runs whose masks
// differ inside the objects (every other column of each object cleared; the
// same objects in every view, so the same objects are sampled) end with the
// same geometry, colours and sigma, bit for bit, and a different sigma*; with
// the paper's loss the geometry differs too.
TEST(StageTwo, SigmaStarOnlyLeavesTheGeometryToThePhotos) {
  TempDir t;
  const fs::path maps = scene() / resolve_id_map_folder(scene(), "auto");
  fs::create_directories(t / "striped");
  size_t cleared = 0;
  for (const auto& entry : fs::directory_iterator(maps)) {
    if (entry.path().extension() != ".png") {  // objects.json
      fs::copy_file(entry.path(), t / "striped" / entry.path().filename());
      continue;
    }
    const IdMap map = read_id_map(entry.path());
    IdMap striped = map;
    for (int y = 0; y < map.height; ++y)
      for (int x = 0; x < map.width; x += 2) striped.at(x, y) = 0;
    if (objects_in_map(striped) != objects_in_map(map)) striped = map;  // an object would vanish
    for (size_t i = 0; i < map.ids.size(); ++i) cleared += striped.ids[i] != map.ids[i];
    write_id_map(t / "striped" / entry.path().filename(), striped, 16);
  }
  ASSERT_GT(cleared, 1000u);
  auto learn = [&](const std::string& name, const fs::path& id_maps, bool reshapes_geometry) {
    TrainRunOptions o = learn_options(330);
    o.train.object_loss.id_maps = id_maps.string();
    o.train.object_loss.reshapes_geometry = reshapes_geometry;
    run_training(scene(), t / name, o);
    return read_gaussian_ply(t / name / "point_cloud/iteration_330/point_cloud.ply");
  };
  const GaussianModel a = learn("a", maps, false), b = learn("b", t / "striped", false);
  EXPECT_EQ(a.means, b.means);
  EXPECT_EQ(a.log_scales, b.log_scales);
  EXPECT_EQ(a.rotations, b.rotations);
  EXPECT_EQ(a.sh_dc, b.sh_dc);
  EXPECT_EQ(a.sh_rest, b.sh_rest);
  EXPECT_EQ(a.opacity_logits, b.opacity_logits);
  EXPECT_NE(a.instance_opacity_logits, b.instance_opacity_logits);
  const GaussianModel c = learn("c", maps, true), d = learn("d", t / "striped", true);
  EXPECT_NE(c.means, d.means);
  EXPECT_NE(c.means, a.means);
  const nlohmann::json metrics = nlohmann::json::parse(std::ifstream(t / "a/metrics.json"));
  EXPECT_EQ(metrics["object_loss"]["reshapes_geometry"], false);
}

TEST(StageTwo, LabelsOfAnotherModelAreRejected) {
  TempDir a;
  GaussianModel other = read_gaussian_ply(stage_one_work() / "work/vote/point_cloud.ply");
  other.means[0] += 1;
  write_gaussian_ply(a / "other.ply", other);
  TrainRunOptions o = learn_options(400);
  o.labels_model = a / "other.ply";
  EXPECT_THROW(run_training(scene(), a / "learn", o), InputError);
}

TEST(StageTwo, RendersMasksLabelMapsAndObjectModels) {
  TempDir a;
  run_training(scene(), a / "learn", learn_options(350));
  RenderRunOptions r;
  r.model = a / "learn/checkpoints/latest.ckpt";
  r.object_images = r.occupancy = true;
  const RenderTiming t = run_render(scene(), a / "render", r);
  EXPECT_EQ(t.views, 2u);  // the test views 0 and 8
  for (const char* f :
       {"rgb/frame_00000.png", "masks_color/frame_00008.png", "instance_labels/frame_00000.png",
        "baseline_labels_color/frame_00008.png", "timing.json"})
    EXPECT_TRUE(fs::exists(a / "render" / f)) << f;
  size_t masks = 0;
  for (const auto& f : fs::directory_iterator(a / "render/masks/frame_00000")) {
    ++masks;
    EXPECT_TRUE(fs::exists(a / "render/occupancy/frame_00000" / f.path().filename()));
    EXPECT_TRUE(fs::exists(a / "render/objects/frame_00000" / f.path().filename()));
  }
  EXPECT_GE(masks, 8u);  // one per object label

  // The evaluation reads both forms of prediction.
  eval::EvalRunOptions e;
  e.predictions = {{"dual", a / "render/masks"}, {"baseline", a / "render/baseline_labels"}};
  const eval::EvalRunResult scores = eval::run_evaluation(scene(), a / "metrics.json", e);
  ASSERT_EQ(scores.miou.size(), 2u);
  EXPECT_GT(scores.miou[0], 0.3);  // a very short run, but well above chance
  EXPECT_TRUE(fs::exists(a / "metrics.json"));
  eval::EvalRunOptions quality;
  quality.renders = a / "render/rgb";
  quality.poses = quality.true_poses = scene() / "sparse/0";
  const eval::EvalRunResult q = eval::run_evaluation(scene(), a / "quality.json", quality);
  EXPECT_GT(q.psnr, 15.0);  // rendered test views against the photos
  EXPECT_GT(q.ssim, 0.3);
  EXPECT_LT(q.center_rmse, 1e-9);  // the true cameras against themselves

  // One object, and the scene without it, partition the model.
  const GaussianModel m = read_model_file(r.model).model;
  const GaussianModel object = select_object(m, 1, 0.1f);
  const GaussianModel rest = remove_object(m, 1, 0.1f);
  EXPECT_GT(object.size(), 0u);
  EXPECT_EQ(object.size() + rest.size(), m.size());
  for (int32_t l : object.labels) EXPECT_EQ(l, 1);
}

TEST(StageTwo, FitsThePosesOfTheViewsWithoutARefinedPose) {
  TempDir a;
  run_training(scene(), a / "learn", learn_options(320));
  // The training views' poses as a stage with --refine-poses writes them.
  const auto s = Scene::load(scene(), SceneOptions{});
  const ViewSplit split = split_views(*s, SplitRule::kAuto);
  std::vector<NamedPose> refined;
  for (size_t v : split.train)
    refined.push_back({s->views()[v].name, s->views()[v].camera.R, s->views()[v].camera.t});
  write_pose_file(a / "refined_poses.txt", refined);
  RenderRunOptions r;
  r.model = a / "learn/checkpoints/latest.ckpt";
  r.views = RenderViews::kAll;
  r.scene.poses = a / "refined_poses.txt";
  r.fit_poses.iterations = 20;
  run_render(scene(), a / "render", r);
  const std::vector<NamedPose> fitted = read_pose_file(a / "render/fitted_poses.txt");
  ASSERT_EQ(fitted.size(), split.test.size());  // the test views only
  for (size_t k = 0; k < fitted.size(); ++k) {
    const Camera& given = s->views()[split.test[k]].camera;
    EXPECT_EQ(fitted[k].name, s->views()[split.test[k]].name);
    // The photos are renders of the true cameras: the fit moves little.
    EXPECT_LT((fitted[k].t - given.t).norm(), 0.05 * s->extent());
  }
}

// --photo-geometry moves the masks into the photos' cameras. Photos whose
// OPENCV cameras have no distortion are the views themselves, so the moved
// masks and label maps must be the rendered ones, pixel for pixel.
TEST(StageTwo, PhotoGeometryMasksMatchTheViewsWhenThePhotosHaveNoDistortion) {
  TempDir a;
  fs::create_directories(a / "scene");
  for (const auto& f : fs::directory_iterator(scene()))
    fs::create_symlink(f.path(), a / "scene" / f.path().filename());
  ColmapModel photos = read_colmap_model(scene() / "sparse/0");
  for (auto& [id, cam] : photos.cameras) {
    ASSERT_EQ(cam.model_id, 1);  // PINHOLE fx fy cx cy
    cam.model_id = 4;            // OPENCV, k1 k2 p1 p2 = 0
    cam.params.insert(cam.params.end(), {0, 0, 0, 0});
  }
  write_colmap_model(photos, a / "scene" / kPhotoCamerasDir, ColmapFormat::kBinary);

  run_training(scene(), a / "learn", learn_options(320));
  RenderRunOptions r;
  r.model = a / "learn/checkpoints/latest.ckpt";
  r.photo_geometry = PhotoGeometryMode::kAuto;
  run_render(a / "scene", a / "render", r);
  size_t compared = 0;
  for (const char* stem : {"frame_00000", "frame_00008"}) {
    for (const auto& f : fs::directory_iterator(a / "render/masks" / stem)) {
      const fs::path moved = a / "render/photo/masks" / stem / f.path().filename();
      ASSERT_TRUE(fs::exists(moved)) << moved;
      EXPECT_EQ(testing_util::read_file(moved), testing_util::read_file(f.path())) << moved;
      ++compared;
    }
    const std::string labels = std::string("instance_labels/") + stem + ".png";
    EXPECT_EQ(read_id_map(a / "render/photo" / labels).ids, read_id_map(a / "render" / labels).ids);
  }
  EXPECT_GE(compared, 16u);

  // Without the photos' cameras, auto writes no photo/ folder, and on is an
  // error naming the folder.
  run_render(scene(), a / "render2", r);
  EXPECT_TRUE(fs::exists(a / "render2/masks"));
  EXPECT_FALSE(fs::exists(a / "render2/photo"));
  r.photo_geometry = PhotoGeometryMode::kOn;
  try {
    run_render(scene(), a / "render3", r);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(kPhotoCamerasDir), std::string::npos) << e.what();
  }
}

// op2gs-embed, op2gs-query and the evaluation's query mode with the tiny CLIP
// of tests/fixtures (random weights: the plumbing is tested, not retrieval).
TEST(StageTwo, EmbedsObjectsAnswersQueriesAndScoresQueryMode) {
  TempDir a;
  run_training(scene(), a / "learn", learn_options(320));
  const fs::path clip = testing_util::tiny_clip_dir();
  EmbedRunOptions e;
  e.model = a / "learn/checkpoints/latest.ckpt";
  e.clip_dir = clip;
  e.views_per_object = 3;
  e.min_mask_pixels = 16;
  const ObjectEmbeddings embeddings = run_embed(scene(), a / "embed", e);
  ASSERT_GE(embeddings.objects.size(), 6u);
  for (const ObjectEmbedding& obj : embeddings.objects) {
    EXPECT_NEAR(obj.embedding.norm(), 1.0f, 1e-5f);
    ASSERT_FALSE(obj.views.empty());
    EXPECT_LE(obj.views.size(), 3u);
    for (size_t k = 0; k + 1 < obj.views.size(); ++k)
      EXPECT_GE(obj.views[k].area, obj.views[k + 1].area);  // the largest masks
    for (const ObjectView& v : obj.views) EXPECT_TRUE(fs::exists(a / "embed" / v.crop)) << v.crop;
  }
  const ObjectEmbeddings back = read_object_embeddings(a / "embed/embeddings.json");
  ASSERT_EQ(back.objects.size(), embeddings.objects.size());
  EXPECT_TRUE(back.objects[0].embedding.isApprox(embeddings.objects[0].embedding, 1e-6f));

  QueryRunOptions q;
  q.embeddings = a / "embed/embeddings.json";
  q.clip_dir = clip;
  q.queries = eval::benchmark_queries(scene());
  ASSERT_FALSE(q.queries.empty());
  const QueryResults answers = run_query(a / "query", q);
  ASSERT_EQ(answers.answers.size(), q.queries.size());
  for (const QueryAnswer& ans : answers.answers) {
    EXPECT_EQ(ans.similarities.size(), embeddings.objects.size());
    EXPECT_FLOAT_EQ(ans.similarity,
                    *std::max_element(ans.similarities.begin(), ans.similarities.end()));
  }
  EXPECT_TRUE(fs::exists(a / "query/similarity.csv"));
  EXPECT_FALSE(answers.full_size_clip);
  EXPECT_FALSE(read_query_results(a / "query/query.json").full_size_clip);

  // The tiny CLIP's answers are not scored: query mode is "not available",
  // with the reason and the command that fetches the real CLIP.
  RenderRunOptions r;
  r.model = e.model;
  run_render(scene(), a / "render", r);
  eval::EvalRunOptions ev;
  ev.predictions = {{"dual", a / "render/masks"}};
  ev.query_results = a / "query/query.json";
  const eval::EvalRunResult unscored = eval::run_evaluation(scene(), a / "tiny.json", ev);
  EXPECT_EQ(unscored.modes, (std::vector<std::string>{"oracle"}));
  EXPECT_NE(unscored.query_mode_unavailable.find("tiny"), std::string::npos);
  const auto tiny = nlohmann::json::parse(testing_util::read_file(a / "tiny.json"));
  EXPECT_FALSE(tiny["query_mode"]["available"].get<bool>());
  EXPECT_NE(tiny["query_mode"]["fetch"].get<std::string>().find("scripts/get_clip.sh"),
            std::string::npos);
  EXPECT_FALSE(tiny.contains("query_results"));
  EXPECT_EQ(tiny["modes"], nlohmann::json({"oracle"}));

  // The same answers, as if a released CLIP had given them: the plumbing of
  // query mode is scored.
  auto released = nlohmann::json::parse(testing_util::read_file(a / "query/query.json"));
  released["clip"]["full_size"] = true;
  testing_util::write_file(a / "released_query.json", released.dump());
  ev.query_results = a / "released_query.json";
  const eval::EvalRunResult scores = eval::run_evaluation(scene(), a / "metrics.json", ev);
  ASSERT_EQ(scores.modes, (std::vector<std::string>{"oracle", "query"}));
  EXPECT_LE(scores.miou[1], scores.miou[0] + 1e-12);  // the oracle is an upper bound
  const auto metrics = nlohmann::json::parse(testing_util::read_file(a / "metrics.json"));
  EXPECT_EQ(metrics["query_results"]["dual"]["queries"].size(),
            metrics["results"]["dual"]["queries"].size());
  for (const auto& row : metrics["query_results"]["dual"]["queries"])
    EXPECT_EQ(row["object"].get<int32_t>(), answers.object_for(row["query"]));

  // Query mode with the oracle's own choices reproduces the oracle's score.
  nlohmann::json oracle_answers = {{"objects", answers.objects},
                                   {"queries", nlohmann::json::array()}};
  for (const auto& row : metrics["results"]["dual"]["queries"])
    oracle_answers["queries"].push_back({{"query", row["query"]},
                                         {"object", row["object"]},
                                         {"similarity", 1.0},
                                         {"similarities", nlohmann::json::array()}});
  testing_util::write_file(a / "oracle_query.json", oracle_answers.dump());
  ev.query_results = a / "oracle_query.json";
  const eval::EvalRunResult same = eval::run_evaluation(scene(), a / "metrics2.json", ev);
  EXPECT_DOUBLE_EQ(same.miou[1], same.miou[0]);

  // The report of the tiny CLIP's scores: query columns marked n/a, with the
  // reason, instead of numbers.
  {
    fs::create_directories(a / "tiny_work/eval");
    fs::copy_file(a / "tiny.json", a / "tiny_work/eval/metrics.json");
    eval::ReportOptions tiny_report;
    tiny_report.scenes = {{"tiny", scene(), a / "tiny_work/eval/metrics.json", {}, {}, {}}};
    const std::string tiny_md =
        testing_util::read_file(eval::write_report(a / "tiny_report", tiny_report).markdown);
    EXPECT_NE(tiny_md.find("dual (query) mIoU"), std::string::npos) << tiny_md;
    EXPECT_NE(tiny_md.find("| n/a | n/a |"), std::string::npos) << tiny_md;
    EXPECT_NE(tiny_md.find("Query mode: not available"), std::string::npos) << tiny_md;
    EXPECT_NE(tiny_md.find("scripts/get_clip.sh"), std::string::npos) << tiny_md;
  }

  // The report of this scene: oracle and query rows side by side, figures,
  // and a page that headless Chromium renders (not blank).
  fs::create_directories(a / "work/eval");
  fs::copy_file(a / "metrics.json", a / "work/eval/metrics.json");
  eval::ReportOptions report;
  report.scenes = {{"tiny",
                    scene(),
                    a / "work/eval/metrics.json",
                    a / "render",
                    {a / "learn/training_curve.png"},
                    a / "query/query.json"}};
  const eval::ReportFiles files = eval::write_report(a / "report", report);
  const std::string md = testing_util::read_file(files.markdown);
  EXPECT_NE(md.find("dual (oracle) mIoU"), std::string::npos) << md;
  EXPECT_NE(md.find("dual (query) mIoU"), std::string::npos);
  const std::string html = testing_util::read_file(files.html);
  EXPECT_NE(html.find("data:image/jpeg;base64,"), std::string::npos);
  EXPECT_NE(html.find("instance label map"), std::string::npos);
  const fs::path shot = a / "screenshot.png";
  const std::string chromium = fs::exists("/usr/bin/chromium") ? "/usr/bin/chromium" : "chromium";
  const int rc = std::system(("timeout 120 " + chromium +
                              " --headless --no-sandbox --disable-gpu --hide-scrollbars "
                              "--window-size=1200,1600 --screenshot=" +
                              shot.string() + " file://" + files.html.string() + " >/dev/null 2>&1")
                                 .c_str());
  ASSERT_EQ(rc, 0) << "headless Chromium failed; install it with scripts/setup.sh --tests";
  const ImageRGB page = read_image_rgb(shot);
  size_t dark = 0, colored = 0;
  for (size_t p = 0; p < size_t(page.width) * page.height; ++p) {
    const float* c = &page.data[3 * p];
    dark += c[0] + c[1] + c[2] < 1.5f;
    colored += std::max({c[0], c[1], c[2]}) - std::min({c[0], c[1], c[2]}) > 0.2f;
  }
  EXPECT_GT(dark, size_t(page.width) * page.height / 100);      // text, tables, photos
  EXPECT_GT(colored, size_t(page.width) * page.height / 1000);  // the embedded figures
}

}  // namespace
}  // namespace splat
