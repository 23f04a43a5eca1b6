// LLFF poses_bounds.npy to COLMAP cameras, against the true cameras of a
// synthetic scene written in both layouts.

#include "splat/sfm/llff.h"

#include <gtest/gtest.h>

#include "splat/error.h"
#include "splat/npy.h"
#include "synth/generator.h"
#include "tests/test_util.h"
#include "tests/tiny_scene.h"

namespace splat {
namespace {

namespace fs = std::filesystem;

TEST(Llff, PosesMatchTheTrueCamerasAndTheFocalScalesWithTheImages) {
  testing_util::TempDir dir;
  testing_util::generate_small_scene_in_both_layouts(dir.path());
  const ColmapModel truth = read_colmap_model(dir / "lerf/sparse/0");
  std::vector<std::string> names = {"0.png", "1.png", "2.png", "3.png", "4.png", "5.png"};
  // Images at twice the stored size: the focal length doubles.
  const ColmapModel m = llff_to_colmap(dir / "ovs/poses_bounds.npy", names, 128, 96);
  ASSERT_EQ(m.images.size(), 6u);
  const ColmapCamera& cam = m.cameras.at(1);
  const ColmapCamera& true_cam = truth.cameras.begin()->second;
  EXPECT_NEAR(cam.params[0], 2 * true_cam.params[0], 1e-9);
  EXPECT_NEAR(cam.params[2], 64, 1e-9);
  auto it = truth.images.begin();
  for (const auto& [id, image] : m.images) {
    EXPECT_EQ(image.name, names[id - 1]);
    const Eigen::Matrix3d R = rotation_from_quaternion(image.qvec);
    const Eigen::Matrix3d true_R = rotation_from_quaternion(it->second.qvec);
    EXPECT_LT((R - true_R).norm(), 1e-9);
    EXPECT_LT((image.tvec - it->second.tvec).norm(), 1e-9);
    ++it;
  }
  EXPECT_THROW(llff_to_colmap(dir / "ovs/poses_bounds.npy", {"a.png"}, 128, 96), InputError);
  EXPECT_THROW(llff_to_colmap(dir / "ovs/poses_bounds.npy", names, 128, 128), InputError);
}

TEST(Npy, ReadsWhatItWrites) {
  testing_util::TempDir dir;
  write_npy_f64(dir / "a.npy", {1, 2, 3, 4, 5, 6}, {2, 3});
  std::vector<size_t> shape;
  EXPECT_EQ(read_npy(dir / "a.npy", &shape), (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(shape, (std::vector<size_t>{2, 3}));
  testing_util::write_file(dir / "b.npy", "\x93NUMPY\x01\x00");
  EXPECT_THROW(read_npy(dir / "b.npy", &shape), InputError);
}

// Found by fuzzing: a dimension beyond 64 bits made std::stoul throw its own
// exception, and dimensions whose product overflows passed the size check.
TEST(Npy, ShapesLargerThanTheFileAreRefused) {
  testing_util::TempDir dir;
  auto npy = [](const std::string& shape) {
    std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" + shape + "), }";
    header.resize(118, ' ');
    header += '\n';
    return std::string("\x93NUMPY\x01\x00", 8) + char(header.size()) + '\0' + header +
           std::string(16, '\0');
  };
  std::vector<size_t> shape;
  testing_util::write_file(dir / "ok.npy", npy("2,"));
  EXPECT_EQ(read_npy(dir / "ok.npy", &shape).size(), 2u);
  for (const std::string s : {"99999999999999999999999,", "4294967296, 4294967296, 2", "3,"}) {
    testing_util::write_file(dir / "bad.npy", npy(s));
    EXPECT_THROW(read_npy(dir / "bad.npy", &shape), InputError) << s;
  }
}

}  // namespace
}  // namespace splat
