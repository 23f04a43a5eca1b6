#include "splat/sfm/colmap_command.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <deque>
#include <fstream>
#include <functional>
#include <thread>

extern char** environ;

namespace splat {
namespace fs = std::filesystem;

namespace {

constexpr const char* kInstallHint =
    "install COLMAP with `apt-get install colmap` (scripts/setup.sh does), or give its path "
    "with --colmap";

// The environment of this process plus QT_QPA_PLATFORM=offscreen.
std::vector<std::string> headless_environment() {
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e)
    if (std::string(*e).rfind("QT_QPA_PLATFORM=", 0) != 0) env.emplace_back(*e);
  env.emplace_back("QT_QPA_PLATFORM=offscreen");
  return env;
}

// The last line of COLMAP's log that says how far a step is ("Processed file
// [12/300]", "Matching block [2/5, 1/5]", "Registering image #40 (41)"), or "".
std::string last_progress_line(const fs::path& log) {
  std::ifstream in(log);
  if (!in) return "";
  // Only the end of the log is read: it grows to megabytes.
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(std::max<std::streamoff>(0, size - 16384));
  std::string line, found;
  while (std::getline(in, line)) {
    const bool counted = line.find('[') != std::string::npos && line.find('/') != std::string::npos;
    if ((counted && (line.find("Processed file") != std::string::npos ||
                     line.find("Matching") != std::string::npos)) ||
        line.find("Registering image") != std::string::npos)
      found = line;
  }
  while (!found.empty() && (found.back() == ' ' || found.back() == '\r')) found.pop_back();
  return found;
}

// "2 min 05 s" or "41.2 s".
std::string elapsed_text(double seconds) {
  if (seconds < 60) return fmt::format("{:.1f} s", seconds);
  const int s = int(seconds);
  return s < 3600 ? fmt::format("{} min {:02d} s", s / 60, s % 60)
                  : fmt::format("{} h {:02d} min", s / 3600, s / 60 % 60);
}

// Runs argv with stdout and stderr appended to `log`; returns the exit
// status, or -1 if the program could not be started. While it runs,
// `progress` is called every `every` seconds with the time so far.
int spawn(const std::vector<std::string>& args, const fs::path& log,
          const std::function<void(double seconds)>& progress = nullptr, int every = 30) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  std::vector<std::string> env_strings = headless_environment();
  std::vector<char*> env;
  for (std::string& e : env_strings) env.push_back(e.data());
  env.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  const std::string log_name = log.empty() ? "/dev/null" : log.string();
  posix_spawn_file_actions_addopen(&actions, 1, log_name.c_str(), O_WRONLY | O_CREAT | O_APPEND,
                                   0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  pid_t pid = 0;
  const int err = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), env.data());
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) return -1;
  int status = 0;
  const auto start = std::chrono::steady_clock::now();
  auto next_report = start + std::chrono::seconds(every);
  for (;;) {
    const pid_t done = waitpid(pid, &status, progress ? WNOHANG : 0);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) return -1;
    if (!progress) continue;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    const auto now = std::chrono::steady_clock::now();
    if (now >= next_report) {
      progress(std::chrono::duration<double>(now - start).count());
      next_report += std::chrono::seconds(every);
    }
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

std::string last_lines(const fs::path& file, int lines) {
  std::ifstream in(file);
  std::deque<std::string> tail;
  std::string line;
  while (std::getline(in, line)) {
    tail.push_back(line);
    if (int(tail.size()) > lines) tail.pop_front();
  }
  return fmt::format("{}", fmt::join(tail, " | "));
}

void ColmapCommand::run(const std::string& step, const std::string& command,
                        const std::vector<std::string>& args) const {
  if (!log_file.empty()) {
    fs::create_directories(log_file.parent_path());
    std::ofstream(log_file, std::ios::app)
        << "\n### " << step << ": " << binary << " " << command << "\n";
  }
  std::vector<std::string> argv = {binary, command};
  argv.insert(argv.end(), args.begin(), args.end());
  const auto start = std::chrono::steady_clock::now();
  const int status = spawn(argv, log_file, [&](double seconds) {
    const std::string where = last_progress_line(log_file);
    spdlog::info("COLMAP {}: {}{}", step, elapsed_text(seconds), where.empty() ? "" : ", " + where);
  });
  if (status == -1)
    throw ColmapError(fmt::format("{}: cannot run `{}`: {}", step, binary, kInstallHint));
  if (status != 0)
    throw ColmapError(fmt::format("{} failed (colmap {} exited with {}); log {}: {}", step, command,
                                  status, log_file.string(), last_lines(log_file, 8)));
  spdlog::info(
      "COLMAP {}: done in {}", step,
      elapsed_text(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()));
}

bool ColmapCommand::available(bool* cuda) const {
  const fs::path probe = fs::temp_directory_path() / fmt::format("op2gs_colmap_{}.txt", getpid());
  const int status = spawn({binary, "-h"}, probe);
  std::ifstream in(probe);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  fs::remove(probe);
  if (cuda) *cuda = text.find("with CUDA") != std::string::npos;
  return status == 0 && text.find("COLMAP") != std::string::npos;
}

}  // namespace splat
