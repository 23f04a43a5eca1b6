#pragma once
// Artifacts are written to a temporary name in the destination folder and
// renamed into place, so a killed stage never leaves a half-written file.

#include <filesystem>
#include <functional>
#include <string>

namespace splat {

// A temporary path beside `target` that keeps its extension (image writers
// choose the format from it): "dir/.name.tmp-<pid>-<n>.ext".
std::filesystem::path temporary_path_for(const std::filesystem::path& target);

// Calls write(tmp) and renames tmp onto target. On any exception the
// temporary file is removed and the exception propagates; target is either the
// old file or the complete new one.
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& tmp)>& write);

// Writes a whole text file atomically.
void write_text_atomically(const std::filesystem::path& target, const std::string& text);

// Reads a whole file; throws InputError naming the file when it cannot be read.
std::string read_text_file(const std::filesystem::path& file);

}  // namespace splat
