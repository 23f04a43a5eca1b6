#pragma once
// Helpers shared by the tests: temporary folders, small file I/O, one-view
// COLMAP models.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
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

// A folder of read-only test data that `make` fills once and every process
// of this test binary then shares: ctest runs each test in a process of its
// own, so a scene made per process is made once per test. It lives beside
// the binary, under a name holding the binary's size and time, so a rebuilt
// binary makes it again; a lock makes a concurrent process wait for the
// first instead of making it twice.
inline std::filesystem::path shared_test_data(
    const std::string& name, const std::function<void(const std::filesystem::path&)>& make) {
  namespace fs = std::filesystem;
  const fs::path exe = fs::read_symlink("/proc/self/exe");
  const auto stamp = fs::last_write_time(exe).time_since_epoch().count();
  const fs::path root = exe.parent_path() / "test_data";
  const fs::path dir = root / (exe.filename().string() + "_" + name + "_" +
                               std::to_string(fs::file_size(exe)) + "_" + std::to_string(stamp));
  fs::create_directories(root);
  const fs::path lock_path = dir.string() + ".lock";
  const int lock = ::open(lock_path.c_str(), O_CREAT | O_RDWR, 0644);
  if (lock < 0 || ::flock(lock, LOCK_EX) != 0)
    throw std::runtime_error("cannot lock " + lock_path.string());
  try {
    if (!fs::exists(dir / ".complete")) {
      fs::remove_all(dir);
      // The data of earlier builds of this binary goes.
      const std::string prefix = exe.filename().string() + "_" + name + "_";
      for (const auto& old : fs::directory_iterator(root))
        if (old.path().filename().string().starts_with(prefix) && old.path() != dir &&
            old.path() != lock_path)
          fs::remove_all(old.path());
      make(dir);
      write_file(dir / ".complete", "");
    }
  } catch (...) {
    ::close(lock);
    throw;
  }
  ::close(lock);
  return dir;
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
