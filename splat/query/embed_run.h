#pragma once
// op2gs-embed: one CLIP image embedding per object (paper, "Object Embedding
// Aggregation"). For each object, its mask M = [S_j > tau] is rendered in
// every training view; the N views where it covers the most pixels are kept;
// in each, the masked image (pixels outside M set to the crop background) is
// cut out as a square around the mask's box with a margin, resized to CLIP's
// input size and encoded; the N normalised embeddings are averaged and the
// mean normalised. Writes, into the output folder:
//
//   embeddings.json        per object: the chosen views, their mask areas, the
//                          crops, and the embedding
//   crops/<id>/<stem>.png  the crops CLIP saw, for a person to check

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "splat/image.h"
#include "splat/scene.h"
#include "splat/view_split.h"

namespace splat {

struct EmbedRunOptions {
  SceneOptions scene;
  SplitRule split = SplitRule::kAuto;
  std::filesystem::path model;     // stage-two checkpoint or PLY with labels
  std::filesystem::path clip_dir;  // model.safetensors, config.json, vocab.json, merges.txt
  std::vector<int32_t> objects;    // only these objects (default: all)
  int views_per_object = 5;        // N
  float tau = 0.5f;                // mask threshold on S_j
  // Square crop side = the mask box's longer side times (1 + 2 margin).
  float margin = 0.1f;
  int min_mask_pixels = 64;  // smaller masks are not used as views
  std::array<float, 3> crop_background = {0, 0, 0};
  void Check() const;  // throws std::invalid_argument
};

struct ObjectView {
  std::string view;  // image name
  int64_t area = 0;  // mask pixels
  std::string crop;  // crop file, relative to the output folder
};

struct ObjectEmbedding {
  int32_t id = 0;
  std::vector<ObjectView> views;
  Eigen::VectorXf embedding;  // unit length
};

struct ObjectEmbeddings {
  std::filesystem::path clip_dir;
  std::vector<ObjectEmbedding> objects;  // by ID
  std::vector<int32_t> unseen;           // objects without a usable view
};

ObjectEmbeddings run_embed(const std::filesystem::path& scene_dir, const std::filesystem::path& out,
                           const EmbedRunOptions& options);

// The crop of the paper's C(M ⊗ I): the image inside the mask (background
// elsewhere), in a square around the mask's bounding box enlarged by the
// margin on each side; parts outside the image are background too. The mask
// must not be empty.
ImageRGB masked_square_crop(const ImageRGB& image, const std::vector<uint8_t>& mask, float margin,
                            const std::array<float, 3>& background);

// Reads embeddings.json. Throws InputError naming the file when malformed.
ObjectEmbeddings read_object_embeddings(const std::filesystem::path& file);

}  // namespace splat
