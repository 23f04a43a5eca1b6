#pragma once
// Helpers shared by the tests: temporary folders, small file I/O, one-view
// COLMAP models.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include "splat/colmap_model.h"

namespace testing_util {

// A folder under the system temp dir, unique to the running test, removed at
// the end of the test.
class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            (std::string("op2gs_") + info->test_suite_name() + "_" + info->name() + "_" +
             std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// A folder shared by the tests of one process (a scene generated once), under
// the system temp dir, removed when the process exits.
inline std::filesystem::path process_temp_dir(const std::string& name) {
  struct RemovedAtExit {
    std::vector<std::filesystem::path> paths;
    ~RemovedAtExit() {
      std::error_code ignored;
      for (const auto& p : paths) std::filesystem::remove_all(p, ignored);
    }
  };
  static RemovedAtExit folders;
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("op2gs_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  folders.paths.push_back(dir);
  return dir;
}

inline void write_file(const std::filesystem::path& p, const std::string& bytes) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << bytes;
}

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A COLMAP model of one image, `name`, seen by `camera` from the origin.
inline splat::ColmapModel one_view_model(const splat::ColmapCamera& camera,
                                         const std::string& name) {
  splat::ColmapModel m;
  m.cameras[camera.camera_id] = camera;
  splat::ColmapImage image;
  image.image_id = 1;
  image.camera_id = camera.camera_id;
  image.name = name;
  m.images[1] = image;
  return m;
}

}  // namespace testing_util
