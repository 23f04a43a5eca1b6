#include "splat/atomic_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <stdio.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "splat/error.h"

namespace splat {
namespace fs = std::filesystem;

fs::path temporary_path_for(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  const std::string name = fmt::format(".{}.tmp-{}-{}{}", target.stem().string(), ::getpid(),
                                       counter++, target.extension().string());
  return target.parent_path() / name;
}

void write_atomically(const fs::path& target, const std::function<void(const fs::path&)>& write) {
  if (target.has_parent_path()) fs::create_directories(target.parent_path());
  const fs::path tmp = temporary_path_for(target);
  try {
    write(tmp);
    fs::rename(tmp, target);
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
}

void write_text_atomically(const fs::path& target, const std::string& text) {
  write_atomically(target, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.close();
    if (!out) throw_write_error(target);
  });
}

void throw_write_error(const fs::path& target) {
  const int error = errno;
  throw InputError(target, error ? fmt::format("cannot write: {}", std::strerror(error))
                                 : std::string("cannot write"));
}

namespace {

constexpr const char* kStagingPrefix = ".staging-";

bool process_is_alive(long pid);

// Staging folders left by runs that were killed (their process is gone).
void remove_abandoned_staging(const fs::path& target) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(target, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kStagingPrefix, 0) != 0) continue;
    const long pid = std::strtol(name.c_str() + std::strlen(kStagingPrefix), nullptr, 10);
    if (process_is_alive(pid) && pid != ::getpid()) continue;
    fs::remove_all(entry.path(), ec);
  }
}

bool process_is_alive(long pid) {
  return pid > 0 && (::kill(pid_t(pid), 0) == 0 || errno == EPERM);
}

// Exchanges two existing paths in one step (Linux renameat2).
bool exchange(const fs::path& a, const fs::path& b) {
  return ::renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE) == 0;
}

}  // namespace

void remove_abandoned_temporaries(const fs::path& dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    // ".<stem>.tmp-<pid>-<n><ext>"
    const std::string name = entry.path().filename().string();
    const size_t at = name.find(".tmp-");
    if (name.empty() || name[0] != '.' || at == std::string::npos || !entry.is_regular_file())
      continue;
    if (!process_is_alive(std::strtol(name.c_str() + at + 5, nullptr, 10)))
      fs::remove(entry.path(), ec);
  }
}

StagedFolder::StagedFolder(fs::path target, Target kind)
    : target_(std::move(target)),
      staging_(target_ / fmt::format("{}{}", kStagingPrefix, ::getpid())),
      kind_(kind) {
  fs::create_directories(target_);
  remove_abandoned_staging(target_);
  fs::remove_all(staging_);
  fs::create_directories(staging_);
}

StagedFolder::~StagedFolder() {
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

void StagedFolder::commit() {
  std::set<fs::path> written;
  for (const auto& entry : fs::directory_iterator(staging_)) {
    written.insert(entry.path().filename());
    const fs::path to = target_ / entry.path().filename();
    // What was there before ends up in the staging folder, removed below.
    if (fs::exists(fs::symlink_status(to)) && exchange(entry.path(), to)) continue;
    if (fs::is_directory(fs::symlink_status(to))) fs::remove_all(to);
    fs::rename(entry.path(), to);
  }
  fs::remove_all(staging_);
  if (kind_ == Target::kShared) return;
  std::vector<fs::path> stale;
  for (const auto& entry : fs::directory_iterator(target_))
    if (!written.count(entry.path().filename()) &&
        entry.path().filename().string().rfind(kStagingPrefix, 0) != 0)
      stale.push_back(entry.path());
  for (const auto& path : stale) fs::remove_all(path);
}

std::string read_text_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace splat
