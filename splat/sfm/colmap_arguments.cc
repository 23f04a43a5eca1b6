#include "splat/sfm/colmap_arguments.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace splat {

std::string colmap_list(const std::vector<double>& values) {
  return fmt::format("{}", fmt::join(values, ","));
}

std::vector<std::string> feature_extractor_arguments(const FeatureExtraction& e) {
  std::vector<std::string> args = {"--database_path",
                                   e.database.string(),
                                   "--image_path",
                                   e.images.string(),
                                   "--ImageReader.single_camera",
                                   e.single_camera ? "1" : "0",
                                   "--ImageReader.camera_model",
                                   e.camera_model,
                                   "--SiftExtraction.use_gpu",
                                   e.gpu ? "1" : "0",
                                   "--SiftExtraction.max_image_size",
                                   std::to_string(e.max_image_size)};
  if (!e.camera_params.empty())
    args.insert(args.end(), {"--ImageReader.camera_params", colmap_list(e.camera_params)});
  if (!e.image_list.empty()) args.insert(args.end(), {"--image_list_path", e.image_list.string()});
  if (e.threads)
    args.insert(args.end(), {"--SiftExtraction.num_threads", std::to_string(e.threads)});
  return args;
}

std::string matcher_command(const Matching& m) {
  return m.sequential ? "sequential_matcher" : "exhaustive_matcher";
}

std::vector<std::string> matcher_arguments(const Matching& m) {
  std::vector<std::string> args = {"--database_path", m.database.string(), "--SiftMatching.use_gpu",
                                   m.gpu ? "1" : "0"};
  if (m.sequential) {
    args.insert(args.end(),
                {"--SequentialMatching.overlap", std::to_string(m.sequential_overlap),
                 "--SequentialMatching.loop_detection", m.vocab_tree.empty() ? "0" : "1"});
    if (!m.vocab_tree.empty())
      args.insert(args.end(), {"--SequentialMatching.vocab_tree_path", m.vocab_tree.string()});
  }
  return args;
}

namespace {
// Bundle adjustment leaves known intrinsics as they are.
void add_fixed_intrinsics(std::vector<std::string>& args) {
  args.insert(args.end(),
              {"--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point", "0",
               "--Mapper.ba_refine_extra_params", "0"});
}
}  // namespace

std::vector<std::string> point_triangulator_arguments(const std::filesystem::path& database,
                                                      const std::filesystem::path& images,
                                                      const std::filesystem::path& known_model,
                                                      const std::filesystem::path& output) {
  std::vector<std::string> args = {"--database_path", database.string(), "--image_path",
                                   images.string(),   "--input_path",    known_model.string(),
                                   "--output_path",   output.string()};
  add_fixed_intrinsics(args);
  return args;
}

std::vector<std::string> mapper_arguments(const std::filesystem::path& database,
                                          const std::filesystem::path& images,
                                          const std::filesystem::path& output,
                                          bool known_intrinsics, int threads) {
  std::vector<std::string> args = {"--database_path", database.string(), "--image_path",
                                   images.string(),   "--output_path",   output.string()};
  if (known_intrinsics) add_fixed_intrinsics(args);
  if (threads) args.insert(args.end(), {"--Mapper.num_threads", std::to_string(threads)});
  return args;
}

std::vector<std::string> image_undistorter_arguments(const std::filesystem::path& images,
                                                     const std::filesystem::path& model,
                                                     const std::filesystem::path& output) {
  return {"--image_path",  images.string(), "--input_path",  model.string(),
          "--output_path", output.string(), "--output_type", "COLMAP"};
}

}  // namespace splat
