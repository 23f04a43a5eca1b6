// op2gs-vote's library run on a tiny synthetic scene: outputs, the summary,
// and the errors for missing and mismatched ID maps.

#include "splat/label/vote_run.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/npy.h"
#include "splat/ply.h"
#include "splat/train/initialize.h"
#include "synth/generator.h"
#include "tests/test_util.h"
#include "tests/tiny_scene.h"

namespace splat {
namespace {

namespace fs = std::filesystem;
using testing_util::TempDir;

// The tiny scene with a model made from its sparse points (they lie on the
// surfaces); generated once for the suite.
const fs::path& tiny_scene() {
  static const fs::path dir = [] {
    const fs::path d = testing_util::generate_tiny_scene("vote_scene");
    const auto scene = Scene::load(d, {});
    write_gaussian_ply(d / "model.ply",
                       initialize_from_points(scene->points(), scene->point_colors()));
    return d;
  }();
  return dir;
}

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

VoteRunOptions options_for(const std::string& id_maps) {
  VoteRunOptions o;
  o.model = tiny_scene() / "model.ply";
  o.id_maps = id_maps;
  return o;
}

TEST(VoteRun, WritesTheLabelledModelSummaryPreviewsAndBaselineMaps) {
  TempDir work;
  const VoteRunResult r = run_voting(tiny_scene(), work / "vote", options_for("instance_gt"));
  EXPECT_EQ(r.views_used, 14u);  // 16 views, every 8th is a test view
  const GaussianModel m = read_gaussian_ply(work / "vote/point_cloud.ply");
  ASSERT_TRUE(m.has_labels);
  EXPECT_EQ(m.size(), r.gaussians);
  const auto summary = read_json(work / "vote/summary.json");
  EXPECT_EQ(summary["objects_found"].get<size_t>(), r.objects);
  EXPECT_GE(r.objects, 8u);  // most of the scene's 10 objects have sparse points
  EXPECT_EQ(summary["visibility"], "depth");
  // Exact maps: a Gaussian on a surface sees the same ID from every view.
  EXPECT_GT(r.vote_agreement, 0.9);
  EXPECT_EQ(fs::directory_iterator(work / "vote/preview") == fs::directory_iterator(), false);
  for (const char* view : {"frame_00000.png", "frame_00008.png"}) {
    const IdMap baseline = read_id_map(work / "vote/baseline" / view);
    EXPECT_EQ(baseline.width, 96);
    EXPECT_TRUE(fs::exists(work / "vote/baseline_color" / view));
  }
  // Names come from the map folder's objects.json when there is one.
  bool named = false;
  for (const auto& o : summary["objects"]) named |= o.contains("name");
  EXPECT_FALSE(named);  // instance_gt/ has none
}

// label_agreement.npy holds one share per Gaussian in the PLY's order: its
// means per label are the summary's.
void expect_agreement_matches_summary(const fs::path& vote, const nlohmann::json& summary) {
  const GaussianModel m = read_gaussian_ply(vote / "point_cloud.ply");
  std::vector<size_t> shape;
  const std::vector<double> agreement = read_npy(vote / "label_agreement.npy", &shape);
  ASSERT_EQ(shape, std::vector<size_t>{m.size()});
  std::map<int, double> sum;
  std::map<int, size_t> count;
  for (size_t j = 0; j < m.size(); ++j) {
    ASSERT_TRUE(agreement[j] >= 0 && agreement[j] <= 1);
    sum[m.labels[j]] += agreement[j], ++count[m.labels[j]];
  }
  for (const auto& o : summary["objects"]) {
    if (o["gaussians"].get<size_t>() > 0) {
      EXPECT_NEAR(sum[o["id"]] / count[o["id"]], o["vote_agreement"].get<double>(), 1e-9);
    }
  }
}

TEST(VoteRun, CorruptedMapsAgreeLessThanExactOnes) {
  TempDir exact, corrupted;
  const VoteRunResult a = run_voting(tiny_scene(), exact / "vote", options_for("instance_gt"));
  const VoteRunResult b = run_voting(tiny_scene(), corrupted / "vote", options_for("sam2"));
  EXPECT_LT(b.vote_agreement, a.vote_agreement);
  const auto summary = read_json(corrupted / "vote/summary.json");
  expect_agreement_matches_summary(corrupted / "vote", summary);
  bool named = false;
  for (const auto& o : summary["objects"]) named |= o.contains("name");
  EXPECT_TRUE(named);  // sam2/objects.json names the IDs
}

// A copy of the scene's map folder under another name, to break.
fs::path copy_maps(const std::string& name) {
  const fs::path dst = tiny_scene() / name;
  fs::remove_all(dst);
  fs::copy(tiny_scene() / "instance_gt", dst);
  return dst;
}

TEST(VoteRun, MissingMapIsNamedUnlessAllowed) {
  const fs::path maps = copy_maps("maps_missing");
  fs::remove(maps / "frame_00003.png");
  TempDir work;
  try {
    run_voting(tiny_scene(), work / "vote", options_for("maps_missing"));
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame_00003"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--allow-missing"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(work / "vote/point_cloud.ply"));
  VoteRunOptions o = options_for("maps_missing");
  o.allow_missing = true;
  const VoteRunResult r = run_voting(tiny_scene(), work / "vote", o);
  EXPECT_EQ(r.views_used, 13u);
  ASSERT_EQ(r.views_skipped.size(), 1u);
  EXPECT_EQ(r.views_skipped[0], "frame_00003.png");
}

TEST(VoteRun, MapsOfAnotherSizeAreScaledAndOtherAspectRatiosRejected) {
  const fs::path maps = copy_maps("maps_resized");
  // Half size, same aspect ratio: scaled with nearest-neighbour sampling.
  for (const auto& f : fs::directory_iterator(maps)) {
    if (f.path().extension() != ".png") continue;
    const IdMap m = read_id_map(f.path());
    IdMap half(48, 36);
    for (int y = 0; y < 36; ++y)
      for (int x = 0; x < 48; ++x) half.at(x, y) = m.at(2 * x, 2 * y);
    write_id_map(f.path(), half, 8);
  }
  TempDir work;
  EXPECT_GT(run_voting(tiny_scene(), work / "vote", options_for("maps_resized")).vote_agreement,
            0.85);
  write_id_map(maps / "frame_00005.png", IdMap(50, 36), 8);
  try {
    run_voting(tiny_scene(), work / "vote", options_for("maps_resized"));
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame_00005.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("aspect ratio"), std::string::npos) << e.what();
  }
}

TEST(VoteRun, UnreadableMapIsNamed) {
  const fs::path maps = copy_maps("maps_broken");
  testing_util::write_file(maps / "frame_00002.png", "not a png");
  TempDir work;
  try {
    run_voting(tiny_scene(), work / "vote", options_for("maps_broken"));
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame_00002.png"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace splat
