#pragma once
// The tiny CLIP of the tests: the ViT-B/16 architecture at a small width, with
// the reference outputs of scripts/make_tiny_clip.py (tests/fixtures/tiny_clip).
// Needs OP2GS_SOURCE_DIR (tests/CMakeLists.txt defines it).

#include <filesystem>

namespace testing_util {

inline std::filesystem::path tiny_clip_dir() {
  return std::filesystem::path(OP2GS_SOURCE_DIR) / "tests" / "fixtures" / "tiny_clip";
}

}  // namespace testing_util
