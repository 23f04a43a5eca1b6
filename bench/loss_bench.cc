// The training loss (L1 + SSIM and its gradient) at the datasets'
// resolutions, as the trainer computes it every iteration (buffers reused),
// beside the slow plane-by-plane reference it is tested against
// (splat/image_quality.h's ssim_plane), which the trainer used before; and
// stage two's object loss with its gradient, on one and on two threads.
//
//   build/bench/loss_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "splat/image_quality.h"
#include "splat/train/image_loss.h"
#include "splat/train/object_loss.h"

namespace {

using namespace splat;

ImageRGB noise_image(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  ImageRGB im(w, h);
  for (float& v : im.data) v = u(rng);
  return im;
}

void BM_ImageLoss(benchmark::State& state) {
  const ImageRGB target = noise_image(int(state.range(0)), int(state.range(1)), 1);
  const ImageRGB rendered = noise_image(int(state.range(0)), int(state.range(1)), 2);
  ImageLossBuffers buffers;
  std::vector<float> grad;
  image_loss(rendered.data, target, {}, &grad, &buffers);  // the buffers' first use
  for (auto _ : state)
    benchmark::DoNotOptimize(image_loss(rendered.data, target, {}, &grad, &buffers));
}

// L1, then ssim_plane channel by channel with fresh planes each call.
void BM_ImageLossReference(benchmark::State& state) {
  const ImageRGB target = noise_image(int(state.range(0)), int(state.range(1)), 1);
  const ImageRGB rendered = noise_image(int(state.range(0)), int(state.range(1)), 2);
  const size_t n = target.data.size();
  std::vector<float> grad;
  for (auto _ : state) {
    double l1 = 0;
    grad.assign(n, 0.f);
    for (size_t i = 0; i < n; ++i) {
      const float d = rendered.data[i] - target.data[i];
      l1 += std::abs(double(d));
      grad[i] = d > 0 ? 0.8f / n : (d < 0 ? -0.8f / n : 0.f);
    }
    double s = 0;
    for (int c = 0; c < 3; ++c) {
      std::vector<float> dx(n / 3, 0.f);
      s += ssim_plane(rgb_channel(rendered.data, c), rgb_channel(target.data, c), target.width,
                      target.height, &dx);
      for (size_t i = 0; i < dx.size(); ++i) grad[3 * i + c] += -0.2f / n * dx[i];
    }
    benchmark::DoNotOptimize(l1 + s);
  }
}

// An object as stage two sees it: a disc a quarter of the image's height in
// radius in the ID map (label `id`), and an occupancy that rises from 0 to
// 1 over 4 pixels across the disc's outline, shifted by `offset` pixels, so
// most pixels are clamped zeros as in training.
struct ObjectPlane {
  IdMap ids;
  std::vector<float> occupancy;
  ObjectPlane(int w, int h, int id, float offset) : ids(w, h), occupancy(size_t(w) * h) {
    const float cx = 0.5f * float(w), cy = 0.5f * float(h), r = 0.25f * float(h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const float d = std::hypot(float(x) - cx, float(y) - cy);
        const size_t p = size_t(y) * size_t(w) + size_t(x);
        ids.ids[p] = d < r ? uint16_t(id) : uint16_t(0);
        occupancy[p] = std::clamp((r + offset - d) / 4.f + 0.5f, 0.f, 1.f);
      }
  }
};

// The default recipe's object loss (robust-outline) over M = range(2) maps
// of one view, on range(3) threads.
void BM_ObjectLoss(benchmark::State& state) {
  const int w = int(state.range(0)), h = int(state.range(1)), m = int(state.range(2));
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(state.range(3)));
  const ObjectPlane object(w, h, 1, 1.5f);
  std::vector<float> maps;
  std::vector<int32_t> labels;
  for (int j = 0; j < m; ++j) {
    maps.insert(maps.end(), object.occupancy.begin(), object.occupancy.end());
    labels.push_back(1);
  }
  PixelLoss loss{PixelLoss::Kind::kGeneralized, 0.7, 3};
  std::vector<float> grad;
  for (auto _ : state)
    benchmark::DoNotOptimize(object_loss(maps, labels, object.ids, 0.1f, &grad, loss));
}

// LERF-Mask's 986x728 and 3DOVS's 1440x1080.
BENCHMARK(BM_ImageLoss)
    ->Args({986, 728})
    ->Args({1440, 1080})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_ImageLossReference)
    ->Args({986, 728})
    ->Args({1440, 1080})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// LERF-Mask's size; M = 1 (a scene of one object) and 3 (the paper's M);
// one thread and two.
BENCHMARK(BM_ObjectLoss)
    ->ArgsProduct({{986}, {728}, {1, 3}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
