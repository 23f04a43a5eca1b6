// How long a stage process takes from exec to exit when it does nothing
// (`--help`): what every stage run and every unit test process pays before
// its work. Image codecs are loaded only at a process's first image
// (splat/image_codec.h), so this should stay a few tens of milliseconds.
//
//   build/bench/startup_bench

#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

extern char** environ;

namespace {

namespace fs = std::filesystem;

// The stages of this build: build/stages/, beside build/bench/.
fs::path stage_path(const std::string& name) {
  return fs::read_symlink("/proc/self/exe").parent_path().parent_path() / "stages" / name;
}

// Runs `stage --help` with its output discarded; false if it did not exit 0.
bool run_help(const fs::path& stage) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  const std::string path = stage.string();
  char help[] = "--help";
  char* argv[] = {const_cast<char*>(path.c_str()), help, nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, path.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  return spawned == 0 && waitpid(pid, &status, 0) == pid && WIFEXITED(status) &&
         WEXITSTATUS(status) == 0;
}

void BM_StageHelp(benchmark::State& state, const char* name) {
  const fs::path stage = stage_path(name);
  for (auto _ : state) {
    if (!run_help(stage)) {  // a benchmark of nothing: stop the run
      std::fprintf(stderr, "startup_bench: %s --help failed\n", stage.c_str());
      std::exit(1);
    }
  }
}
BENCHMARK_CAPTURE(BM_StageHelp, train, "op2gs-train")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_StageHelp, eval, "op2gs-eval")->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
