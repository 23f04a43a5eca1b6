// Throughput of the model and scene I/O on sizes users meet: PLY files of
// 100k-1M Gaussians, COLMAP models of 100k points, images and ID maps.
//
//   build/bench/io_bench --benchmark_counters_tabular=true

#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>

#include "splat/camera_distortion.h"
#include "splat/colmap_model.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/ply.h"

namespace {

namespace fs = std::filesystem;

fs::path bench_dir() {
  const fs::path dir = fs::temp_directory_path() / ("op2gs_io_bench_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

splat::GaussianModel random_gaussians(size_t n) {
  std::mt19937 rng(1);
  std::normal_distribution<float> g;
  splat::GaussianModel m;
  m.resize(n);
  for (auto* v : {&m.means, &m.sh_dc, &m.sh_rest, &m.opacity_logits, &m.log_scales, &m.rotations,
                  &m.instance_opacity_logits})
    for (float& x : *v) x = g(rng);
  m.has_instance_opacity = m.has_labels = true;
  return m;
}

void BM_PlyWrite(benchmark::State& state) {
  const auto m = random_gaussians(size_t(state.range(0)));
  const fs::path file = bench_dir() / "w.ply";
  for (auto _ : state) splat::write_gaussian_ply(file, m);
  state.counters["gaussians/s"] =
      benchmark::Counter(double(m.size()) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["MB"] = fs::file_size(file) / 1e6;
  fs::remove_all(file.parent_path());
}
BENCHMARK(BM_PlyWrite)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

void BM_PlyRead(benchmark::State& state) {
  const auto m = random_gaussians(size_t(state.range(0)));
  const fs::path file = bench_dir() / "r.ply";
  splat::write_gaussian_ply(file, m);
  for (auto _ : state) benchmark::DoNotOptimize(splat::read_gaussian_ply(file));
  state.counters["gaussians/s"] =
      benchmark::Counter(double(m.size()) * state.iterations(), benchmark::Counter::kIsRate);
  fs::remove_all(file.parent_path());
}
BENCHMARK(BM_PlyRead)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

splat::ColmapModel random_colmap(size_t points, size_t images) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  splat::ColmapModel m;
  m.cameras[1] = {1, 1, 1280, 960, {1000, 1000, 640, 480}};
  for (uint32_t i = 1; i <= images; ++i) {
    splat::ColmapImage im;
    im.image_id = i;
    im.camera_id = 1;
    im.name = "frame_" + std::to_string(i) + ".jpg";
    m.images[i] = im;
  }
  for (uint64_t p = 1; p <= points; ++p) {
    splat::ColmapPoint3D pt;
    pt.point3d_id = p;
    pt.xyz = {u(rng), u(rng), u(rng)};
    for (uint32_t k = 0; k < 5; ++k) {
      auto& im = m.images[uint32_t(1 + (p + k * 7) % images)];
      pt.track.push_back({im.image_id, uint32_t(im.points2d.size())});
      im.points2d.emplace_back(u(rng) * 640 + 640, u(rng) * 480 + 480);
      im.point3d_ids.push_back(int64_t(p));
    }
    m.points3d[p] = pt;
  }
  return m;
}

void BM_ColmapRead(benchmark::State& state) {
  const auto format = state.range(0) ? splat::ColmapFormat::kText : splat::ColmapFormat::kBinary;
  const fs::path dir = bench_dir() / "model";
  splat::write_colmap_model(random_colmap(100000, 300), dir, format);
  for (auto _ : state) benchmark::DoNotOptimize(splat::read_colmap_model(dir, format));
  state.SetLabel(state.range(0) ? "text, 100k points, 300 images"
                                : "binary, 100k points, 300 images");
  fs::remove_all(dir.parent_path());
}
BENCHMARK(BM_ColmapRead)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_ImageReadPng(benchmark::State& state) {
  const fs::path file = bench_dir() / "i.png";
  splat::ImageRGB im(1280, 960);
  std::mt19937 rng(3);
  for (float& v : im.data) v = float(rng() % 256) / 255.f;
  splat::write_image_rgb(file, im);
  for (auto _ : state) benchmark::DoNotOptimize(splat::read_image_rgb(file));
  state.SetLabel("1280x960 noise PNG");
  fs::remove_all(file.parent_path());
}
BENCHMARK(BM_ImageReadPng)->Unit(benchmark::kMillisecond);

// An ID map like SAM2's at LERF-Mask's size: a dozen objects on background.
splat::IdMap object_ids(int width, int height) {
  splat::IdMap map(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      map.ids[size_t(y) * width + x] = uint16_t((x / 240 + 6 * (y / 270)) % 13);
  return map;
}

void BM_IdMapReadPng(benchmark::State& state) {
  const fs::path file = bench_dir() / "m.png";
  splat::write_id_map(file, object_ids(1440, 1080), 8);
  for (auto _ : state) benchmark::DoNotOptimize(splat::read_id_map(file));
  state.SetLabel("1440x1080 8-bit grey");
  fs::remove_all(file.parent_path());
}
BENCHMARK(BM_IdMapReadPng)->Unit(benchmark::kMillisecond);

// op2gs-sfm resamples every ID map when COLMAP undistorts the photos.
void BM_IdMapUndistort(benchmark::State& state) {
  splat::ColmapCamera distorted{1, 4, 1440, 1080, {1150, 1150, 720, 540, -0.1, 0.02, 0, 0}};
  splat::ColmapCamera pinhole{1, 1, 1404, 1052, {1150, 1150, 702, 526}};
  const splat::IdMap map = object_ids(1440, 1080);
  for (auto _ : state) benchmark::DoNotOptimize(splat::undistort_id_map(map, distorted, pinhole));
  state.SetLabel("1440x1080 OPENCV to PINHOLE");
}
BENCHMARK(BM_IdMapUndistort)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
