// One Adam step over every parameter group (59 floats per Gaussian), as the
// trainer takes it each iteration, at the sizes training reaches.
// {Gaussians, percent in view, sparse}: at 100 every gradient is read;
// below, a random share of the Gaussians is in view and the others step with
// a zero gradient they do not read, as the trainer's (about 55% late in
// training, in no order by index), or with sparse 1 do not step at all
// (GaussianAdam::Culled::kKeep).
//
//   build/bench/adam_bench

#include <benchmark/benchmark.h>

#include <random>

#include "splat/train/adam.h"

namespace {

using namespace splat;

void BM_AdamStep(benchmark::State& state) {
  const size_t n = size_t(state.range(0));
  GaussianModel model;
  model.resize(n);
  GaussianGradients grads;
  std::mt19937 rng(1);
  std::normal_distribution<float> normal;
  for (int g = 0; g < kParamGroups; ++g) {
    auto& values = const_cast<std::vector<float>&>(group_gradients(grads, ParamGroup(g)));
    values.resize(group_values(model, ParamGroup(g)).size());
    for (float& v : values) v = normal(rng);
  }
  const int in_view = int(state.range(1));
  std::bernoulli_distribution visible(in_view / 100.0);
  grads.visible.resize(n);
  for (uint8_t& v : grads.visible) v = visible(rng) ? 1 : 0;
  GaussianAdam adam(n);
  std::array<float, kParamGroups> lr;
  lr.fill(1e-3f);
  lr[int(ParamGroup::kInstanceOpacity)] = 0;  // stage one: no sigma*
  const GaussianAdam::Culled culled = state.range(2)   ? GaussianAdam::Culled::kKeep
                                      : in_view == 100 ? GaussianAdam::Culled::kReadGradients
                                                       : GaussianAdam::Culled::kZeroGradients;
  for (auto _ : state) adam.step(model, grads, lr, {}, kMaxShDegree, culled);
  state.counters["Gaussians"] = double(n);
}
BENCHMARK(BM_AdamStep)
    ->Args({230000, 100, 0})
    ->Args({466000, 100, 0})
    ->Args({466000, 55, 0})
    ->Args({466000, 55, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
