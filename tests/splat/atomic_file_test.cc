#include "splat/atomic_file.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "splat/error.h"

namespace splat {
namespace {
namespace fs = std::filesystem;

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("op2gs_atomic_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

size_t entries(const fs::path& dir) {
  return size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

TEST_F(AtomicFileTest, AStagesOwnFolderHoldsOnlyWhatItWroteLast) {
  const fs::path out = dir_ / "render";
  write_text_atomically(out / "photo" / "0.png", "old");
  write_text_atomically(out / "masks" / "0.png", "old");
  StagedFolder staged(out, StagedFolder::Target::kOwned);
  write_text_atomically(staged.path() / "masks" / "0.png", "new");
  staged.commit();
  EXPECT_FALSE(fs::exists(out / "photo"));
  EXPECT_EQ(read_text_file(out / "masks" / "0.png"), "new");
  EXPECT_EQ(entries(out), 1u);
}

TEST_F(AtomicFileTest, AFailedWriteLeavesTheOldFileAndNoTemporary) {
  const fs::path file = dir_ / "a.txt";
  write_text_atomically(file, "old");
  EXPECT_THROW(write_atomically(file,
                                [](const fs::path& tmp) {
                                  std::ofstream(tmp) << "half";
                                  throw InputError(tmp, "disk full");
                                }),
               InputError);
  EXPECT_EQ(read_text_file(file), "old");
  EXPECT_EQ(entries(dir_), 1u);
}

TEST_F(AtomicFileTest, StagedOutputsReplaceTheOldOnlyOnCommit) {
  const fs::path out = dir_ / "render";
  write_text_atomically(out / "masks" / "0.txt", "old mask");
  write_text_atomically(out / "summary.json", "old");
  write_text_atomically(out / "notes.txt", "the user's");
  {
    StagedFolder staged(out, StagedFolder::Target::kShared);
    write_text_atomically(staged.path() / "masks" / "1.txt", "new mask");
    write_text_atomically(staged.path() / "summary.json", "new");
    EXPECT_EQ(read_text_file(out / "summary.json"), "old");
    EXPECT_TRUE(fs::exists(out / "masks" / "0.txt"));
    staged.commit();
  }
  EXPECT_EQ(read_text_file(out / "summary.json"), "new");
  EXPECT_FALSE(fs::exists(out / "masks" / "0.txt"));  // the masks folder is replaced whole
  EXPECT_EQ(read_text_file(out / "masks" / "1.txt"), "new mask");
  EXPECT_EQ(read_text_file(out / "notes.txt"), "the user's");
  EXPECT_EQ(entries(out), 3u);  // no staging folder left
}

TEST_F(AtomicFileTest, AStageThatFailsLeavesThePreviousOutputs) {
  const fs::path out = dir_ / "vote";
  write_text_atomically(out / "summary.json", "old");
  try {
    StagedFolder staged(out, StagedFolder::Target::kOwned);
    write_text_atomically(staged.path() / "summary.json", "new");
    throw InputError(staged.path() / "point_cloud.ply", "cannot write: No space left on device");
  } catch (const InputError&) {
  }
  EXPECT_EQ(read_text_file(out / "summary.json"), "old");
  EXPECT_EQ(entries(out), 1u);
}

TEST_F(AtomicFileTest, AKilledRunsStagingFolderIsRemovedByTheNext) {
  const fs::path out = dir_ / "embed";
  // No process has this ID: Linux's pid_max is at most 2^22.
  const fs::path abandoned = out / ".staging-99999999";
  write_text_atomically(abandoned / "embeddings.json", "partial");
  StagedFolder staged(out, StagedFolder::Target::kOwned);
  EXPECT_FALSE(fs::exists(abandoned));
  EXPECT_TRUE(fs::is_directory(staged.path()));
}

// "<pid>-<start time>" of a child process, as the writer names itself.
std::string tag_of(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(stat, line);
  std::istringstream rest(line.substr(line.rfind(')') + 2));
  std::string field;
  for (int k = 3; k <= 22; ++k) rest >> field;
  return std::to_string(pid) + "-" + field;
}

// A run killed with its make becomes a zombie where init does not reap
// (many containers): it has ended, and its staging folder is abandoned.
TEST_F(AtomicFileTest, AZombiesStagingFolderIsRemovedALiveWritersStays) {
  const pid_t zombie = ::fork();
  if (zombie == 0) ::_exit(0);
  const pid_t live = ::fork();
  if (live == 0) {
    ::pause();
    ::_exit(0);
  }
  for (int tries = 0; tries < 1000; ++tries) {  // until the first has exited
    std::ifstream stat("/proc/" + std::to_string(zombie) + "/stat");
    std::string line;
    std::getline(stat, line);
    if (line.find(") Z ") != std::string::npos) break;
    ::usleep(1000);
  }
  const fs::path out = dir_ / "vote";
  const fs::path of_zombie = out / (".staging-" + tag_of(zombie));
  const fs::path of_live = out / (".staging-" + tag_of(live));
  write_text_atomically(of_zombie / "point_cloud.ply", "partial");
  write_text_atomically(of_live / "point_cloud.ply", "partial");
  { StagedFolder staged(out, StagedFolder::Target::kOwned); }
  EXPECT_FALSE(fs::exists(of_zombie));
  EXPECT_TRUE(fs::exists(of_live));
  ::kill(live, SIGKILL);
  ::waitpid(zombie, nullptr, 0);
  ::waitpid(live, nullptr, 0);
}

TEST_F(AtomicFileTest, TemporariesOfKilledRunsAreRemovedOthersStay) {
  const fs::path dead = dir_ / ".training_curve.tmp-99999999-7.png";
  const fs::path alive = temporary_path_for(dir_ / "metrics.json");  // this process's
  for (const auto& f : {dead, alive, dir_ / "metrics.json", dir_ / ".hidden.txt"})
    write_text_atomically(f, "x");
  remove_abandoned_temporaries(dir_);
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(dir_ / "metrics.json"));
  EXPECT_TRUE(fs::exists(dir_ / ".hidden.txt"));
}

TEST_F(AtomicFileTest, AWriteErrorSaysWhy) {
  const fs::path file = dir_ / "x.ply";
  errno = ENOSPC;
  try {
    throw_write_error(file);
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("x.ply"), std::string::npos) << what;
    EXPECT_NE(what.find("No space left on device"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace splat
