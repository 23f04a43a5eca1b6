// The report's 3D viewer at the size issue #26 names: writes the viewer of a
// scene for a trained-like model of N Gaussians (random values in trained
// models' ranges, ten object labels) and prints how long that took and the
// file sizes (model.spz against the PLY). bench/studies/viewer_open.sh then times
// opening it in headless Chromium.
//
//   viewer_bench SCENE_DIR OUT_DIR [N = 1000000]

#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "eval/report/viewer.h"
#include "splat/ply.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc < 3) {
    fmt::print(stderr, "usage: viewer_bench SCENE_DIR OUT_DIR [N]\n");
    return 2;
  }
  const fs::path scene = argv[1], out = argv[2];
  const size_t n = argc > 3 ? size_t(std::atoll(argv[3])) : 1000000;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  splat::GaussianModel m;
  m.resize(n);
  for (float& x : m.means) x = 3.f * u(rng);
  for (float& x : m.sh_dc) x = 1.5f * u(rng);
  for (float& x : m.sh_rest) x = 0.2f * u(rng);
  for (float& x : m.opacity_logits) x = 4.f * u(rng);
  for (float& x : m.instance_opacity_logits) x = 4.f * u(rng);
  for (float& x : m.log_scales) x = -5.f + u(rng);
  for (float& x : m.rotations) x = u(rng);
  for (size_t i = 0; i < n; ++i) m.labels[i] = int32_t(i % 11);
  m.has_labels = m.has_instance_opacity = true;
  fs::create_directories(out);
  const fs::path ply = out / "model.ply";
  splat::write_gaussian_ply(ply, m);

  const auto start = std::chrono::steady_clock::now();
  eval::write_viewer(out / "viewer",
                     {.name = "bench", .scene = scene, .model = ply, .model_ply = ply});
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const fs::path dir = out / "viewer" / "bench";
  fmt::print(
      "{} Gaussians: viewer written in {:.2f} s; model.ply {:.1f} MB, model.spz {:.1f} MB "
      "({:.1f}x smaller), gaussians.bin {:.1f} MB, vendor.min.js {:.1f} MB\n",
      n, seconds, fs::file_size(ply) / 1e6, fs::file_size(dir / "model.spz") / 1e6,
      double(fs::file_size(ply)) / fs::file_size(dir / "model.spz"),
      fs::file_size(dir / "gaussians.bin") / 1e6,
      fs::file_size(out / "viewer" / "vendor.min.js") / 1e6);
}
