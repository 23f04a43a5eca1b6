#include "splat/atomic_file.h"

#include <fcntl.h>
#include <fmt/format.h>
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

namespace {

// When process `pid` started (clock ticks since boot, field 22 of
// /proc/<pid>/stat), or "" when it does not exist or has ended. A killed
// process whose parent died too stays a zombie (state Z) for as long as the
// machine's init leaves it unreaped, as in many containers: it writes nothing
// more and counts as ended.
std::string start_time_of(long pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return "";
  // The command name (field 2) may hold spaces; fields after it follow ')'.
  std::istringstream rest(line.substr(line.rfind(')') + 1));
  std::string state, field;
  if (!(rest >> state) || state == "Z" || state == "X") return "";
  for (int k = 4; k <= 22 && rest >> field; ++k) {
  }
  return field;
}

// "<pid>-<start time>": names this process in temporary names. A process ID
// alone does not do: a dead run's ID may be reused by a live process.
const std::string& this_process_tag() {
  static const std::string tag = fmt::format("{}-{}", ::getpid(), start_time_of(::getpid()));
  return tag;
}

// Whether the process a tag ("<pid>-<start time>...") names still runs.
bool tag_is_alive(const char* tag) {
  char* end = nullptr;
  const long pid = std::strtol(tag, &end, 10);
  if (pid <= 0 || *end != '-') return false;
  const unsigned long long start = std::strtoull(end + 1, nullptr, 10);
  const std::string now = start_time_of(pid);
  return !now.empty() && std::strtoull(now.c_str(), nullptr, 10) == start;
}

}  // namespace

fs::path temporary_path_for(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  const std::string name = fmt::format(".{}.tmp-{}-{}{}", target.stem().string(),
                                       this_process_tag(), counter++, target.extension().string());
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

// Staging folders left by runs that were killed (their process is gone).
void remove_abandoned_staging(const fs::path& target) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(target, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kStagingPrefix, 0) != 0) continue;
    const std::string tag = name.substr(std::strlen(kStagingPrefix));
    if (tag != this_process_tag() && tag_is_alive(tag.c_str())) continue;
    fs::remove_all(entry.path(), ec);
  }
}

// Exchanges two existing paths in one step (Linux renameat2).
bool exchange(const fs::path& a, const fs::path& b) {
  return ::renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE) == 0;
}

}  // namespace

void remove_abandoned_temporaries(const fs::path& dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    // ".<stem>.tmp-<pid>-<start time>-<n><ext>"
    const std::string name = entry.path().filename().string();
    const size_t at = name.find(".tmp-");
    if (name.empty() || name[0] != '.' || at == std::string::npos || !entry.is_regular_file())
      continue;
    if (!tag_is_alive(name.c_str() + at + 5)) fs::remove(entry.path(), ec);
  }
}

StagedFolder::StagedFolder(fs::path target, Target kind)
    : target_(std::move(target)),
      staging_(target_ / (kStagingPrefix + this_process_tag())),
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
