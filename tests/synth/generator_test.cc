#include "synth/generator.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>

#include "splat/colmap_model.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/scene.h"
#include "synth/raytracer.h"
#include "synth/render_scene.h"
#include "tests/test_util.h"

namespace synth {
namespace {

namespace fs = std::filesystem;
using testing_util::read_file;
using testing_util::TempDir;

SynthOptions tiny() {
  SynthOptions o;
  o.views = 10;
  o.width = 80;
  o.height = 60;
  o.supersample = 1;
  o.num_points = 600;
  return o;
}

size_t count_files(const fs::path& dir) {
  size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.is_regular_file();
  return n;
}

TEST(Generator, WritesTheLerfMaskLayout) {
  TempDir dir;
  generate_scene(tiny(), dir / "scene", false);
  const fs::path s = dir / "scene";
  EXPECT_EQ(count_files(s / "images"), 10u);
  EXPECT_EQ(count_files(s / "images_train"), 8u);  // views 0 and 8 are test views
  EXPECT_FALSE(fs::exists(s / "images_train" / "frame_00000.png"));
  EXPECT_FALSE(fs::exists(s / "images_train" / "frame_00008.png"));
  EXPECT_EQ(count_files(s / "instance_gt"), 10u);
  EXPECT_EQ(count_files(s / "sam2"), 11u);  // + objects.json
  EXPECT_TRUE(fs::is_directory(s / "test_mask" / "0"));
  EXPECT_TRUE(fs::is_directory(s / "test_mask" / "1"));
  EXPECT_FALSE(fs::exists(s / "test_mask" / "2"));
  const auto objects = nlohmann::json::parse(read_file(s / "objects.json"));
  EXPECT_EQ(objects.size(), 10u);
  const std::string queries = read_file(s / "queries.txt");
  EXPECT_NE(queries.find("red ball\n"), std::string::npos);
  // Every test mask is binary 0/255 and matches instance_gt of its view.
  const splat::IdMap gt = splat::read_id_map(s / "instance_gt" / "frame_00008.png");
  const splat::IdMap mask = splat::read_id_map(s / "test_mask" / "1" / "red ball.png");
  for (size_t i = 0; i < gt.ids.size(); ++i) ASSERT_EQ(mask.ids[i], gt.ids[i] == 1 ? 255 : 0);
  // No temporary folders are left behind.
  for (const auto& e : fs::directory_iterator(dir.path())) EXPECT_EQ(e.path().filename(), "scene");
}

TEST(Generator, SparseModelIsConsistentAndLoadsAsAScene) {
  TempDir dir;
  generate_scene(tiny(), dir / "scene", false);
  const auto model = splat::read_colmap_model(dir / "scene" / "sparse" / "0");
  EXPECT_EQ(model.images.size(), 10u);
  EXPECT_GT(model.points3d.size(), 300u);
  // Every observation is the projection of its 3D point.
  for (const auto& [id, p] : model.points3d) {
    ASSERT_GE(p.track.size(), 2u);
    for (const auto& el : p.track) {
      const auto& im = model.images.at(el.image_id);
      const splat::Camera cam = splat::pinhole_camera(model, im, "m");
      ASSERT_EQ(im.point3d_ids[el.point2d_idx], int64_t(id));
      ASSERT_LT((cam.project(p.xyz) - im.points2d[el.point2d_idx]).norm(), 1e-6);
    }
  }
  const auto scene = splat::Scene::load(dir / "scene", splat::SceneOptions{});
  EXPECT_EQ(scene->views().size(), 10u);
  EXPECT_EQ(scene->image(3)->width, 80);
}

TEST(Generator, NoSparseOption) {
  TempDir dir;
  SynthOptions o = tiny();
  o.write_sparse = false;
  generate_scene(o, dir / "scene", false);
  EXPECT_FALSE(fs::exists(dir / "scene" / "sparse"));
}

TEST(Generator, DeterministicForASeed) {
  TempDir dir;
  SynthOptions o = tiny();
  o.views = 3;
  generate_scene(o, dir / "a", false);
  generate_scene(o, dir / "b", false);
  o.seed = 2;
  generate_scene(o, dir / "c", false);
  for (const char* f :
       {"images/frame_00001.png", "sam2/frame_00001.png", "sparse/0/points3D.txt"}) {
    EXPECT_EQ(read_file(dir / "a" / f), read_file(dir / "b" / f)) << f;
    EXPECT_NE(read_file(dir / "a" / f), read_file(dir / "c" / f)) << f;
  }
}

TEST(Generator, HardCasesAreVisible) {
  SynthOptions o = tiny();
  o.views = 12;
  o.width = 160;
  o.height = 120;
  const World world = default_world(o.seed);
  const RenderedScene r = render_scene(o, world);
  std::map<int, size_t> pixels;  // id -> pixels over all views
  bool crates_touch = false;
  for (const splat::IdMap& m : r.instance_maps) {
    for (int y = 0; y < m.height; ++y)
      for (int x = 0; x + 1 < m.width; ++x) {
        ++pixels[m.at(x, y)];
        const int a = m.at(x, y), b = m.at(x + 1, y);
        crates_touch |= (a == 2 && b == 3) || (a == 3 && b == 2);
      }
  }
  for (const SceneObject& obj : world.objects)
    EXPECT_GT(pixels[obj.id], 10u) << obj.name << " never visible";
  EXPECT_TRUE(crates_touch) << "the touching crates never share a boundary in view";
  EXPECT_LT(pixels[7], pixels[1] / 10) << "the marble is small";
}

TEST(RayTracer, SemiTransparentSurfaceBlendsWhatIsBehind) {
  World world = default_world(1);
  const SceneObject& glass = world.objects[8];
  ASSERT_LT(glass.material.opacity, 1.0);
  const RayTracer tracer(world);
  const Eigen::Vector3d eye = glass.position + Eigen::Vector3d(0, 0.1, 2.0);
  const Eigen::Vector3d dir = (glass.position - eye).normalized();
  const Hit front = tracer.intersect(eye, dir);
  ASSERT_EQ(front.object, 8);
  const Hit behind = tracer.intersect(front.point, dir, false, 8);
  const Eigen::Vector3d expected = glass.material.opacity * tracer.surface_color(front) +
                                   (1 - glass.material.opacity) * tracer.surface_color(behind);
  EXPECT_LT((tracer.trace(eye, dir) - expected).norm(), 1e-9);
  EXPECT_EQ(tracer.instance_id(eye, dir), glass.id);
}

TEST(Generator, ThreeDovsLayout) {
  TempDir dir;
  SynthOptions o = tiny();
  o.ovs_dir = dir / "ovs";
  generate_scene(o, dir / "scene", false);
  const fs::path s = dir / "ovs";
  EXPECT_TRUE(fs::exists(s / "images" / "00.png"));
  EXPECT_TRUE(fs::exists(s / "images" / "09.png"));
  const std::string classes = read_file(s / "segmentations" / "classes.txt");
  EXPECT_EQ(std::count(classes.begin(), classes.end(), '\n'), 10);
  size_t test_views = 0;
  for (const auto& e : fs::directory_iterator(s / "segmentations")) test_views += e.is_directory();
  EXPECT_EQ(test_views, 5u);
  // poses_bounds.npy: N x 17 float64, translation column = camera centre.
  const std::string npy = read_file(s / "poses_bounds.npy");
  ASSERT_EQ(npy.substr(0, 6), "\x93NUMPY");
  const size_t header = 10 + uint8_t(npy[8]) + 256 * uint8_t(npy[9]);
  EXPECT_EQ(header % 64, 0u);
  EXPECT_NE(npy.find("'shape': (10, 17)"), std::string::npos);
  ASSERT_EQ(npy.size(), header + 10 * 17 * 8);
  std::vector<double> row(17);
  std::memcpy(row.data(), npy.data() + header + 17 * 8 * 3, 17 * 8);
  const auto cams = orbit_cameras(o, default_world(o.seed));
  EXPECT_NEAR(row[3], cams[3].center().x(), 1e-12);
  EXPECT_NEAR(row[8], cams[3].center().y(), 1e-12);
  EXPECT_NEAR(row[13], cams[3].center().z(), 1e-12);
  EXPECT_EQ(row[4], 60.0);  // H
  EXPECT_EQ(row[9], 80.0);  // W
}

int run(const std::string& args) {
  const int status =
      std::system((std::string(OP2GS_SYNTH_BIN) + " " + args + " > /dev/null 2>&1").c_str());
  return WEXITSTATUS(status);
}

TEST(SynthStage, RefusesToOverwriteWithoutForceAndRejectsBadOptions) {
  TempDir dir;
  const std::string out = (dir / "s").string();
  const std::string small = " --views 3 --width 32 --height 24 --supersample 1 --points 50";
  EXPECT_EQ(run("'" + out + "'" + small), 0);
  EXPECT_NE(run("'" + out + "'" + small), 0);
  EXPECT_EQ(run("'" + out + "'" + small + " --force"), 0);
  const std::string t = (dir / "t").string();
  EXPECT_NE(run("'" + t + "' --views 1"), 0);
  EXPECT_NE(run("'" + t + "' --sam2-strength -1"), 0);
  EXPECT_FALSE(fs::exists(dir / "t"));
}

}  // namespace
}  // namespace synth
