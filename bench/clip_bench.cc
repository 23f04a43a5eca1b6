// CLIP ViT-B/16 in C++ at its real size (random weights: the speed does not
// depend on them): one image, the 50 crops of a 10-object scene spread over
// the cores as op2gs-embed runs them, and one text query.
//
//   build/bench/clip_bench
//   build/bench/clip_bench --write-model DIR   # a random ViT-B/16 model file
//                                              # for timing op2gs-embed itself

#include <benchmark/benchmark.h>
#include <tbb/parallel_for.h>

#include <cstring>
#include <random>

#include "splat/clip/clip_model.h"
#include "splat/clip/safetensors.h"

namespace {

using namespace splat;

// ViT-B/16 as openai/clip-vit-base-patch16: image width 768, text width 512,
// 12 layers each, MLP 4x, 224 px in 16 px patches, 49,408 tokens, 77 positions.
constexpr int kImageWidth = 768, kTextWidth = 512, kLayers = 12, kEmbedding = 512;
constexpr int kPatch = 16, kImage = 224, kVocabulary = 49408, kContext = 77;

std::map<std::string, Tensor> random_vit_b16() {
  std::mt19937 rng(5);
  std::normal_distribution<float> normal(0.f, 0.02f);
  std::map<std::string, Tensor> t;
  const auto add = [&](const std::string& name, std::vector<int64_t> shape, float constant = -1) {
    Tensor x;
    x.shape = shape;
    int64_t n = 1;
    for (int64_t d : shape) n *= d;
    x.values.resize(size_t(n));
    for (float& v : x.values) v = constant >= 0 ? constant : normal(rng);
    t[name] = std::move(x);
  };
  const auto tower = [&](const std::string& prefix, int64_t w) {
    for (int i = 0; i < kLayers; ++i) {
      const std::string p = prefix + ".encoder.layers." + std::to_string(i) + ".";
      for (const char* proj : {"q_proj", "k_proj", "v_proj", "out_proj"}) {
        add(p + "self_attn." + proj + ".weight", {w, w});
        add(p + "self_attn." + proj + ".bias", {w});
      }
      for (const char* ln : {"layer_norm1", "layer_norm2"}) {
        add(p + ln + ".weight", {w}, 1.f);
        add(p + ln + ".bias", {w}, 0.f);
      }
      add(p + "mlp.fc1.weight", {4 * w, w});
      add(p + "mlp.fc1.bias", {4 * w});
      add(p + "mlp.fc2.weight", {w, 4 * w});
      add(p + "mlp.fc2.bias", {w});
    }
  };
  const int64_t grid = kImage / kPatch;
  add("vision_model.embeddings.class_embedding", {kImageWidth});
  add("vision_model.embeddings.patch_embedding.weight", {kImageWidth, 3, kPatch, kPatch});
  add("vision_model.embeddings.position_embedding.weight", {grid * grid + 1, kImageWidth});
  add("vision_model.pre_layrnorm.weight", {kImageWidth}, 1.f);
  add("vision_model.pre_layrnorm.bias", {kImageWidth}, 0.f);
  tower("vision_model", kImageWidth);
  add("vision_model.post_layernorm.weight", {kImageWidth}, 1.f);
  add("vision_model.post_layernorm.bias", {kImageWidth}, 0.f);
  add("visual_projection.weight", {kEmbedding, kImageWidth});
  add("text_model.embeddings.token_embedding.weight", {kVocabulary, kTextWidth});
  add("text_model.embeddings.position_embedding.weight", {kContext, kTextWidth});
  tower("text_model", kTextWidth);
  add("text_model.final_layer_norm.weight", {kTextWidth}, 1.f);
  add("text_model.final_layer_norm.bias", {kTextWidth}, 0.f);
  add("text_projection.weight", {kEmbedding, kTextWidth});
  return t;
}

const ClipModel& model() {
  static const ClipModel m = [] {
    const auto dir = std::filesystem::temp_directory_path() / "op2gs_clip_bench";
    std::filesystem::create_directories(dir);
    write_safetensors(dir / "model.safetensors", random_vit_b16());
    ClipFiles files;
    files.model = dir / "model.safetensors";
    ClipModel loaded = ClipModel::load(files);
    std::filesystem::remove_all(dir);
    return loaded;
  }();
  return m;
}

ClipPixels random_pixels() {
  ImageRGB image(300, 300);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (float& v : image.data) v = u(rng);
  return clip_preprocess(image, kImage);
}

void BM_ImageEncoderOneCrop(benchmark::State& state) {
  const ClipModel& m = model();
  const ClipPixels pixels = random_pixels();
  for (auto _ : state) benchmark::DoNotOptimize(m.encode_image(pixels));
}
BENCHMARK(BM_ImageEncoderOneCrop)->Unit(benchmark::kMillisecond)->UseRealTime();

// 10 objects x 5 crops, in parallel over the cores (as op2gs-embed).
void BM_ImageEncoder50Crops(benchmark::State& state) {
  const ClipModel& m = model();
  const std::vector<ClipPixels> crops(50, random_pixels());
  std::vector<Eigen::VectorXf> out(crops.size());
  for (auto _ : state)
    tbb::parallel_for(size_t(0), crops.size(),
                      [&](size_t i) { out[i] = m.encode_image(crops[i]).normalized(); });
  state.counters["crops/s"] =
      benchmark::Counter(double(state.iterations()) * 50, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ImageEncoder50Crops)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);

void BM_TextEncoderOneQuery(benchmark::State& state) {
  const ClipModel& m = model();
  const std::vector<int32_t> ids = {49406, 320, 1125, 539, 320, 736, 4269, 49407};
  for (auto _ : state) benchmark::DoNotOptimize(m.encode_text(ids));
}
BENCHMARK(BM_TextEncoderOneQuery)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::strcmp(argv[1], "--write-model") == 0) {
    splat::write_safetensors(std::filesystem::path(argv[2]) / "model.safetensors",
                             random_vit_b16());
    return 0;
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
