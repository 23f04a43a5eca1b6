#pragma once
// What the renderer takes and gives back (docs/gaussian-splatting.md,
// "Renderer constants", and the paper's dual-opacity branch).
//
// Conventions: pixel (x, y) is sampled at its centre (x + 0.5, y + 0.5) in
// COLMAP pixel coordinates; images are row-major; colour is interleaved RGB.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "splat/gaussians.h"
#include "splat/huge_page_allocator.h"

namespace splat {

inline constexpr int kTileSize = 16;
inline constexpr float kNearPlane = 0.2f;          // cull camera depth <= this
inline constexpr float kMaxAlpha = 0.99f;          // alpha clamp
inline constexpr float kMinAlpha = 1.0f / 255.0f;  // skip contributions below this
inline constexpr float kMinTransmittance = 1e-4f;  // stop before T falls below this
inline constexpr float kLowPass = 0.3f;            // added to the 2D covariance diagonal
inline constexpr float kFovClamp = 1.3f;           // Jacobian clamp, times tan(fov/2)

struct RenderSettings {
  float background[3] = {0, 0, 0};
  int sh_degree = kMaxShDegree;  // active SH degree, 0..3
  bool color = true;             // false: instance branch only, no colour work
  bool depth = true;             // false: no depth output (a mask query needs none)

  // The dual-opacity branch (paper, eq. S_j). Occupancy maps
  //   S_j(v) = sum over Gaussians i with label j of alpha*_i T_i,
  // alpha*_i = min(0.99, sigma*_i G_i(v)), with T_i and early termination
  // from the colour branch.
  std::vector<int32_t> instance_labels;  // one map per label, in this order
  // Instead: one map per label the model holds (> 0, ascending). Labels need
  // not be contiguous (IDs of other mask tools, objects lost in training), so
  // absent labels get no plane.
  bool all_instance_labels = false;
  // The labels to render the occupancy maps with, one per Gaussian, instead
  // of the model's (empty: the model's). Stage two's vote protection renders
  // an object's protected and unprotected Gaussians to two maps this way
  // (train/object_loss.h, split_labels). Must outlive the render and its
  // backward pass.
  std::span<const int32_t> labels;
  // Label of the Gaussian with the largest alpha*_i along the ray (up to
  // termination; only alpha*_i >= 1/255 counts, else 0).
  bool instance_label_map = false;
  // Ablation baseline: label of the Gaussian with the largest alpha_i T_i.
  bool baseline_label_map = false;
};

// Takes the SH-rest gradient rows of a batch of consecutive Gaussians as the
// backward pass makes them (BackwardSettings::sh_rest_sink).
class ShRestGradientSink {
 public:
  virtual ~ShRestGradientSink() = default;
  // Gaussians first .. first + count - 1: row l of `rows` (kShRestFloats
  // values) is Gaussian first + l's gradient where bit l of `visible` is set
  // (it was in view); `rows` may be null when no bit is. Called once for
  // every Gaussian, from several threads at once on disjoint batches.
  virtual void take(size_t first, size_t count, const float* rows, uint32_t visible) = 0;
};

// What only the backward pass reads.
struct BackwardSettings {
  // The gradient of the first this many occupancy maps reaches sigma* only,
  // not the geometry (stage two's vote protection: the object loss does not
  // move or reshape the Gaussians the votes are sure of).
  int maps_without_geometry_gradient = 0;
  // Also the gradient w.r.t. the camera pose (GaussianGradients::camera), for
  // pose refinement.
  bool camera_gradient = false;
  // false leaves the parameter gradients of the Gaussians out of view
  // (GaussianGradients::visible == 0) unwritten instead of zeroing them, for
  // a caller that reads `visible` first, such as the trainer's Adam step
  // (GaussianAdam::step): about half the Gaussians of a training view, whose
  // 60 zeros would only be written to be read back.
  bool zero_culled_gradients = true;
  // When set, the SH-rest gradients go to it a batch at a time and
  // GaussianGradients::sh_rest is left unwritten: the trainer's Adam steps
  // those rows while they are in cache, where a separate step read the
  // parameters, gradients and moments back from memory (the largest group,
  // 45 of a Gaussian's 59 values). Not with camera_gradient.
  ShRestGradientSink* sh_rest_sink = nullptr;
};

// The images are ImageBuffers: cache-line aligned (whole-line streaming
// stores), in 2 MiB pages when large, and not cleared when they grow, as the
// renderer writes every element.
struct RenderOutput {
  int width = 0, height = 0;
  ImageBuffer<float> color;  // 3 * W * H, over the background
  ImageBuffer<float> alpha;  // W * H, accumulated alpha = 1 - T_final
  ImageBuffer<float> depth;  // W * H, sum of z_i alpha_i T_i (divide by alpha for mean depth);
                             // empty when settings.depth is false
  ImageBuffer<uint32_t> contributors;  // W * H, number of Gaussians blended into the pixel
  // Occupancy maps, one W * H plane per entry of instance_map_labels.
  std::vector<int32_t> instance_map_labels;
  ImageBuffer<float> instance_maps;
  ImageBuffer<int32_t> instance_label;  // W * H if requested
  ImageBuffer<int32_t> baseline_label;  // W * H if requested
  std::vector<int32_t> radii;           // per Gaussian: screen radius in pixels, 0 if culled
};

// dLoss/d(output), same shapes as RenderOutput; empty vectors mean zero.
struct RenderOutputGradients {
  std::vector<float> color;
  std::vector<float> alpha;
  std::vector<float> depth;
  std::vector<float> instance_maps;  // per plane of RenderOutput::instance_maps
};

// dLoss/d(parameter) for every Gaussian parameter, shaped like GaussianModel.
struct GaussianGradients {
  std::vector<float> means;                    // 3N
  std::vector<float> sh_dc;                    // 3N
  std::vector<float> sh_rest;                  // 45N
  std::vector<float> opacity_logits;           // N
  std::vector<float> log_scales;               // 3N
  std::vector<float> rotations;                // 4N
  std::vector<float> instance_opacity_logits;  // N
  // dLoss/d(projected 2D mean) in normalised device units (pixel gradient
  // times half the image size on that axis): the densification statistic.
  std::vector<float> mean2d_ndc;  // 2N
  std::vector<uint8_t> visible;   // N: 1 if the Gaussian was rasterized
  // With BackwardSettings::camera_gradient: dLoss/d(rho, omega) of a pose
  // perturbation applied in the camera frame, x_cam' = exp([omega]x) x_cam +
  // rho, at rho = omega = 0 (the translation rho first). Zero otherwise.
  std::array<double, 6> camera{};

  // Sizes every array for n Gaussians (values are left to the backward pass,
  // which writes all of them, or with BackwardSettings::zero_culled_gradients
  // false those of the visible Gaussians and `visible`).
  void resize(size_t n);
};

}  // namespace splat
