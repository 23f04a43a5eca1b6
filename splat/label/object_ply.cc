#include "splat/label/object_ply.h"

#include <stdexcept>
#include <vector>

#include "splat/checkpoint.h"
#include "splat/ply.h"

namespace splat {

namespace {

std::vector<uint8_t> object_membership(const GaussianModel& m, int32_t object, float min_sigma) {
  if (!m.has_labels) throw std::invalid_argument("the model has no labels (run op2gs-vote)");
  std::vector<uint8_t> in(m.size(), 0);
  for (size_t i = 0; i < m.size(); ++i) {
    const float s =
        sigmoid(m.has_instance_opacity ? m.instance_opacity_logits[i] : m.opacity_logits[i]);
    in[i] = m.labels[i] == object && s >= min_sigma;
  }
  return in;
}

}  // namespace

GaussianModel select_object(const GaussianModel& model, int32_t object, float min_sigma) {
  GaussianModel m = model;
  keep_gaussians(m, object_membership(model, object, min_sigma));
  return m;
}

GaussianModel remove_object(const GaussianModel& model, int32_t object, float min_sigma) {
  std::vector<uint8_t> keep = object_membership(model, object, min_sigma);
  for (uint8_t& k : keep) k = !k;
  GaussianModel m = model;
  keep_gaussians(m, keep);
  return m;
}

void ObjectPlyOptions::Check() const {
  if (object <= 0) throw std::invalid_argument("the object ID must be > 0");
  if (out.empty()) throw std::invalid_argument("--ply-out is required");
  if (model.empty()) throw std::invalid_argument("the model is not set");
}

ObjectPlyResult write_object_ply(const ObjectPlyOptions& o) {
  o.Check();
  const GaussianModel m = read_model_file(o.model).model;
  const GaussianModel part = o.without ? remove_object(m, o.object, o.min_instance_opacity)
                                       : select_object(m, o.object, o.min_instance_opacity);
  write_gaussian_ply(o.out, part);
  return {part.size(), m.size()};
}

}  // namespace splat
