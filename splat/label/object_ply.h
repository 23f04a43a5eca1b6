#pragma once
// The object operations a single label per Gaussian allows: a model of one
// object, or of the scene without it, written as a standard 3DGS PLY
// (op2gs-render --ply-object / --ply-without).
//
// The object is the Gaussians with its label whose instance opacity sigma* is
// at least min_instance_opacity: stage two pushes mislabelled Gaussians'
// sigma* towards 0, and they stay with the scene. A model without sigma*
// (stage one with labels) uses sigma.

#include <cstdint>
#include <filesystem>

#include "splat/gaussians.h"

namespace splat {

GaussianModel select_object(const GaussianModel& model, int32_t object, float min_instance_opacity);
GaussianModel remove_object(const GaussianModel& model, int32_t object, float min_instance_opacity);

struct ObjectPlyOptions {
  std::filesystem::path model;  // checkpoint or PLY with labels
  int32_t object = 0;           // > 0
  bool without = false;         // the scene without the object, instead of the object
  float min_instance_opacity = 0.1f;
  std::filesystem::path out;  // the PLY to write
  void Check() const;         // throws std::invalid_argument
};

struct ObjectPlyResult {
  size_t written = 0, total = 0;  // Gaussians
};

// Reads the model, writes the object's (or the rest's) PLY atomically.
ObjectPlyResult write_object_ply(const ObjectPlyOptions& options);

}  // namespace splat
