// The trainer's checkpoint: the model (checkpoint.h's head, which the other
// stages read), then the training state that resumes a run exactly: Adam's
// moments, the densification statistics, the random generator, the views
// still to visit, the training views' names, and the optional sections
// (exposure transforms, pose corrections), each after its tag.

#include <sstream>

#include "splat/atomic_file.h"
#include "splat/binary_io.h"
#include "splat/checkpoint.h"
#include "splat/error.h"
#include "splat/train/trainer.h"

namespace splat {
namespace fs = std::filesystem;

namespace {
// Marks the optional exposure section at the end of a checkpoint.
constexpr std::string_view kExposureTag = "exposure-transforms-v1";
// Marks the optional pose corrections section.
constexpr std::string_view kPoseTag = "pose-corrections-v1";

bool all_finite(const GaussianModel& m) {
  for (int g = 0; g < kParamGroups; ++g)
    for (float x : group_values(m, ParamGroup(g)))
      if (!std::isfinite(x)) return false;
  return true;
}
}  // namespace

void Trainer::save_checkpoint(const fs::path& file) const {
  if (!all_finite(model_))
    throw TrainingDiverged(
        fmt::format("the model holds non-finite values at iteration {}; the "
                    "checkpoint {} was not written",
                    iteration_, file.string()));
  std::ostringstream out(std::ios::binary);
  write_checkpoint_head(out, model_, iteration_, sh_degree_);
  adam_.save(out);
  stats_.save(out);
  std::ostringstream rng;
  rng << rng_;
  const std::string rng_state = rng.str();
  write_vector(out, std::vector<char>(rng_state.begin(), rng_state.end()));
  std::vector<uint64_t> stack(view_stack_.begin(), view_stack_.end());
  write_vector(out, stack);
  std::vector<char> names;
  for (size_t v : split_.train) {
    const std::string& n = scene_->views()[v].name;
    names.insert(names.end(), n.begin(), n.end());
    names.push_back('\n');
  }
  write_vector(out, names);
  if (compensates_exposure()) {
    write_vector(out, std::vector<char>(kExposureTag.begin(), kExposureTag.end()));
    exposure_.save(out);
  }
  if (refines_poses()) {
    write_vector(out, std::vector<char>(kPoseTag.begin(), kPoseTag.end()));
    poses_.save(out);
  }
  write_text_atomically(file, out.str());
}

void Trainer::load_checkpoint(const fs::path& file) {
  std::istringstream in(read_text_file(file), std::ios::binary);
  try {
    CheckpointModel head = read_checkpoint_head(in, file);
    iteration_ = head.iteration;
    sh_degree_ = head.sh_degree;
    model_ = std::move(head.model);
    adam_.load(in);
    stats_.load(in);
    const std::vector<char> rng_state = read_vector<char>(in);
    std::istringstream rng(std::string(rng_state.begin(), rng_state.end()));
    rng >> rng_;
    const std::vector<uint64_t> stack = read_vector<uint64_t>(in);
    view_stack_.assign(stack.begin(), stack.end());
    const std::vector<char> names = read_vector<char>(in);
    std::string expected;
    for (size_t v : split_.train) expected += scene_->views()[v].name + "\n";
    if (std::string(names.begin(), names.end()) != expected)
      throw InputError(file,
                       "the checkpoint was made with other training views than this scene has");
    if (adam_.size() != model_.size() || stats_.count.size() != model_.size())
      throw InputError(file, "checkpoint arrays disagree in size");
    for (size_t v : view_stack_)
      if (v >= scene_->views().size())
        throw InputError(file, "checkpoint refers to a missing view");
    // Optional sections, each after its tag.
    while (in.peek() != std::char_traits<char>::eof()) {
      const std::vector<char> tag_chars = read_vector<char>(in);
      const std::string tag(tag_chars.begin(), tag_chars.end());
      if (tag == kExposureTag) {
        exposure_.load(in);
        if (exposure_.size() != scene_->views().size())
          throw InputError(file, "the checkpoint's exposure transforms are for another scene");
      } else if (tag == kPoseTag) {
        poses_.load(in);
        if (poses_.size() != scene_->views().size())
          throw InputError(file, "the checkpoint's pose corrections are for another scene");
      } else {
        throw InputError(file, "corrupt checkpoint: unknown section after the training state");
      }
    }
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(file, std::string("corrupt checkpoint: ") + e.what());
  }
}

}  // namespace splat
