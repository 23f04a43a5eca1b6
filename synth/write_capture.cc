#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "synth/scene_writers.h"

namespace synth {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// Camera to world in the OpenGL convention (x right, y up, z back), as
// transforms.json holds it.
json opengl_pose(const splat::Camera& c, const Eigen::Matrix3d& world_turn) {
  Eigen::Matrix3d r = world_turn * c.R.transpose();
  r.col(1) *= -1;
  r.col(2) *= -1;
  const Eigen::Vector3d t = world_turn * c.center();
  json m = json::array();
  for (int i = 0; i < 3; ++i) m.push_back({r(i, 0), r(i, 1), r(i, 2), t(i)});
  m.push_back({0.0, 0.0, 0.0, 1.0});
  return m;
}

}  // namespace

// A posed capture as nerfstudio or instant-ngp writes it (generator.h).
void write_capture(const fs::path& dir, const SynthOptions& o, const World& world,
                   const RenderedScene& r, const std::vector<splat::IdMap>& sam2) {
  const int n = int(r.images.size());
  tbb::parallel_for(0, n, [&](int i) {
    splat::write_image_rgb(dir / "images" / r.names[i], r.images[i]);
    splat::write_id_map(dir / "sam2" / (file_stem(r.names[i]) + ".png"), sam2[i], 8);
  });
  json names = json::array();
  for (const SceneObject& obj : world.objects)
    names.push_back({{"id", obj.id}, {"name", obj.name}});
  splat::write_text_atomically(dir / "sam2" / "objects.json", names.dump(2) + "\n");

  const bool ns = o.format == OutputFormat::kNerfstudio;
  // nerfstudio turns COLMAP's world (x <-> y, z flipped) and says so.
  Eigen::Matrix3d turn = Eigen::Matrix3d::Identity();
  if (ns) turn << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  const splat::Camera& c0 = r.posed_cameras.front();
  json t = {{"w", c0.width}, {"h", c0.height}, {"fl_x", c0.fx},
            {"fl_y", c0.fy}, {"cx", c0.cx},    {"cy", c0.cy}};
  if (!ns) {
    t["camera_angle_x"] = 2 * std::atan(0.5 * c0.width / c0.fx);
    t["camera_angle_y"] = 2 * std::atan(0.5 * c0.height / c0.fy);
    t["aabb_scale"] = 4;
  }
  if (!o.distortion.empty())
    for (int k = 0; k < 4; ++k) t[std::array{"k1", "k2", "p1", "p2"}[k]] = o.distortion[k];
  if (ns) {
    t["camera_model"] = o.distortion.empty() ? "PINHOLE" : "OPENCV";
    t["applied_transform"] = {{0.0, 1.0, 0.0, 0.0}, {1.0, 0.0, 0.0, 0.0}, {0.0, 0.0, -1.0, 0.0}};
    t["ply_file_path"] = "sparse_pc.ply";
  }
  json frames = json::array();
  for (int i = 0; i < n; ++i) {
    // instant-ngp's captures often name their photos without extension.
    const std::string path = "images/" + (ns ? r.names[i] : file_stem(r.names[i]));
    frames.push_back(
        {{"file_path", path}, {"transform_matrix", opengl_pose(r.posed_cameras[i], turn)}});
  }
  t["frames"] = frames;
  splat::write_text_atomically(dir / "transforms.json", t.dump(4) + "\n");
  if (!ns) return;
  std::string ply = fmt::format(
      "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n"
      "property float z\nproperty uint8 red\nproperty uint8 green\nproperty uint8 blue\n"
      "end_header\n",
      r.sparse.points3d.size());
  for (const auto& [id, p] : r.sparse.points3d) {
    const Eigen::Vector3d x = turn * p.xyz;
    ply += fmt::format("{:.6f} {:.6f} {:.6f} {} {} {}\n", x.x(), x.y(), x.z(), p.rgb[0], p.rgb[1],
                       p.rgb[2]);
  }
  splat::write_text_atomically(dir / "sparse_pc.ply", ply);
}

}  // namespace synth
