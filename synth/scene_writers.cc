#include "synth/scene_writers.h"

#include <filesystem>

namespace synth {

std::string file_stem(const std::string& name) {
  return std::filesystem::path(name).stem().string();
}

std::vector<uint8_t> object_mask(const splat::IdMap& m, int id) {
  std::vector<uint8_t> mask(m.ids.size());
  for (size_t i = 0; i < mask.size(); ++i) mask[i] = m.ids[i] == id;
  return mask;
}

}  // namespace synth
