// The layout of a scene folder told from its files, the ID map folder it
// prefers, and the train/test split that follows from it.

#include "splat/dataset_layout.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "splat/colmap_model.h"
#include "splat/error.h"
#include "splat/image.h"
#include "splat/view_split.h"
#include "tests/test_util.h"

namespace splat {
namespace {

namespace fs = std::filesystem;
using testing_util::TempDir;

void make_dirs(const fs::path& scene, std::initializer_list<const char*> dirs) {
  for (const char* d : dirs) fs::create_directories(scene / d);
}

TEST(DatasetLayout, ToldFromTheFolder) {
  TempDir t;
  make_dirs(t / "photos", {"images", "sam2"});
  make_dirs(t / "lerf", {"images", "images_train", "object_mask"});
  make_dirs(t / "lerf_truth_only", {"images", "test_mask"});
  make_dirs(t / "ovs", {"images", "segmentations", "sam2"});
  make_dirs(t / "ovs_prepared", {"images", "segmentations", "object_mask_deva", "sparse/0"});
  EXPECT_EQ(detect_dataset_layout(t / "photos"), DatasetLayout::kPhotos);
  EXPECT_EQ(detect_dataset_layout(t / "lerf"), DatasetLayout::kLerfMask);
  EXPECT_EQ(detect_dataset_layout(t / "lerf_truth_only"), DatasetLayout::kLerfMask);
  EXPECT_EQ(detect_dataset_layout(t / "ovs"), DatasetLayout::kOvsOriginal);
  EXPECT_EQ(detect_dataset_layout(t / "ovs_prepared"), DatasetLayout::kOvsPrepared);
  EXPECT_EQ(layout_name(DatasetLayout::kOvsPrepared), "3dovs-prepared");
}

TEST(DatasetLayout, IdMapFolderIsTheOneThatExistsInTheLayoutsOrder) {
  TempDir t;
  make_dirs(t / "lerf", {"images_train", "object_mask"});
  EXPECT_EQ(resolve_id_map_folder(t / "lerf", "auto"), "object_mask");
  make_dirs(t / "lerf", {"sam2"});  // both: LERF-Mask's own DEVA maps first
  EXPECT_EQ(resolve_id_map_folder(t / "lerf", "auto"), "object_mask");
  make_dirs(t / "photos", {"object_mask", "sam2"});  // both: SAM2 first for photos
  EXPECT_EQ(resolve_id_map_folder(t / "photos", "auto"), "sam2");
  make_dirs(t / "ovs", {"segmentations", "object_mask_deva"});
  EXPECT_EQ(resolve_id_map_folder(t / "ovs", "auto"), "object_mask_deva");
  // An explicit name is taken as it is.
  EXPECT_EQ(resolve_id_map_folder(t / "photos", "my_masks"), "my_masks");
  fs::create_directories(t / "none");
  try {
    resolve_id_map_folder(t / "none", "auto");
    FAIL() << "a scene without ID maps passed";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find((t / "none").string()), std::string::npos) << m;
    for (const char* name : {"sam2/", "object_mask/", "object_mask_deva/"})
      EXPECT_NE(m.find(name), std::string::npos) << m;
  }
}

// A scene of five 4x3 views named 00.png .. 04.png, posed anyhow.
fs::path five_view_scene(const fs::path& dir) {
  ColmapModel m;
  m.cameras[1] = ColmapCamera{1, 1, 4, 3, {4, 4, 2, 1.5}};
  for (uint32_t i = 0; i < 5; ++i) {
    ColmapImage image;
    image.image_id = i + 1;
    image.camera_id = 1;
    image.tvec = Eigen::Vector3d(0, 0, 1 + i);
    image.name = fmt::format("{:02d}.png", i);
    m.images[image.image_id] = image;
    write_image_rgb(dir / "images" / image.name, ImageRGB(4, 3));
  }
  write_colmap_model(m, dir / "sparse" / "0", ColmapFormat::kText);
  return dir;
}

std::vector<size_t> test_views(const fs::path& scene, SplitRule rule) {
  return split_views(*Scene::load(scene, SceneOptions{}), rule).test;
}

TEST(DatasetLayout, SplitFollowsTheLayout) {
  TempDir t;
  const fs::path scene = five_view_scene(t.path());
  EXPECT_EQ(test_views(scene, SplitRule::kAuto), (std::vector<size_t>{0}));  // photos: every 8th
  make_dirs(scene, {"segmentations/01", "segmentations/03"});
  EXPECT_EQ(test_views(scene, SplitRule::kAuto), std::vector<size_t>{});  // as released: all train
  EXPECT_EQ(test_views(scene, SplitRule::kSegmented), (std::vector<size_t>{1, 3}));
  make_dirs(scene, {"object_mask_deva"});  // prepared: the segmented views held out
  EXPECT_EQ(test_views(scene, SplitRule::kAuto), (std::vector<size_t>{1, 3}));
  make_dirs(scene, {"segmentations/09"});
  EXPECT_THROW(test_views(scene, SplitRule::kSegmented), InputError);
}

}  // namespace
}  // namespace splat
