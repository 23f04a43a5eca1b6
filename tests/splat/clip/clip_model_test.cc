// The C++ CLIP against the PyTorch reference of scripts/make_tiny_clip.py:
// the tiny fixture in tests/fixtures/tiny_clip has the ViT-B/16 architecture
// and file layout with random weights; reference.json holds what PyTorch
// computed from it (in float64).

#include "splat/clip/clip_model.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/clip/tokenizer.h"
#include "splat/error.h"
#include "tests/test_util.h"
#include "tests/tiny_clip.h"

namespace splat {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const json& reference() {
  static const json r =
      json::parse(read_text_file(testing_util::tiny_clip_dir() / "reference.json"));
  return r;
}

const ClipModel& tiny_model() {
  static const ClipModel m = ClipModel::load(ClipFiles::in(testing_util::tiny_clip_dir()));
  return m;
}

double max_abs_difference(const Eigen::VectorXf& a, const std::vector<double>& b) {
  EXPECT_EQ(size_t(a.size()), b.size());
  double d = 0;
  for (size_t i = 0; i < b.size() && i < size_t(a.size()); ++i)
    d = std::max(d, std::abs(double(a[Eigen::Index(i)]) - b[i]));
  return d;
}

TEST(ClipTokenizer, MatchesReferenceTokenIdsOnTrickyStrings) {
  const ClipTokenizer tokenizer(testing_util::tiny_clip_dir() / "vocab.json",
                                testing_util::tiny_clip_dir() / "merges.txt");
  size_t checked = 0;
  for (const json& t : reference()["tokens"]) {
    const std::string text = t["text"];
    EXPECT_EQ(tokenizer.encode(text), t["ids"].get<std::vector<int32_t>>()) << "text: " << text;
    ++checked;
  }
  EXPECT_GE(checked, 10u);
}

TEST(ClipModel, ImageEncoderMatchesPyTorchReference) {
  const ClipModel& model = tiny_model();
  for (const json& image : reference()["images"]) {
    ClipPixels pixels;
    pixels.size = model.image_size();
    for (double v : image["pixels"]) pixels.values.push_back(float(v));
    const Eigen::VectorXf e = model.encode_image(pixels);
    EXPECT_LT(max_abs_difference(e, image["embedding"].get<std::vector<double>>()), 1e-4);
  }
}

TEST(ClipModel, TextEncoderMatchesPyTorchReference) {
  const ClipModel& model = tiny_model();
  const ClipTokenizer tokenizer(testing_util::tiny_clip_dir() / "vocab.json",
                                testing_util::tiny_clip_dir() / "merges.txt");
  for (const json& text : reference()["texts"]) {
    const std::vector<int32_t> ids = tokenizer.encode(text["text"].get<std::string>());
    EXPECT_EQ(ids, text["ids"].get<std::vector<int32_t>>());
    const Eigen::VectorXf e = model.encode_text(ids);
    EXPECT_LT(max_abs_difference(e, text["embedding"].get<std::vector<double>>()), 1e-4)
        << text["text"];
  }
}

TEST(ClipModel, TellsTheTestClipFromReleasedSizes) {
  EXPECT_FALSE(tiny_model().is_full_size());  // the tests' tiny CLIP
  // Weights of a given depth and embedding size (values unused: only the
  // shapes are asked).
  const auto model = [](int blocks, int embedding, int vision_width) {
    ClipVisionWeights v;
    v.blocks.resize(size_t(blocks));
    v.projection = RowMatrix::Zero(embedding, vision_width);
    ClipTextWeights t;
    t.token_embedding = RowMatrix::Zero(2, embedding);
    t.blocks.resize(12);
    t.projection = RowMatrix::Zero(embedding, embedding);
    return ClipModel(std::move(v), std::move(t));
  };
  EXPECT_TRUE(model(12, 512, 768).is_full_size());   // ViT-B/16, the paper's
  EXPECT_TRUE(model(24, 768, 1024).is_full_size());  // ViT-L/14
  EXPECT_FALSE(model(2, 512, 768).is_full_size());   // too shallow
  EXPECT_FALSE(model(12, 32, 48).is_full_size());    // too narrow
}

TEST(ClipModel, ReadsShapesFromTheTensors) {
  const ClipModel& model = tiny_model();
  EXPECT_EQ(model.image_size(), 32);
  EXPECT_EQ(model.embedding_size(), 24);
  EXPECT_EQ(model.context_length(), 77u);
}

TEST(ClipModel, MissingFilesGiveTheDownloadInstruction) {
  const testing_util::TempDir tmp;
  const fs::path dir = tmp.path();
  try {
    ClipFiles::in(dir);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("model.safetensors"), std::string::npos);
    EXPECT_NE(what.find("openai/clip-vit-base-patch16"), std::string::npos);
  }
}

TEST(ClipPreprocess, NormalisesWithClipMeanAndStd) {
  ImageRGB grey(40, 40);
  std::fill(grey.data.begin(), grey.data.end(), 0.5f);
  const ClipPixels p = clip_preprocess(grey, 32);
  ASSERT_EQ(p.values.size(), 3u * 32 * 32);
  EXPECT_NEAR(p.values[0], (0.5 - 0.48145466) / 0.26862954, 1e-5);
  EXPECT_NEAR(p.values[2 * 32 * 32], (0.5 - 0.40821073) / 0.27577711, 1e-5);
  const ClipPixels up = clip_preprocess(ImageRGB(8, 8), 32);  // enlarged: bicubic
  EXPECT_NEAR(up.values[0], -0.48145466 / 0.26862954, 1e-5);
}

}  // namespace
}  // namespace splat
