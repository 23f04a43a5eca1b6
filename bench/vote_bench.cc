// op2gs-vote's library run (splat::run_voting) at the size of the voting
// issue's target: 1M Gaussians, 300 training views with 16-bit ID maps at
// 1280x960, on a scene folder written once to a temporary directory. The
// timed region is the whole run as the stage performs it (model read, ID map
// decoding, depth rendering, votes, labelled PLY), without previews or
// baseline maps.
//
//   build/bench/vote_bench [--benchmark_filter=...]

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <random>

#include "bench/bench_scenes.h"
#include "splat/colmap_model.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/label/vote_run.h"
#include "splat/ply.h"

namespace {

namespace fs = std::filesystem;
using namespace splat;

constexpr int kWidth = 1280, kHeight = 960;

// Cameras around the origin, looking into the surface scene, which each of
// them sees almost entirely (the worst case: every Gaussian votes in every view).
std::vector<Camera> jittered_cameras(int count) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Camera> cams;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d eye(0.4 * u(rng), 0.3 * u(rng), 0.4 * u(rng));
    const Eigen::Vector3d target(0.3 * u(rng), 0.3 * u(rng), 6);
    cams.push_back(Camera::look_at(eye, target, Eigen::Vector3d::UnitY(), kWidth, kHeight,
                                   0.8 * kWidth, 0.8 * kWidth));
  }
  return cams;
}

// Blocky ID maps (objects as rectangles of IDs 0..20), different per view.
IdMap id_map_of(int view) {
  IdMap m(kWidth, kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      m.at(x, y) = uint16_t(((x + 7 * view) / 97 + (y + 3 * view) / 83 * 5) % 21);
  return m;
}

fs::path make_scene(size_t gaussians, int views) {
  const fs::path dir =
      fs::temp_directory_path() / ("op2gs_vote_bench_" + std::to_string(::getpid()));
  fs::remove_all(dir);  // a folder left by an aborted run under a reused process ID
  ColmapModel model;
  model.cameras[1] = {
      1, 1, kWidth, kHeight, {0.8 * kWidth, 0.8 * kWidth, kWidth / 2.0, kHeight / 2.0}};
  const std::vector<Camera> cams = jittered_cameras(views);
  // Voting reads each photo's header (its size), not its pixels: one blank
  // photo, copied per view.
  const fs::path blank = dir / "blank.png";
  write_image_rgb(blank, ImageRGB(kWidth, kHeight));
  fs::create_directories(dir / "images");
  for (int i = 0; i < views; ++i) {
    ColmapImage image;
    image.image_id = uint32_t(i + 1);
    image.camera_id = 1;
    image.qvec = quaternion_from_rotation(cams[i].R);
    image.tvec = cams[i].t;
    image.name = "view_" + std::to_string(1000 + i) + ".png";
    model.images[image.image_id] = image;
    fs::copy_file(blank, dir / "images" / image.name);
    write_id_map(dir / "sam2" / image.name, id_map_of(i), 16);
  }
  write_colmap_model(model, dir / "sparse" / "0", ColmapFormat::kBinary);
  write_gaussian_ply(dir / "model.ply", bench::surface_scene(gaussians, kWidth, kHeight));
  return dir;
}

void BM_Vote(benchmark::State& state) {
  const size_t n = size_t(state.range(0));
  const int views = int(state.range(1));
  const fs::path scene = make_scene(n, views);
  VoteRunOptions o;
  o.model = scene / "model.ply";
  o.split = SplitRule::kAll;
  o.preview_views = 0;
  o.baseline_maps = false;
  if (state.range(2) == 1) o.vote.visibility = VoteVisibility::kFrustum;
  for (auto _ : state) {
    const VoteRunResult r = run_voting(scene, scene / "work" / "vote", o);
    state.counters["objects"] = double(r.objects);
    state.counters["unseen"] = r.unseen_share;
  }
  fs::remove_all(scene);
}
BENCHMARK(BM_Vote)
    ->ArgNames({"gaussians", "views", "frustum_only"})
    ->Args({1000000, 300, 0})
    ->Args({1000000, 300, 1})
    ->Args({200000, 60, 0})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
