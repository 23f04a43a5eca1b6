// One Adam step over every parameter group (59 floats per Gaussian), as the
// trainer takes it each iteration, at the sizes training reaches.
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
  GaussianAdam adam(n);
  std::array<float, kParamGroups> lr;
  lr.fill(1e-3f);
  lr[int(ParamGroup::kInstanceOpacity)] = 0;  // stage one: no sigma*
  for (auto _ : state) adam.step(model, grads, lr);
  state.counters["Gaussians"] = double(n);
}
BENCHMARK(BM_AdamStep)->Arg(230000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
