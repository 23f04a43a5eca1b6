// The training loss (L1 + SSIM and its gradient) at the datasets'
// resolutions, as the trainer computes it every iteration (buffers reused),
// beside the slow plane-by-plane reference it is tested against
// (splat/image_quality.h's ssim_plane), which the trainer used before.
//
//   build/bench/loss_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <random>

#include "splat/image_quality.h"
#include "splat/train/image_loss.h"

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

}  // namespace

BENCHMARK_MAIN();
