#pragma once
// The Gaussian model as structure of arrays: one contiguous array per
// parameter, each Gaussian's components adjacent (means[3*i + k]).
//
// Parameters are stored as the optimiser sees them (before activation):
// opacity and instance opacity as logits (sigmoid), scales as logs (exp),
// rotations as unnormalised quaternions w x y z. SH coefficients beyond the DC
// term are stored coefficient-major, [i][coefficient 1..15][channel], like the
// reference implementation's features_rest tensor; the PLY file stores them
// channel-major and the PLY I/O converts.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace splat {

inline constexpr int kMaxShDegree = 3;
inline constexpr int kShRestCoeffs = 15;                 // (3+1)^2 - 1
inline constexpr int kShRestFloats = 3 * kShRestCoeffs;  // 45

// The activations of the stored opacities: sigma = sigmoid(logit).
inline float sigmoid(float x) { return 1.f / (1.f + std::exp(-x)); }
inline float logit(float p) { return std::log(p / (1 - p)); }

struct GaussianModel {
  std::vector<float> means;           // 3 per Gaussian
  std::vector<float> sh_dc;           // 3 per Gaussian
  std::vector<float> sh_rest;         // 45 per Gaussian, [coefficient][channel]
  std::vector<float> opacity_logits;  // 1 per Gaussian, sigma = sigmoid(logit)
  std::vector<float> log_scales;      // 3 per Gaussian
  std::vector<float> rotations;       // 4 per Gaussian, w x y z
  // OP2GS: the instance opacity sigma* (as a logit) and the object label.
  std::vector<float> instance_opacity_logits;  // 1 per Gaussian
  std::vector<int32_t> labels;                 // 1 per Gaussian, 0 = background
  bool has_instance_opacity = false;
  bool has_labels = false;

  size_t size() const { return opacity_logits.size(); }
  // Resizes every array; new Gaussians are zero with identity rotation.
  void resize(size_t n);
  bool operator==(const GaussianModel&) const = default;
};

// The parameter groups of a model, as the optimiser and the checkpoint see
// them: one array each, group_width floats per Gaussian.
enum class ParamGroup { kMeans, kShDc, kShRest, kOpacity, kScales, kRotations, kInstanceOpacity };
inline constexpr int kParamGroups = 7;
const char* group_name(ParamGroup g);
// Floats per Gaussian in each group.
int group_width(ParamGroup g);
std::vector<float>& group_values(GaussianModel& m, ParamGroup g);
const std::vector<float>& group_values(const GaussianModel& m, ParamGroup g);

// Keeps, in order, the Gaussians i with keep[i] != 0 (every parameter and
// the label).
void keep_gaussians(GaussianModel& m, const std::vector<uint8_t>& keep);

// Keeps, in order, the entries i of v (w values each) with keep[i] != 0.
template <typename T>
void keep_entries(std::vector<T>& v, size_t w, const std::vector<uint8_t>& keep) {
  size_t out = 0;
  for (size_t i = 0; i < keep.size(); ++i) {
    if (!keep[i]) continue;
    for (size_t k = 0; k < w; ++k) v[w * out + k] = v[w * i + k];
    ++out;
  }
  v.resize(w * out);
}

// Puts Gaussian order[k] at position k, in every array (order is a
// permutation of 0..size-1).
void reorder_gaussians(GaussianModel& m, const std::vector<uint32_t>& order);
// The same for one per-Gaussian array of `width` values per Gaussian (float,
// int32_t or double).
template <typename T>
void reorder_array(std::vector<T>& values, size_t width, const std::vector<uint32_t>& order);

// A permutation that puts Gaussians close in space close in memory (Morton
// order of the centres, over the box holding all but the farthest 0.1% on
// each axis). Per-Gaussian passes over many views, as voting makes, then read
// screen-space buffers and tile lists with far fewer cache misses.
std::vector<uint32_t> spatial_order(const GaussianModel& m);

// The inverse permutation: inverse[order[k]] = k.
std::vector<uint32_t> inverse_order(const std::vector<uint32_t>& order);

}  // namespace splat
