#include "splat/sfm/colmap_command.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <deque>
#include <fstream>

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

// Runs argv with stdout and stderr appended to `log`; returns the exit
// status, or -1 if the program could not be started.
int spawn(const std::vector<std::string>& args, const fs::path& log) {
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
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
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
  const int status = spawn(argv, log_file);
  if (status == -1)
    throw ColmapError(fmt::format("{}: cannot run `{}`: {}", step, binary, kInstallHint));
  if (status != 0)
    throw ColmapError(fmt::format("{} failed (colmap {} exited with {}); log {}: {}", step, command,
                                  status, log_file.string(), last_lines(log_file, 8)));
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
