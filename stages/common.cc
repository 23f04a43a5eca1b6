#include "stages/common.h"

#include <fcntl.h>
#include <spdlog/sinks/ansicolor_sink.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>

#include "splat/error.h"

namespace stages {
namespace {

// Where a stage's output goes while it runs: its own messages (spdlog) to the
// terminal's stderr, one line each; what libraries print there themselves
// (libpng's "libpng error: ...", decoders' warnings) to the file named by
// $OP2GS_LIBRARY_LOG (pipeline/run_stage.sh sets it to the stage log), or
// nowhere: the stage's own error line already says what went wrong.
class StageOutput {
 public:
  StageOutput() : terminal_(::dup(2)) {
    if (terminal_ < 0) return;
    FILE* terminal = ::fdopen(terminal_, "w");
    if (!terminal) return;
    auto sink = std::make_shared<spdlog::sinks::ansicolor_sink<spdlog::details::console_mutex>>(
        terminal, spdlog::color_mode::automatic);
    spdlog::set_default_logger(std::make_shared<spdlog::logger>("op2gs", std::move(sink)));
    const char* log = std::getenv("OP2GS_LIBRARY_LOG");
    const int libraries = log && *log ? ::open(log, O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644)
                                      : ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (libraries >= 0) ::dup2(libraries, 2), ::close(libraries);
  }
  ~StageOutput() {
    std::fflush(stderr);
    spdlog::default_logger()->flush();
    if (terminal_ >= 0) ::dup2(terminal_, 2);
  }
  StageOutput(const StageOutput&) = delete;
  StageOutput& operator=(const StageOutput&) = delete;

 private:
  int terminal_;
};

// A message as one line: libraries' own error texts (OpenImageIO's) may
// hold several.
std::string one_line(std::string message) {
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  for (size_t p; (p = message.find('\n')) != std::string::npos;) message.replace(p, 1, "; ");
  return message;
}

}  // namespace

// Peak resident memory of this process so far, in MiB.
double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
}

int run_stage(CLI::App& app, int argc, char** argv, const std::function<void()>& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  const StageOutput output;
  spdlog::set_pattern("[%H:%M:%S] %v");
  try {
    body();
    spdlog::info("peak memory {:.0f} MiB", peak_rss_mib());
    return 0;
  } catch (const splat::InputError& e) {
    spdlog::error("{}", one_line(e.what()));
  } catch (const std::invalid_argument& e) {
    spdlog::error("invalid option: {}", one_line(e.what()));
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    spdlog::error("{}: {}", e.path1().string(), e.code().message());
  } catch (const std::exception& e) {
    spdlog::error("{}", one_line(e.what()));
  }
  return 1;
}

}  // namespace stages
