#pragma once
// The tiny synthetic scene of the end-to-end tests: 16 views at 96x72 (views 0
// and 8 are the test views), 3,000 sparse points, generated into a
// temporary folder of this process.

#include <filesystem>
#include <string>

#include "synth/generator.h"
#include "tests/test_util.h"

namespace testing_util {

inline synth::SynthOptions tiny_scene_options() {
  synth::SynthOptions o;
  o.views = 16;
  o.width = 96;
  o.height = 72;
  o.supersample = 1;
  o.num_points = 3000;
  return o;
}

// <temp>/op2gs_<name>_<pid>, with the tiny scene generated into it; removed
// when the process exits.
inline std::filesystem::path generate_tiny_scene(const std::string& name) {
  const std::filesystem::path dir = process_temp_dir(name);
  synth::generate_scene(tiny_scene_options(), dir, true);
  return dir;
}

// A 6-view 64x48 scene written in both layouts: LERF-Mask into dir/lerf
// (with its true sparse/0) and 3DOVS into dir/ovs (2 segmented views).
inline void generate_small_scene_in_both_layouts(const std::filesystem::path& dir) {
  synth::SynthOptions o = tiny_scene_options();
  o.views = 6;
  o.width = 64;
  o.height = 48;
  o.num_points = 200;
  o.ovs_dir = dir / "ovs";
  o.ovs_test_views = 2;
  synth::generate_scene(o, dir / "lerf", true);
}

}  // namespace testing_util
