#pragma once
// Artifacts are written to a temporary name in the destination folder and
// renamed into place, so a killed stage never leaves a half-written file; a
// stage that writes a folder of them builds it aside (StagedFolder), so a
// stage that fails (a full disk) or is killed leaves the previous ones as
// they were.

#include <filesystem>
#include <functional>
#include <string>

namespace splat {

// A temporary path beside `target` that keeps its extension (image writers
// choose the format from it): "dir/.name.tmp-<pid>-<start time>-<n>.ext",
// the process's ID and start time telling a live writer from a dead one.
std::filesystem::path temporary_path_for(const std::filesystem::path& target);

// Calls write(tmp) and renames tmp onto target. On any exception the
// temporary file is removed and the exception propagates; target is either the
// old file or the complete new one.
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& tmp)>& write);

// Removes the temporary files (temporary_path_for) that runs killed while
// writing left in `dir` (not its subfolders); those of live processes stay.
void remove_abandoned_temporaries(const std::filesystem::path& dir);

// Writes a whole text file atomically.
void write_text_atomically(const std::filesystem::path& target, const std::string& text);

// Throws InputError naming `target` and why the system refused to write it
// (errno: "No space left on device", ...). Call it right after the failure.
[[noreturn]] void throw_write_error(const std::filesystem::path& target);

// A stage's outputs, written into a staging folder inside the output folder
// and moved into place entry by entry only when all are written. Until
// commit() the output folder holds the previous outputs untouched; the
// staging folder of a failed run is removed, and that of a killed run by the
// next run.
class StagedFolder {
 public:
  // kOwned: the folder is the stage's alone (its place in the work folder),
  // so entries the stage no longer writes are removed at commit. kShared: a
  // folder the user named, perhaps holding other files; only the entries the
  // stage writes are replaced.
  enum class Target { kOwned, kShared };
  StagedFolder(std::filesystem::path target, Target kind);
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  // Where the stage writes: "<target>/.staging-<pid>-<start time>".
  const std::filesystem::path& path() const { return staging_; }
  const std::filesystem::path& target() const { return target_; }

  // Swaps every entry of the staging folder with its namesake in the target
  // (renames, no data written) and removes the old ones (and, for kOwned,
  // the entries it did not write).
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path staging_;
  Target kind_;
};

// Reads a whole file; throws InputError naming the file when it cannot be read.
std::string read_text_file(const std::filesystem::path& file);

}  // namespace splat
