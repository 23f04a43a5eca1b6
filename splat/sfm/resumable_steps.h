#pragma once
// The bookkeeping that lets op2gs-sfm resume: each finished step leaves a
// marker in the output folder holding a fingerprint of its inputs and
// options, and a rerun with the same fingerprint skips the step.

#include <filesystem>
#include <functional>
#include <string>

namespace splat {

class ResumableSteps {
 public:
  explicit ResumableSteps(std::filesystem::path out) : out_(std::move(out)) {}

  // Runs `body` unless `step` finished before with this fingerprint (or
  // `force`). Returns true if it ran, so that the later steps run too.
  bool run(const std::string& step, const std::string& fingerprint, bool force,
           const std::function<void()>& body);

 private:
  std::filesystem::path out_;
};

}  // namespace splat
