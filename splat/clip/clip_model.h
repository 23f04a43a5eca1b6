#pragma once
// CLIP's image and text encoders (Radford et al. 2021), in the layout of the
// Hugging Face `openai/clip-vit-base-patch16` release. Every width, depth and
// the image size are read from the tensors' shapes, so the same code runs the
// ViT-B/16 release and the tiny test fixture; the attention head counts come
// from config.json (64-wide heads when it is absent, as in every OpenAI CLIP).
//
// Image encoder: patch embedding (a strided convolution without bias), class
// token, position embedding, pre-LayerNorm, pre-norm transformer blocks
// (self-attention, QuickGELU MLP), post-LayerNorm of the class token, linear
// projection. Text encoder: token and position embeddings, the same blocks
// with a causal mask, final LayerNorm, the end-of-text token's state, linear
// projection. Both return the projected, unnormalised embedding.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "splat/image.h"

namespace splat {

// The files of a CLIP release, in one folder.
struct ClipFiles {
  std::filesystem::path model;   // model.safetensors
  std::filesystem::path config;  // config.json (optional: may not exist)
  std::filesystem::path vocab;   // vocab.json
  std::filesystem::path merges;  // merges.txt

  // The files in `dir`. Throws InputError naming the first missing file, with
  // the instructions to download them (docs/clip.md).
  static ClipFiles in(const std::filesystem::path& dir);
};

// Where the CLIP files are when no folder is named (op2gs-embed and
// op2gs-query without --clip): $OP2GS_CLIP_DIR, else
// ~/.cache/op2gs/clip-vit-base-patch16, where scripts/get_clip.sh puts them.
std::filesystem::path default_clip_dir();

using RowMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// One pre-norm transformer block's weights. Linear weights are (out, in), as
// stored.
struct TransformerBlock {
  Eigen::VectorXf ln1_weight, ln1_bias, ln2_weight, ln2_bias;
  RowMatrix qkv_weight;  // (3 width, width): q, k, v stacked
  Eigen::VectorXf qkv_bias;
  RowMatrix out_weight;
  Eigen::VectorXf out_bias;
  RowMatrix fc1_weight, fc2_weight;
  Eigen::VectorXf fc1_bias, fc2_bias;
};

struct ClipVisionWeights {
  int image_size = 0, patch_size = 0, heads = 0;
  RowMatrix patch_weight;  // (width, 3 * patch * patch)
  Eigen::VectorXf class_embedding;
  RowMatrix position_embedding;  // (patches + 1, width)
  Eigen::VectorXf pre_ln_weight, pre_ln_bias, post_ln_weight, post_ln_bias;
  std::vector<TransformerBlock> blocks;
  RowMatrix projection;  // (embedding, width)
};

struct ClipTextWeights {
  int heads = 0;
  RowMatrix token_embedding;     // (vocabulary, width)
  RowMatrix position_embedding;  // (context, width)
  std::vector<TransformerBlock> blocks;
  Eigen::VectorXf final_ln_weight, final_ln_bias;
  RowMatrix projection;  // (embedding, width)
};

// Pixels ready for the image encoder: (3, size, size), channel-major,
// normalised with CLIP's per-channel mean and standard deviation.
struct ClipPixels {
  int size = 0;
  std::vector<float> values;
};

// An RGB image in [0, 1] resized to size x size (area filter when shrinking,
// bicubic when enlarging, as Pillow's antialiased bicubic resize of the CLIP
// preprocessor behaves) and normalised.
ClipPixels clip_preprocess(const ImageRGB& image, int size);

class ClipModel {
 public:
  // Reads the weights of both encoders. Throws InputError naming the file for
  // a missing tensor or a shape that does not fit.
  static ClipModel load(const ClipFiles& files);
  ClipModel(ClipVisionWeights vision, ClipTextWeights text);

  Eigen::VectorXf encode_image(const ClipPixels& pixels) const;
  // token_ids as ClipTokenizer::encode returns them; pooled at the first
  // end-of-text token (the highest ID of the vocabulary), or the last token.
  Eigen::VectorXf encode_text(const std::vector<int32_t>& token_ids) const;

  int image_size() const { return vision_.image_size; }
  int embedding_size() const { return int(vision_.projection.rows()); }
  size_t context_length() const { return size_t(text_.position_embedding.rows()); }
  // Whether the model has the size of a released CLIP (ViT-B/16, the paper's,
  // or a larger one): at least 12 transformer blocks in each encoder and
  // embeddings of at least 512 values. The tiny random CLIP of the tests (2
  // blocks, 32 values) has not, and its similarities mean nothing.
  bool is_full_size() const;

 private:
  ClipVisionWeights vision_;
  ClipTextWeights text_;
  int32_t end_token_ = 0;
};

}  // namespace splat
