#include "synth/generator.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <set>

#include "splat/atomic_file.h"
#include "splat/camera_distortion.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/npy.h"
#include "synth/render_scene.h"
#include "synth/scene_writers.h"

namespace synth {
namespace fs = std::filesystem;
using json = nlohmann::json;

void SynthOptions::Check() const {
  auto fail = [](const std::string& s) { throw std::invalid_argument(s); };
  if (views < 2) fail(fmt::format("views must be >= 2, not {}", views));
  if (width < 8 || height < 8) fail(fmt::format("image size {}x{} is too small", width, height));
  if (supersample < 1 || supersample > 8) fail("supersample must be in 1..8");
  if (test_every < 2) fail("test_every must be >= 2");
  if (!(fov_x_degrees > 5 && fov_x_degrees < 150)) fail("fov_x_degrees must be in (5, 150)");
  if (!(orbit_radius > 0.5)) fail("orbit_radius must be > 0.5");
  if (num_points < 0) fail("num_points must be >= 0");
  if (!ovs_dir.empty() && (ovs_test_views < 1 || ovs_test_views > views))
    fail("ovs_test_views must be in 1..views");
  if (!distortion.empty() && distortion.size() != 4)
    fail("distortion is four OPENCV coefficients: k1 k2 p1 p2");
  if (!distortion.empty() && format == OutputFormat::kLerfMaskDownload)
    fail("the LERF-Mask download holds undistorted photos: no distortion");
  if (ovs_prepared && ovs_dir.empty()) fail("a prepared 3DOVS world needs its folder");
  sam2.Check();
  tracks.Check();
  capture.Check();
}

void generate_scene(const SynthOptions& o, const fs::path& out_dir, bool force) {
  o.Check();
  for (const fs::path& dir : {out_dir, o.ovs_dir})
    if (!dir.empty() && fs::exists(dir) && !force)
      throw std::runtime_error(dir.string() + ": already exists (use --force to replace it)");
  World world = default_world(o.seed);
  world.specular = o.capture.specular;
  spdlog::info("rendering {} views at {}x{} ({}x{} samples per pixel)", o.views, o.width, o.height,
               o.supersample, o.supersample);
  const RenderedScene r = render_scene(o, world);

  std::vector<int> ids;
  for (const SceneObject& obj : world.objects) ids.push_back(obj.id);
  std::vector<splat::IdMap> sam2 = corrupt_sequence_like_sam2(r.instance_maps, ids, o.sam2, o.seed);
  const std::vector<int> switched =
      apply_track_errors(sam2, r.instance_maps, ids, o.tracks, o.seed);
  if (!switched.empty()) spdlog::info("{} track IDs switched", switched.size());

  // Each folder is built aside and swapped in whole (--force replaces it).
  spdlog::info("writing the scene to {}", out_dir.string());
  splat::StagedFolder scene(out_dir, splat::StagedFolder::Target::kOwned);
  if (o.format == OutputFormat::kNerfstudio || o.format == OutputFormat::kInstantNgp)
    write_capture(scene.path(), o, world, r, sam2);
  else
    write_lerf_mask_layout(scene.path(), o, world, r, sam2);
  scene.commit();

  if (!o.ovs_dir.empty()) {
    spdlog::info("writing the 3DOVS world to {}", o.ovs_dir.string());
    splat::StagedFolder ovs(o.ovs_dir, splat::StagedFolder::Target::kOwned);
    write_ovs_layout(ovs.path(), r, sam2, world, o.ovs_test_views, o.ovs_prepared);
    ovs.commit();
  }
}

}  // namespace synth
