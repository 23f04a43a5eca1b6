// The CPU rasterizer on fixed seeded scenes: forward, backward, forward with
// the instance branch (M = 3), and all-object masks alone.
//
//   build/bench/render_bench --benchmark_counters_tabular=true
//
// Two fixed seeded scenes (the second argument after the size picks one):
//  - volume: N Gaussians spread through a box 2..8 units in front of the
//    camera, log-normal scales whose median projects to about 1.5 px at the
//    mean depth for 200k Gaussians at 640x480 (so every size has about the same
//    depth complexity), opacities sigmoid(N(1, 2)), random rotations. A hard
//    case: rays cross many semi-transparent Gaussians before terminating.
//  - surface: what training produces. N Gaussians on 16 random planar and
//    spherical patches plus a back wall that fills the view; tangent scales
//    from the sampling spacing on each patch (times log-normal(0, 0.5)) so
//    every surface is covered, flattened along the normal (scale / 10),
//    mostly opaque (sigmoid(N(2, 1.5))).
// Both: full degree-3 SH, labels 0..10.

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <random>

#include "bench/bench_scenes.h"
#include "splat/render/project.h"
#include "splat/render/renderer.h"

namespace {

using namespace splat;

using bench::bench_camera;
using bench::bench_scene;
using bench::surface_scene;

struct Case {
  size_t n;
  int width, height;
  bool surface;
};
Case case_of(const benchmark::State& state) {
  const int scale = int(state.range(1));
  return {size_t(state.range(0)), 640 * scale, 480 * scale, state.range(2) == 1};
}
GaussianModel scene_of(const Case& c) {
  return c.surface ? surface_scene(c.n, c.width, c.height) : bench_scene(c.n, c.width, c.height);
}

void report(benchmark::State& state, const RenderOutput& out, const Case& c) {
  double blends = 0;
  for (uint32_t v : out.contributors) blends += v;
  state.counters["blends/px"] = blends / out.contributors.size();
  state.counters["blends/s"] =
      benchmark::Counter(blends * state.iterations(), benchmark::Counter::kIsRate);
  state.SetLabel(std::string(c.surface ? "surface " : "volume ") + std::to_string(c.n / 1000) +
                 "k @ " + std::to_string(c.width) + "x" + std::to_string(c.height));
}

void BM_Forward(benchmark::State& state) {
  const Case c = case_of(state);
  const GaussianModel m = scene_of(c);
  const Camera cam = bench_camera(c.width, c.height);
  RenderOutput out;
  std::unique_ptr<RenderState> rs;  // reused, as when rendering many views
  for (auto _ : state) CpuRenderer().render(m, cam, RenderSettings{}, out, &rs);
  report(state, out, c);
}

void BM_ForwardInstanceM3(benchmark::State& state) {
  const Case c = case_of(state);
  const GaussianModel m = scene_of(c);
  const Camera cam = bench_camera(c.width, c.height);
  RenderSettings s;
  s.instance_labels = {2, 5, 7};
  RenderOutput out;
  std::unique_ptr<RenderState> rs;
  for (auto _ : state) CpuRenderer().render(m, cam, s, out, &rs);
  report(state, out, c);
}

void BM_AllObjectMasksOnly(benchmark::State& state) {
  const Case c = case_of(state);
  const GaussianModel m = scene_of(c);
  const Camera cam = bench_camera(c.width, c.height);
  RenderSettings s;
  s.color = s.depth = false;
  s.all_instance_labels = true;
  RenderOutput out;
  std::unique_ptr<RenderState> rs;
  for (auto _ : state) CpuRenderer().render(m, cam, s, out, &rs);
  report(state, out, c);
}

void BM_LabelMapsOnly(benchmark::State& state) {
  const Case c = case_of(state);
  const GaussianModel m = scene_of(c);
  const Camera cam = bench_camera(c.width, c.height);
  RenderSettings s;
  s.color = s.depth = false;
  s.instance_label_map = s.baseline_label_map = true;
  RenderOutput out;
  std::unique_ptr<RenderState> rs;
  for (auto _ : state) CpuRenderer().render(m, cam, s, out, &rs);
  report(state, out, c);
}

// Backward alone (the forward's state is made once, outside the timing).
void BM_Backward(benchmark::State& state) {
  const Case c = case_of(state);
  const GaussianModel m = scene_of(c);
  const Camera cam = bench_camera(c.width, c.height);
  RenderSettings s;
  s.instance_labels = {2, 5, 7};
  std::unique_ptr<RenderState> rs;
  const RenderOutput out = CpuRenderer().render(m, cam, s, &rs);
  RenderOutputGradients g;
  g.color.assign(out.color.size(), 1e-3f);
  g.instance_maps.assign(out.instance_maps.size(), 1e-3f);
  GaussianGradients grads;
  for (auto _ : state) CpuRenderer().backward(m, cam, s, *rs, g, grads);
  report(state, out, c);
  // Parameters + gradients + render state + backward buffers, per Gaussian;
  // the per-pixel buffers (final transmittance, contributor count: 8 bytes a
  // pixel) are reported apart, as they do not grow with the Gaussians.
  const double pixels = double(c.width) * c.height;
  const double model_bytes = double(sizeof(float)) * (3 + 3 + 45 + 1 + 3 + 4 + 1) + sizeof(int32_t);
  const double grad_bytes = double(sizeof(float)) * (3 + 3 + 45 + 1 + 3 + 4 + 1 + 2) + 1;
  const double state_bytes = double(rs->bytes() + rs->backward_bytes()) - 8 * pixels;
  state.counters["bytes/gaussian"] = model_bytes + grad_bytes + state_bytes / c.n;
  state.counters["state bytes/pixel"] = 8;
}

// A training iteration's rendering work with settings s: forward with the
// state, then backward.
void forward_backward(benchmark::State& state, const RenderSettings& s) {
  const Case c = case_of(state);
  const GaussianModel m = scene_of(c);
  const Camera cam = bench_camera(c.width, c.height);
  RenderOutput out;
  RenderOutputGradients g;
  GaussianGradients grads;
  std::unique_ptr<RenderState> rs;  // buffers reused from iteration to iteration
  for (auto _ : state) {
    CpuRenderer().render(m, cam, s, out, &rs);
    g.color.assign(out.color.size(), 1e-3f);
    CpuRenderer().backward(m, cam, s, *rs, g, grads);
  }
  report(state, out, c);
}

void BM_ForwardBackward(benchmark::State& state) { forward_backward(state, RenderSettings{}); }

// The same with the trainer's settings: colour alone, no depth output (the
// renderer has a path of its own for it).
void BM_TrainingForwardBackward(benchmark::State& state) {
  RenderSettings s;
  s.depth = false;
  forward_backward(state, s);
}

// Pose refinement's cost (op2gs-train --refine-poses): the backward pass
// with the camera-pose gradient against without, alternated in one loop so
// that the machine's drift cancels.
void BM_CameraGradientRatio(benchmark::State& state) {
  const Case c = case_of(state);
  const GaussianModel m = scene_of(c);
  const Camera cam = bench_camera(c.width, c.height);
  const RenderSettings s;
  BackwardSettings plain, posed;
  posed.camera_gradient = true;
  std::unique_ptr<RenderState> rs;
  const RenderOutput out = CpuRenderer().render(m, cam, s, &rs);
  RenderOutputGradients g;
  g.color.assign(out.color.size(), 1e-3f);
  GaussianGradients grads;
  double t_plain = 0, t_posed = 0;
  auto timed = [&](const BackwardSettings& b) {
    const auto t0 = std::chrono::steady_clock::now();
    CpuRenderer().backward(m, cam, s, b, *rs, g, grads);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  timed(posed);  // sizes the gradient buffers outside the timing
  for (auto _ : state) {
    t_plain += timed(plain);
    t_posed += timed(posed);
  }
  state.counters["camera_gradient/plain"] = t_posed / t_plain;
  report(state, out, c);
}

// The passes over every Gaussian alone, as training runs them: the
// projection with the SH colour, and its backward from fixed projected
// gradients.
RenderSettings trainer_settings() {
  RenderSettings s;
  s.depth = false;  // colour alone
  return s;
}
BackwardSettings trainer_backward_settings() {
  BackwardSettings b;
  b.zero_culled_gradients = false;  // culled Gaussians' gradients left unwritten
  return b;
}

// A case's scene and camera, projected once with the trainer's settings.
struct ProjectedScene {
  explicit ProjectedScene(const Case& c)
      : model(scene_of(c)), camera(bench_camera(c.width, c.height)) {
    project_gaussians(model, camera, settings, projected);
  }
  GaussianModel model;
  Camera camera;
  RenderSettings settings = trainer_settings();
  BackwardSettings backward = trainer_backward_settings();
  ProjectedGaussians projected;
};

void BM_Project(benchmark::State& state) {
  const Case c = case_of(state);
  ProjectedScene scene(c);
  for (auto _ : state)
    project_gaussians(scene.model, scene.camera, scene.settings, scene.projected);
  size_t visible = 0;
  for (size_t i = 0; i < c.n; ++i) visible += scene.projected.visible(i);
  state.counters["visible"] = double(visible) / double(c.n);
}

void BM_ProjectBackward(benchmark::State& state) {
  const Case c = case_of(state);
  const ProjectedScene scene(c);
  ProjectedGradients pg;
  pg.resize(c.n);
  std::mt19937 rng(3);
  std::normal_distribution<float> normal(0.f, 1e-3f);
  for (auto* v : {&pg.mean2d, &pg.conic, &pg.depth, &pg.color, &pg.opacity, &pg.instance_opacity})
    for (float& x : *v) x = normal(rng);
  GaussianGradients grads;
  for (auto _ : state)
    project_gaussians_backward(scene.model, scene.camera, scene.settings, scene.backward,
                               scene.projected, pg, grads);
}

// {Gaussians, resolution (1: 640x480, 2: 1280x960), scene (0: volume, 1: surface)}
// Paired ratios against a colour render, alternating the two renders in one
// loop so that the machine's drift cancels: the instance branch with M = 3
// (target: at most 1.15) and all-object masks alone (target: at most 1.0).
void BM_InstanceCostRatios(benchmark::State& state) {
  const Case c = case_of(state);
  const GaussianModel m = scene_of(c);
  const Camera cam = bench_camera(c.width, c.height);
  RenderSettings colour, instance, masks;
  instance.instance_labels = {2, 5, 7};
  masks.color = masks.depth = false;
  masks.all_instance_labels = true;
  RenderOutput out;
  std::unique_ptr<RenderState> rs;
  double t_colour = 0, t_instance = 0, t_masks = 0;
  auto timed = [&](const RenderSettings& s) {
    const auto t0 = std::chrono::steady_clock::now();
    CpuRenderer().render(m, cam, s, out, &rs);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  for (auto _ : state) {
    t_colour += timed(colour);
    t_instance += timed(instance);
    t_colour += timed(colour);
    t_masks += timed(masks);
  }
  state.counters["instance_M3/colour"] = t_instance / (t_colour / 2);
  state.counters["all_masks/colour"] = t_masks / (t_colour / 2);
  report(state, out, c);
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int scene : {1, 0})
    for (auto [n, res] :
         {std::pair{100000, 1}, {200000, 1}, {1000000, 1}, {100000, 2}, {1000000, 2}})
      b->Args({n, res, scene});
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(BM_Forward)->Apply(sizes);
BENCHMARK(BM_ForwardInstanceM3)->Apply(sizes);
BENCHMARK(BM_AllObjectMasksOnly)->Apply(sizes);
BENCHMARK(BM_LabelMapsOnly)->Apply(sizes);
BENCHMARK(BM_InstanceCostRatios)->Apply(sizes);
BENCHMARK(BM_Backward)->Apply(sizes);
BENCHMARK(BM_ForwardBackward)->Apply(sizes);
BENCHMARK(BM_TrainingForwardBackward)->Apply(sizes);
BENCHMARK(BM_CameraGradientRatio)->Apply(sizes);
BENCHMARK(BM_Project)->Apply(sizes);
BENCHMARK(BM_ProjectBackward)->Apply(sizes);

}  // namespace

BENCHMARK_MAIN();
