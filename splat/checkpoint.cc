#include "splat/checkpoint.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

#include "splat/atomic_file.h"
#include "splat/binary_io.h"
#include "splat/error.h"
#include "splat/ply.h"

namespace splat {
namespace fs = std::filesystem;

namespace {
constexpr char kMagic[8] = {'O', 'P', '2', 'G', 'S', 'C', 'K', 'P'};
constexpr uint32_t kVersion = 1;

void write_model(std::ostream& out, const GaussianModel& m) {
  for (int g = 0; g < kParamGroups; ++g) write_vector(out, group_values(m, ParamGroup(g)));
  write_vector(out, m.labels);
  write_pod(out, uint8_t(m.has_instance_opacity));
  write_pod(out, uint8_t(m.has_labels));
}

GaussianModel read_model(std::istream& in) {
  GaussianModel m;
  for (int g = 0; g < kParamGroups; ++g) group_values(m, ParamGroup(g)) = read_vector<float>(in);
  m.labels = read_vector<int32_t>(in);
  m.has_instance_opacity = read_pod<uint8_t>(in);
  m.has_labels = read_pod<uint8_t>(in);
  const size_t n = m.opacity_logits.size();
  for (int g = 0; g < kParamGroups; ++g)
    if (group_values(m, ParamGroup(g)).size() != size_t(group_width(ParamGroup(g))) * n)
      throw std::runtime_error(std::string("inconsistent array ") + group_name(ParamGroup(g)));
  if (m.labels.size() != n) throw std::runtime_error("inconsistent labels");
  return m;
}

CheckpointModel read_head(std::istream& in, const fs::path& file, bool with_model) {
  char magic[8];
  if (!in.read(magic, 8) || !std::equal(magic, magic + 8, kMagic))
    throw InputError(file, "not an op2gs checkpoint");
  if (read_pod<uint32_t>(in) != kVersion) throw InputError(file, "unsupported checkpoint version");
  CheckpointModel c;
  c.iteration = read_pod<int32_t>(in);
  c.sh_degree = read_pod<int32_t>(in);
  if (with_model) c.model = read_model(in);
  return c;
}
}  // namespace

void write_checkpoint_head(std::ostream& out, const GaussianModel& model, int iteration,
                           int sh_degree) {
  out.write(kMagic, 8);
  write_pod(out, kVersion);
  write_pod(out, int32_t(iteration));
  write_pod(out, int32_t(sh_degree));
  write_model(out, model);
}

CheckpointModel read_checkpoint_head(std::istream& in, const fs::path& file, bool with_model) {
  try {
    return read_head(in, file, with_model);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(file, std::string("corrupt checkpoint: ") + e.what());
  }
}

CheckpointModel read_checkpoint_model(const fs::path& file) {
  std::istringstream in(read_text_file(file), std::ios::binary);
  return read_checkpoint_head(in, file, true);
}

int read_checkpoint_iteration(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "cannot read the checkpoint");
  return read_checkpoint_head(in, file, false).iteration;
}

CheckpointModel read_model_file(const fs::path& file) {
  if (!fs::is_regular_file(file)) throw InputError(file, "model file not found");
  if (file.extension() == ".ply") return {read_gaussian_ply(file), 0, kMaxShDegree};
  return read_checkpoint_model(file);
}

}  // namespace splat
