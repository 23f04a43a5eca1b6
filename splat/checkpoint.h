#pragma once
// Checkpoints and the model files the stages hand on to each other.
//
// A checkpoint (.ckpt) starts with the model: "OP2GSCKP", a uint32 version,
// the iteration and active SH degree (int32), every parameter group, the
// labels and two flags (sigma* present, labels present), in the layout of
// binary_io.h. The trainer appends its own state after that (Adam's moments,
// densification statistics, random state, view order, training view names);
// the stages after training read only the model.

#include <filesystem>
#include <istream>
#include <ostream>

#include "splat/gaussians.h"

namespace splat {

// The model stored in a checkpoint, with the iteration and active SH degree
// it was saved at.
struct CheckpointModel {
  GaussianModel model;
  int iteration = 0;
  int sh_degree = 0;
};

// Writes the header and the model.
void write_checkpoint_head(std::ostream& out, const GaussianModel& model, int iteration,
                           int sh_degree);
// Reads the header and, if with_model, the model; leaves `in` after them, at
// the trainer's state. Throws InputError naming `file` when it is not a
// checkpoint of this version or is corrupt.
CheckpointModel read_checkpoint_head(std::istream& in, const std::filesystem::path& file,
                                     bool with_model = true);

CheckpointModel read_checkpoint_model(const std::filesystem::path& file);
// The iteration a checkpoint was saved at, from its header alone.
int read_checkpoint_iteration(const std::filesystem::path& file);

// The model a later stage starts from: a checkpoint (.ckpt) or a PLY. The SH
// degree is the checkpoint's active degree, or 3 for a PLY.
CheckpointModel read_model_file(const std::filesystem::path& file);

}  // namespace splat
