#pragma once
// Errors for bad input. Every message is one line that names the file and says
// what is wrong with it, so a stage can print it and exit non-zero.

#include <filesystem>
#include <stdexcept>
#include <string>

namespace splat {

class InputError : public std::runtime_error {
 public:
  InputError(const std::filesystem::path& file, const std::string& problem)
      : std::runtime_error(file.string() + ": " + problem), file_(file) {}

  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
};

}  // namespace splat
