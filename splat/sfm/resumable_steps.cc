#include "splat/sfm/resumable_steps.h"

#include <spdlog/spdlog.h>

#include "splat/atomic_file.h"

namespace splat {
namespace fs = std::filesystem;

bool ResumableSteps::run(const std::string& step, const std::string& fingerprint, bool force,
                         const std::function<void()>& body) {
  const fs::path marker = out_ / (".done_" + step);
  if (!force && fs::exists(marker) && read_text_file(marker) == fingerprint) {
    spdlog::info("{}: done before, reused", step);
    return false;
  }
  fs::remove(marker);
  spdlog::info("{} ...", step);
  body();
  write_text_atomically(marker, fingerprint);
  return true;
}

}  // namespace splat
