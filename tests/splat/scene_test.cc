#include "splat/scene.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "splat/colmap_model.h"
#include "splat/error.h"
#include "splat/image.h"
#include "splat/pose_file.h"
#include "tests/test_util.h"

namespace splat {
namespace {

using testing_util::TempDir;

// A scene folder with n views of w x h (PINHOLE), each image a constant colour
// that encodes its index.
void make_scene(const std::filesystem::path& root, int n, int w, int h, int model_id = 1) {
  ColmapModel m;
  m.cameras[1] = ColmapCamera{1, model_id, uint64_t(w), uint64_t(h), {}};
  m.cameras[1].params = model_id == 1 ? std::vector<double>{50, 50, w / 2.0, h / 2.0}
                                      : std::vector<double>{50, 50, w / 2.0, h / 2.0, 0.1, 0, 0, 0};
  for (int i = 0; i < n; ++i) {
    ColmapImage im;
    im.image_id = uint32_t(i + 1);
    im.camera_id = 1;
    im.tvec = {double(i), 0, 0};
    im.name = fmt::format("v{}.png", 1000 + i);
    m.images[im.image_id] = im;
    ImageRGB img(w, h);
    std::fill(img.data.begin(), img.data.end(), float(i % 256) / 255.f);
    write_image_rgb(root / "images" / im.name, img);
  }
  m.points3d[1] = ColmapPoint3D{1, {1, 2, 3}, {255, 0, 51}, 0, {}};
  write_colmap_model(m, root / "sparse" / "0", ColmapFormat::kBinary);
}

TEST(Scene, LoadsViewsSortedByNameWithCameras) {
  TempDir dir;
  make_scene(dir.path(), 3, 40, 30);
  const auto scene = Scene::load(dir.path(), SceneOptions{});
  ASSERT_EQ(scene->views().size(), 3u);
  EXPECT_EQ(scene->views()[0].name, "v1000.png");
  EXPECT_EQ(scene->views()[2].camera.width, 40);
  EXPECT_EQ(scene->find_view("v1001.png"), 1);
  EXPECT_EQ(scene->find_view("nope.png"), -1);
  EXPECT_EQ(scene->points().size(), 1u);
  EXPECT_FLOAT_EQ(scene->point_colors()[0].z(), 0.2f);
  EXPECT_NEAR(scene->extent(), 1.1, 1e-12);  // centres at x = 0, -1, -2
  EXPECT_EQ(scene->cache().loads(), 0u) << "no image is decoded before it is asked for";
  const auto img = scene->image(2);
  EXPECT_EQ(img->width, 40);
  EXPECT_NEAR(img->data[0], 2 / 255.f, 1e-6);
}

TEST(Scene, APoseFileReplacesTheNamedViewsPosesOnly) {
  TempDir dir;
  make_scene(dir.path(), 3, 40, 30);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()).toRotationMatrix();
  write_pose_file(dir / "poses.txt", {{"v1001.png", R, {5, 6, 7}}});
  SceneOptions o;
  o.poses = dir / "poses.txt";
  const auto scene = Scene::load(dir.path(), o);
  EXPECT_TRUE(scene->views()[1].camera.R.isApprox(R, 1e-10));
  EXPECT_TRUE(scene->views()[1].camera.t.isApprox(Eigen::Vector3d(5, 6, 7), 1e-10));
  EXPECT_EQ(scene->views()[2].camera.t, Eigen::Vector3d(2, 0, 0));
  EXPECT_NEAR(scene->extent(), 1.1, 1e-12);  // the model's poses'

  write_pose_file(dir / "other.txt", {{"elsewhere.png", R, {0, 0, 0}}});
  o.poses = dir / "other.txt";
  try {
    Scene::load(dir.path(), o);
    FAIL() << "a pose for a view the scene lacks must be an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("other.txt: image 'elsewhere.png' is not in the scene"),
              std::string::npos)
        << e.what();
  }
}

TEST(Scene, DownscalesFullImagesWithAreaFilter) {
  TempDir dir;
  make_scene(dir.path(), 2, 40, 30);
  SceneOptions o;
  o.downscale = 4;
  const auto scene = Scene::load(dir.path(), o);
  const View& v = scene->views()[1];
  EXPECT_EQ(v.camera.width, 10);
  EXPECT_EQ(v.camera.height, 8);  // round(7.5)
  EXPECT_DOUBLE_EQ(v.camera.fx, 50.0 / 4);
  EXPECT_EQ(v.file, dir / "images" / "v1001.png");
  const auto img = scene->image(1);
  EXPECT_EQ(img->width, 10);
  EXPECT_EQ(img->height, 8);
  EXPECT_NEAR(img->data[0], 1 / 255.f, 1e-6);
}

TEST(Scene, ReusesExistingImagesNFolder) {
  TempDir dir;
  make_scene(dir.path(), 2, 40, 30);
  for (const char* name : {"v1000.png", "v1001.png"}) {
    ImageRGB small(20, 15);
    std::fill(small.data.begin(), small.data.end(), 0.5f);
    write_image_rgb(dir / "images_2" / name, small);
  }
  SceneOptions o;
  o.downscale = 2;
  const auto scene = Scene::load(dir.path(), o);
  EXPECT_EQ(scene->views()[0].file, dir / "images_2" / "v1000.png");
  EXPECT_NEAR(scene->image(0)->data[0], 128 / 255.f, 1e-6) << "pixels come from images_2/";
}

TEST(Scene, MaxWidthKeepsAspectRatio) {
  TempDir dir;
  make_scene(dir.path(), 1, 40, 30);
  SceneOptions o;
  o.max_width = 16;
  const auto scene = Scene::load(dir.path(), o);
  EXPECT_EQ(scene->views()[0].camera.width, 16);
  EXPECT_EQ(scene->views()[0].camera.height, 12);
  EXPECT_EQ(scene->image(0)->height, 12);
}

TEST(Scene, ManyViewsStayWithinTheCacheBudget) {
  TempDir dir;
  make_scene(dir.path(), 300, 16, 12);
  SceneOptions o;
  // Room for 10 views as floats, 40 as the 8-bit codes the cache keeps of
  // these 8-bit PNGs.
  o.cache_bytes = 10 * 16 * 12 * 3 * sizeof(float);
  const auto scene = Scene::load(dir.path(), o);
  for (size_t i = 0; i < scene->views().size(); ++i) {
    ASSERT_NEAR(scene->image(i)->data[0], float(i % 256) / 255.f, 1e-6);
    ASSERT_LE(scene->cache().views_held(), 40u);
    ASSERT_LE(scene->cache().bytes_held(), o.cache_bytes);
  }
  EXPECT_EQ(scene->cache().views_held(), 40u);
}

TEST(Scene, BadInputNamesTheFile) {
  {
    TempDir dir;
    make_scene(dir.path(), 2, 40, 30);
    std::filesystem::remove(dir / "images" / "v1001.png");
    try {
      Scene::load(dir.path(), SceneOptions{});
      FAIL();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("v1001.png"), std::string::npos) << e.what();
    }
  }
  {
    TempDir dir;
    make_scene(dir.path(), 1, 40, 30, /*OPENCV*/ 4);
    EXPECT_THROW(Scene::load(dir.path(), SceneOptions{}), InputError);
  }
  {
    TempDir dir;
    make_scene(dir.path(), 1, 40, 30);
    write_image_rgb(dir / "images" / "v1000.png", ImageRGB(30, 30));  // wrong aspect ratio
    try {  // found when the scene loads (from the header), not at the view's first use
      Scene::load(dir.path(), SceneOptions{});
      FAIL();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("v1000.png"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("30x30"), std::string::npos) << e.what();
    }
  }
  {
    TempDir dir;
    EXPECT_THROW(Scene::load(dir.path(), SceneOptions{}), InputError);
  }
}

TEST(SceneOptions, CheckRejectsBadValues) {
  SceneOptions o;
  o.downscale = 3;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o.downscale = 8;
  EXPECT_NO_THROW(o.Check());
}

}  // namespace
}  // namespace splat
