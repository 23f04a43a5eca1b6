#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <nlohmann/json.hpp>
#include <set>

#include "splat/atomic_file.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "synth/scene_writers.h"

namespace synth {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

json object_table(const World& world) {
  json objects = json::array();
  for (const SceneObject& o : world.objects)
    objects.push_back({{"id", o.id},
                       {"name", o.name},
                       {"shape", shape_name(o.shape)},
                       {"opacity", o.material.opacity},
                       {"hard_case", o.hard_case}});
  return objects;
}

}  // namespace

// The LERF-Mask layout: op2gs's own, or Gaussian Grouping's download (DEVA
// maps in object_mask/, black on the test views; no op2gs extras).
void write_lerf_mask_layout(const fs::path& dir, const SynthOptions& o, const World& world,
                            const RenderedScene& r, const std::vector<splat::IdMap>& sam2) {
  const int n = int(r.images.size());
  const bool download = o.format == OutputFormat::kLerfMaskDownload;
  tbb::parallel_for(0, n, [&](int i) {
    const bool test = i % o.test_every == 0;
    splat::write_image_rgb(dir / "images" / r.names[i], r.images[i]);
    if (!test) splat::write_image_rgb(dir / "images_train" / r.names[i], r.images[i]);
    const std::string map_name = file_stem(r.names[i]) + ".png";
    if (download) {
      const splat::IdMap black(sam2[i].width, sam2[i].height);
      splat::write_id_map(dir / "object_mask" / map_name, test ? black : sam2[i], 8);
      return;
    }
    splat::write_id_map(dir / "instance_gt" / map_name, r.instance_maps[i], 8);
    splat::write_id_map(dir / "sam2" / map_name, sam2[i], 8);
  });
  // test_mask/<k>/<query>.png, k = index among the test views sorted by name.
  std::set<std::string> queries;
  int k = 0;
  for (int i = 0; i < n; i += o.test_every, ++k) {
    for (const SceneObject& obj : world.objects) {
      const auto mask = object_mask(r.instance_maps[i], obj.id);
      if (std::none_of(mask.begin(), mask.end(), [](uint8_t v) { return v; })) continue;
      splat::write_mask_png(dir / "test_mask" / std::to_string(k) / (obj.name + ".png"),
                            r.images[i].width, r.images[i].height, mask);
      queries.insert(obj.name);
    }
  }
  if (download) {
    splat::write_colmap_model(r.sparse, dir / "sparse" / "0", splat::ColmapFormat::kBinary);
    // COLMAP's leftovers that the download carries.
    splat::write_colmap_model(r.sparse, dir / "distorted" / "sparse" / "0",
                              splat::ColmapFormat::kBinary);
    for (const char* cfg : {"fusion.cfg", "patch-match.cfg"})
      splat::write_text_atomically(dir / "stereo" / cfg, "");
    return;
  }
  std::string query_list;
  for (const SceneObject& obj : world.objects)
    if (queries.count(obj.name)) query_list += obj.name + "\n";
  splat::write_text_atomically(dir / "queries.txt", query_list);

  const json objects = object_table(world);
  splat::write_text_atomically(dir / "objects.json", objects.dump(2) + "\n");
  json sam2_names = json::array();
  for (const SceneObject& obj : world.objects)
    sam2_names.push_back({{"id", obj.id}, {"name", obj.name}});
  splat::write_text_atomically(dir / "sam2" / "objects.json", sam2_names.dump(2) + "\n");

  if (o.write_sparse)
    splat::write_colmap_model(r.sparse, dir / "sparse" / "0", splat::ColmapFormat::kText);

  json meta = {{"generator", "op2gs-synth"},
               {"seed", o.seed},
               {"views", o.views},
               {"width", o.width},
               {"height", o.height},
               {"supersample", o.supersample},
               {"test_every", o.test_every},
               {"fov_x_degrees", o.fov_x_degrees},
               {"orbit_radius", o.orbit_radius},
               {"orbit_height", o.orbit_height},
               {"look_at", {world.look_at.x(), world.look_at.y(), world.look_at.z()}},
               {"sparse_points", r.sparse.points3d.size()},
               {"sam2",
                {{"strength", o.sam2.strength},
                 {"boundary_jitter_px", o.sam2.boundary_jitter_px},
                 {"miss_probability", o.sam2.miss_probability},
                 {"miss_radius", o.sam2.miss_radius},
                 {"leak_probability", o.sam2.leak_probability},
                 {"leak_radius", o.sam2.leak_radius},
                 {"spurious_blobs", o.sam2.spurious_blobs},
                 {"spurious_radius", o.sam2.spurious_radius},
                 {"persistence_views", o.sam2.persistence_views}}},
               {"tracks",
                {{"id_switches", o.tracks.id_switches},
                 {"switch_run_views", o.tracks.switch_run_views},
                 {"merges", o.tracks.merges},
                 {"merge_run_views", o.tracks.merge_run_views},
                 {"late_objects", o.tracks.late_objects},
                 {"late_fraction", o.tracks.late_fraction}}},
               {"capture",
                {{"exposure_stops", o.capture.exposure_stops},
                 {"white_balance", o.capture.white_balance},
                 {"drift_correlation", o.capture.drift_correlation},
                 {"noise", o.capture.noise},
                 {"jpeg_quality", o.capture.jpeg_quality},
                 {"specular", o.capture.specular},
                 {"pose_rotation_degrees", o.capture.pose_rotation_degrees},
                 {"pose_translation", o.capture.pose_translation},
                 {"focal_error", o.capture.focal_error}}}};
  splat::write_text_atomically(dir / "scene.json", meta.dump(2) + "\n");
  splat::write_text_atomically(dir / "surfaces.json", world_to_json(world).dump(2) + "\n");
}

}  // namespace synth
