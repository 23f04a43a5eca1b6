#pragma once
// Running Debian's `colmap` command line (version 3.8) headless, one step at
// a time, with its output appended to a log file.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace splat {

// A COLMAP step that could not run or failed. The message says which step,
// shows the last lines of the log and how to install COLMAP.
class ColmapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ColmapCommand {
  std::string binary = "colmap";  // found in PATH unless it has a slash
  std::filesystem::path log_file;

  // Runs `binary command args...` with QT_QPA_PLATFORM=offscreen (COLMAP's
  // GUI library aborts without a display otherwise). `step` names it in
  // errors ("feature extraction").
  void run(const std::string& step, const std::string& command,
           const std::vector<std::string>& args) const;

  // True if the binary runs; true in *cuda if it was built with CUDA.
  bool available(bool* cuda = nullptr) const;
};

// The last `lines` lines of a text file ("" if it cannot be read).
std::string last_lines(const std::filesystem::path& file, int lines);

}  // namespace splat
