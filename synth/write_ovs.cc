#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/npy.h"
#include "synth/scene_writers.h"

namespace synth {
namespace fs = std::filesystem;

namespace {

// LLFF poses_bounds.npy: per view a 3x5 matrix [R | t | (H, W, f)] of the
// camera-to-world pose with columns (down, right, backwards), then near, far.
void write_poses_bounds(const fs::path& file, const RenderedScene& r, const World& world) {
  std::vector<double> rows;
  for (const splat::Camera& c : r.posed_cameras) {
    const Eigen::Matrix3d c2w = c.R.transpose();
    Eigen::Matrix<double, 3, 5> m;
    m.col(0) = c2w.col(1);
    m.col(1) = c2w.col(0);
    m.col(2) = -c2w.col(2);
    m.col(3) = c.center();
    m.col(4) = Eigen::Vector3d(c.height, c.width, c.fx);
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 5; ++col) rows.push_back(m(row, col));
    const double far = (c.center().norm() + world.enclosure_radius);
    rows.push_back(0.1);
    rows.push_back(far);
  }
  splat::write_npy_f64(file, rows, {r.cameras.size(), 17});
}

}  // namespace

void write_ovs_layout(const fs::path& dir, const RenderedScene& r,
                      const std::vector<splat::IdMap>& sam2, const World& world, int test_views,
                      bool prepared) {
  const int n = int(r.images.size());
  const int digits = std::max(2, int(std::to_string(n - 1).size()));
  auto ovs_name = [&](int i) { return fmt::format("{:0{}d}", i, digits); };
  std::string classes;
  for (const SceneObject& o : world.objects) classes += o.name + "\n";
  splat::write_text_atomically(dir / "segmentations" / "classes.txt", classes);
  tbb::parallel_for(0, n, [&](int i) {
    splat::write_image_rgb(dir / "images" / (ovs_name(i) + ".png"), r.images[i]);
    splat::write_id_map(dir / (prepared ? "object_mask_deva" : "sam2") / (ovs_name(i) + ".png"),
                        sam2[i], 8);
  });
  // Test views spread over the sequence; in 3DOVS they are training views too.
  for (int k = 0; k < test_views; ++k) {
    const int i = int(std::lround((k + 0.5) * n / test_views - 0.5));
    for (const SceneObject& o : world.objects)
      splat::write_mask_png(dir / "segmentations" / ovs_name(i) / (o.name + ".png"),
                            r.images[i].width, r.images[i].height,
                            object_mask(r.instance_maps[i], o.id));
  }
  if (!prepared) {
    write_poses_bounds(dir / "poses_bounds.npy", r, world);
    return;
  }
  splat::ColmapModel model = r.sparse;  // the true cameras, under the 3DOVS names
  for (auto& [id, image] : model.images) image.name = ovs_name(int(id) - 1) + ".png";
  splat::write_colmap_model(model, dir / "sparse" / "0", splat::ColmapFormat::kBinary);
}

}  // namespace synth
