#include "splat/clip/clip_model.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "splat/atomic_file.h"
#include "splat/clip/safetensors.h"
#include "splat/error.h"
#include "splat/json_integer.h"

namespace splat {
namespace fs = std::filesystem;

namespace {

constexpr float kLayerNormEps = 1e-5f;
// CLIP's preprocessing constants (preprocessor_config.json of the release).
constexpr float kMean[3] = {0.48145466f, 0.4578275f, 0.40821073f};
constexpr float kStd[3] = {0.26862954f, 0.26130258f, 0.27577711f};

// ------------------------------------------------------------------ loading

class WeightReader {
 public:
  explicit WeightReader(const fs::path& file) : file_(file) {}

  RowMatrix matrix(const std::string& name, int64_t rows, int64_t cols) const {
    return matrix(name, {rows, cols}, rows, cols);
  }
  // A tensor of any shape read as a (rows, cols) matrix in C order.
  RowMatrix matrix(const std::string& name, const std::vector<int64_t>& shape, int64_t rows,
                   int64_t cols) const {
    Tensor t = file_.read(name, shape);
    return Eigen::Map<RowMatrix>(t.values.data(), rows, cols);
  }
  Eigen::VectorXf vector(const std::string& name, int64_t size) const {
    Tensor t = file_.read(name, {size});
    return Eigen::Map<Eigen::VectorXf>(t.values.data(), size);
  }
  const std::vector<int64_t>& shape(const std::string& name, size_t dims) const {
    const auto& s = file_.shape(name);
    if (s.size() != dims)
      throw InputError(file_.path(),
                       fmt::format("tensor {} should have {} dimensions", name, dims));
    return s;
  }
  bool has(const std::string& name) const { return file_.has(name); }
  const fs::path& path() const { return file_.path(); }

 private:
  SafetensorsFile file_;
};

TransformerBlock read_block(const WeightReader& r, const std::string& prefix, int64_t width) {
  const int64_t inner = r.shape(prefix + "mlp.fc1.weight", 2)[0];
  TransformerBlock b;
  b.ln1_weight = r.vector(prefix + "layer_norm1.weight", width);
  b.ln1_bias = r.vector(prefix + "layer_norm1.bias", width);
  b.ln2_weight = r.vector(prefix + "layer_norm2.weight", width);
  b.ln2_bias = r.vector(prefix + "layer_norm2.bias", width);
  b.qkv_weight.resize(3 * width, width);
  b.qkv_bias.resize(3 * width);
  const char* names[3] = {"q_proj", "k_proj", "v_proj"};
  for (int k = 0; k < 3; ++k) {
    const std::string p = prefix + "self_attn." + names[k];
    b.qkv_weight.middleRows(k * width, width) = r.matrix(p + ".weight", width, width);
    b.qkv_bias.segment(k * width, width) = r.vector(p + ".bias", width);
  }
  b.out_weight = r.matrix(prefix + "self_attn.out_proj.weight", width, width);
  b.out_bias = r.vector(prefix + "self_attn.out_proj.bias", width);
  b.fc1_weight = r.matrix(prefix + "mlp.fc1.weight", inner, width);
  b.fc1_bias = r.vector(prefix + "mlp.fc1.bias", inner);
  b.fc2_weight = r.matrix(prefix + "mlp.fc2.weight", width, inner);
  b.fc2_bias = r.vector(prefix + "mlp.fc2.bias", width);
  return b;
}

std::vector<TransformerBlock> read_blocks(const WeightReader& r, const std::string& tower,
                                          int64_t width) {
  std::vector<TransformerBlock> blocks;
  for (int i = 0;; ++i) {
    const std::string prefix = fmt::format("{}.encoder.layers.{}.", tower, i);
    if (!r.has(prefix + "mlp.fc1.weight")) break;
    blocks.push_back(read_block(r, prefix, width));
  }
  if (blocks.empty())
    throw InputError(r.path(), fmt::format("no {}.encoder.layers (not a CLIP model)", tower));
  return blocks;
}

// Attention heads of a tower from config.json ("text_config" or the older
// "text_config_dict"), or 64-wide heads.
int heads_of(const fs::path& config, const std::string& tower, int64_t width) {
  if (fs::exists(config)) {
    try {
      const auto c = nlohmann::json::parse(read_text_file(config));
      for (const std::string& key : {tower + "_config", tower + "_config_dict"})
        if (c.contains(key) && c[key].is_object() && c[key].contains("num_attention_heads") &&
            c[key]["num_attention_heads"].is_number_integer())
          return json_integer<int>(c[key]["num_attention_heads"], config, "num_attention_heads");
    } catch (const nlohmann::json::exception& e) {
      throw InputError(config, std::string("malformed JSON: ") + e.what());
    }
  }
  return int(std::max<int64_t>(1, width / 64));
}

ClipVisionWeights read_vision(const WeightReader& r, const fs::path& config) {
  ClipVisionWeights v;
  const std::vector<int64_t> patch = r.shape("vision_model.embeddings.patch_embedding.weight", 4);
  const int64_t width = patch[0];
  if (patch[1] != 3 || patch[2] != patch[3])
    throw InputError(r.path(),
                     "vision_model.embeddings.patch_embedding.weight is not (W, 3, P, P)");
  v.patch_size = int(patch[2]);
  const int64_t positions = r.shape("vision_model.embeddings.position_embedding.weight", 2)[0];
  const int grid = int(std::lround(std::sqrt(double(positions - 1))));
  if (int64_t(grid) * grid + 1 != positions)
    throw InputError(r.path(), "the vision position embedding is not a square grid plus one");
  v.image_size = grid * v.patch_size;
  v.heads = heads_of(config, "vision", width);
  if (width % v.heads) throw InputError(config, "vision width is not a multiple of the heads");
  v.patch_weight = r.matrix("vision_model.embeddings.patch_embedding.weight", patch, width,
                            3 * int64_t(v.patch_size) * v.patch_size);
  v.class_embedding = r.vector("vision_model.embeddings.class_embedding", width);
  v.position_embedding =
      r.matrix("vision_model.embeddings.position_embedding.weight", positions, width);
  v.pre_ln_weight = r.vector("vision_model.pre_layrnorm.weight", width);
  v.pre_ln_bias = r.vector("vision_model.pre_layrnorm.bias", width);
  v.blocks = read_blocks(r, "vision_model", width);
  v.post_ln_weight = r.vector("vision_model.post_layernorm.weight", width);
  v.post_ln_bias = r.vector("vision_model.post_layernorm.bias", width);
  const int64_t embedding = r.shape("visual_projection.weight", 2)[0];
  v.projection = r.matrix("visual_projection.weight", embedding, width);
  return v;
}

ClipTextWeights read_text(const WeightReader& r, const fs::path& config) {
  ClipTextWeights t;
  const auto& tokens = r.shape("text_model.embeddings.token_embedding.weight", 2);
  const int64_t width = tokens[1];
  t.heads = heads_of(config, "text", width);
  if (width % t.heads) throw InputError(config, "text width is not a multiple of the heads");
  t.token_embedding = r.matrix("text_model.embeddings.token_embedding.weight", tokens[0], width);
  const int64_t context = r.shape("text_model.embeddings.position_embedding.weight", 2)[0];
  t.position_embedding =
      r.matrix("text_model.embeddings.position_embedding.weight", context, width);
  t.blocks = read_blocks(r, "text_model", width);
  t.final_ln_weight = r.vector("text_model.final_layer_norm.weight", width);
  t.final_ln_bias = r.vector("text_model.final_layer_norm.bias", width);
  const int64_t embedding = r.shape("text_projection.weight", 2)[0];
  t.projection = r.matrix("text_projection.weight", embedding, width);
  return t;
}

// ------------------------------------------------------------------ forward

RowMatrix layer_norm(const RowMatrix& x, const Eigen::VectorXf& weight,
                     const Eigen::VectorXf& bias) {
  RowMatrix y(x.rows(), x.cols());
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const float mean = x.row(i).mean();
    const float variance = (x.row(i).array() - mean).square().mean();
    const float scale = 1.0f / std::sqrt(variance + kLayerNormEps);
    y.row(i) =
        ((x.row(i).array() - mean) * scale * weight.transpose().array() + bias.transpose().array())
            .matrix();
  }
  return y;
}

RowMatrix linear(const RowMatrix& x, const RowMatrix& weight, const Eigen::VectorXf& bias) {
  RowMatrix y(x.rows(), weight.rows());
  y.noalias() = x * weight.transpose();
  y.rowwise() += bias.transpose();
  return y;
}

RowMatrix attention(const RowMatrix& h, const TransformerBlock& b, int heads, bool causal) {
  const Eigen::Index tokens = h.rows(), width = h.cols(), d = width / heads;
  const RowMatrix qkv = linear(h, b.qkv_weight, b.qkv_bias);
  const float scale = 1.0f / std::sqrt(float(d));
  RowMatrix mixed(tokens, width), scores(tokens, tokens);
  for (int head = 0; head < heads; ++head) {
    const auto q = qkv.middleCols(head * d, d);
    const auto k = qkv.middleCols(width + head * d, d);
    const auto v = qkv.middleCols(2 * width + head * d, d);
    scores.noalias() = (q * scale) * k.transpose();
    for (Eigen::Index i = 0; i < tokens; ++i) {
      const Eigen::Index visible = causal ? i + 1 : tokens;
      auto row = scores.row(i).head(visible).array();
      row = (row - row.maxCoeff()).exp();
      row /= row.sum();
      scores.row(i).tail(tokens - visible).setZero();
    }
    mixed.middleCols(head * d, d).noalias() = scores * v;
  }
  return linear(mixed, b.out_weight, b.out_bias);
}

void run_block(RowMatrix& x, const TransformerBlock& b, int heads, bool causal) {
  x += attention(layer_norm(x, b.ln1_weight, b.ln1_bias), b, heads, causal);
  RowMatrix h = linear(layer_norm(x, b.ln2_weight, b.ln2_bias), b.fc1_weight, b.fc1_bias);
  h = h.array() / (1.0f + (-1.702f * h.array()).exp());  // QuickGELU: h sigmoid(1.702 h)
  x += linear(h, b.fc2_weight, b.fc2_bias);
}

// The (patches, 3 P P) matrix of a (3, S, S) image: each row one patch in the
// (channel, row, column) order of the convolution's weight.
RowMatrix patches_of(const ClipPixels& pixels, int patch) {
  const int grid = pixels.size / patch, S = pixels.size;
  RowMatrix p(grid * grid, 3 * patch * patch);
  for (int gy = 0; gy < grid; ++gy)
    for (int gx = 0; gx < grid; ++gx) {
      float* row = p.row(gy * grid + gx).data();
      for (int c = 0; c < 3; ++c)
        for (int y = 0; y < patch; ++y)
          for (int x = 0; x < patch; ++x)
            *row++ = pixels.values[(size_t(c) * S + gy * patch + y) * S + gx * patch + x];
    }
  return p;
}

}  // namespace

fs::path default_clip_dir() {
  if (const char* dir = std::getenv("OP2GS_CLIP_DIR"); dir && *dir) return dir;
  const char* home = std::getenv("HOME");
  return fs::path(home ? home : ".") / ".cache/op2gs/clip-vit-base-patch16";
}

ClipFiles ClipFiles::in(const fs::path& dir) {
  ClipFiles f{dir / "model.safetensors", dir / "config.json", dir / "vocab.json",
              dir / "merges.txt"};
  for (const fs::path& p : {f.model, f.vocab, f.merges})
    if (!fs::exists(p))
      throw InputError(p,
                       "missing; download model.safetensors, config.json, vocab.json and "
                       "merges.txt of openai/clip-vit-base-patch16 into this folder "
                       "(scripts/get_clip.sh, docs/clip.md)");
  return f;
}

ClipPixels clip_preprocess(const ImageRGB& image, int size) {
  ImageRGB resized;
  if (image.width >= size && image.height >= size) {
    resized = resize_area(image, size, size);
  } else {
    const cv::Mat in(image.height, image.width, CV_32FC3, const_cast<float*>(image.data.data()));
    resized = ImageRGB(size, size);
    cv::Mat out(size, size, CV_32FC3, resized.data.data());
    cv::resize(in, out, out.size(), 0, 0, cv::INTER_CUBIC);
  }
  ClipPixels p;
  p.size = size;
  p.values.resize(size_t(3) * size * size);
  for (int c = 0; c < 3; ++c)
    for (size_t i = 0; i < size_t(size) * size; ++i)
      p.values[c * size_t(size) * size + i] =
          (std::clamp(resized.data[3 * i + c], 0.f, 1.f) - kMean[c]) / kStd[c];
  return p;
}

ClipModel ClipModel::load(const ClipFiles& files) {
  const WeightReader reader(files.model);
  return ClipModel(read_vision(reader, files.config), read_text(reader, files.config));
}

ClipModel::ClipModel(ClipVisionWeights vision, ClipTextWeights text)
    : vision_(std::move(vision)),
      text_(std::move(text)),
      end_token_(int32_t(text_.token_embedding.rows() - 1)) {}

Eigen::VectorXf ClipModel::encode_image(const ClipPixels& pixels) const {
  const ClipVisionWeights& v = vision_;
  if (pixels.size != v.image_size ||
      pixels.values.size() != size_t(3) * v.image_size * v.image_size)
    throw std::invalid_argument(
        fmt::format("CLIP expects {0}x{0} pixels, got {1}x{1}", v.image_size, pixels.size));
  const Eigen::Index width = v.class_embedding.size();
  const RowMatrix patches = patches_of(pixels, v.patch_size);
  RowMatrix x(patches.rows() + 1, width);
  x.row(0) = v.class_embedding.transpose();
  x.bottomRows(patches.rows()).noalias() = patches * v.patch_weight.transpose();
  x += v.position_embedding;
  x = layer_norm(x, v.pre_ln_weight, v.pre_ln_bias);
  for (const TransformerBlock& b : v.blocks) run_block(x, b, v.heads, false);
  const RowMatrix pooled = layer_norm(x.topRows(1), v.post_ln_weight, v.post_ln_bias);
  return v.projection * pooled.row(0).transpose();
}

Eigen::VectorXf ClipModel::encode_text(const std::vector<int32_t>& ids) const {
  const ClipTextWeights& t = text_;
  if (ids.empty() || ids.size() > size_t(t.position_embedding.rows()))
    throw std::invalid_argument(fmt::format("CLIP text takes 1 to {} tokens, got {}",
                                            t.position_embedding.rows(), ids.size()));
  RowMatrix x(Eigen::Index(ids.size()), t.token_embedding.cols());
  for (size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] < 0 || ids[i] >= t.token_embedding.rows())
      throw std::invalid_argument(fmt::format("token ID {} is outside the vocabulary", ids[i]));
    x.row(Eigen::Index(i)) =
        t.token_embedding.row(ids[i]) + t.position_embedding.row(Eigen::Index(i));
  }
  for (const TransformerBlock& b : t.blocks) run_block(x, b, t.heads, true);
  size_t pool = ids.size() - 1;
  for (size_t i = 0; i < ids.size(); ++i)
    if (ids[i] == end_token_) {
      pool = i;
      break;
    }
  const RowMatrix pooled =
      layer_norm(x.middleRows(Eigen::Index(pool), 1), t.final_ln_weight, t.final_ln_bias);
  return t.projection * pooled.row(0).transpose();
}

bool ClipModel::is_full_size() const {
  return vision_.blocks.size() >= 12 && text_.blocks.size() >= 12 && embedding_size() >= 512;
}

}  // namespace splat
