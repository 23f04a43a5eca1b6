#pragma once
// Label voting (paper, "Initialization" and appendix "Majority voting"): every
// Gaussian gets the object ID that most training views show at the
// projection of its centre,
//
//   l_j = argmax_k  sum over views i in V_j of 1[L_i(pi_i(mu_j)) = k],
//
// where V_j are the views in which Gaussian j is visible. Ties go to the
// smallest ID; a Gaussian visible in no view gets 0 (background).
//
// Visibility: in front of the near plane and inside the image, and, by
// default, not occluded: its depth is at most (1 + tolerance) times the depth
// rendered for that view at its pixel (the paper's "depth culling"). Pixels
// where the rendered opacity is low have no surface to hide behind.
//
//   LabelVotes votes(model.size());
//   for each training view: votes.add_view(model, camera, ids, &depth, options);
//   model.labels = votes.labels();

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "splat/camera.h"
#include "splat/gaussians.h"
#include "splat/image.h"
#include "splat/render/renderer.h"

namespace splat {

enum class VoteVisibility {
  kDepth,    // in the frustum and not occluded (the default)
  kFrustum,  // in the frustum only (the ablation without depth culling)
};

struct VoteOptions {
  VoteVisibility visibility = VoteVisibility::kDepth;
  // A Gaussian is occluded when its depth exceeds the rendered depth at its
  // pixel by more than this fraction of the rendered depth.
  float depth_tolerance = 0.05f;
  // Pixels whose rendered opacity is below this occlude nothing.
  float min_surface_alpha = 0.5f;
  // The depth maps are rendered at most this wide (0: at the ID map's size);
  // a coarser depth map is much cheaper and the tolerance absorbs the rest.
  int depth_max_width = 480;

  void Check() const;  // throws std::invalid_argument with a one-line message
};

// The depth a view sees: expected depth (sum z_i alpha_i T_i / alpha) where the
// rendered opacity reaches min_surface_alpha, +infinity elsewhere.
struct DepthMap {
  int width = 0, height = 0;
  std::vector<float> depth;  // W * H
};
// A state from an earlier call, when given, is reused (its buffers hold every
// Gaussian: reusing them saves their allocation in every view).
DepthMap render_depth_map(const Renderer& renderer, const GaussianModel& model,
                          const Camera& camera, const VoteOptions& options,
                          std::unique_ptr<RenderState>* state = nullptr);

// Where a Gaussian's centre falls in a view, if it is visible there.
class CentreVisibility {
 public:
  // depth is required for VoteVisibility::kDepth (any size with the camera's
  // aspect ratio); it must outlive this object.
  CentreVisibility(const Camera& camera, const DepthMap* depth, const VoteOptions& options);
  // True, with the pixel (x, y) and camera depth z, if the centre `mean`
  // (3 floats) is visible.
  bool test(const float* mean, int& x, int& y, float& z) const {
    const Eigen::Vector3f xc = R_ * Eigen::Map<const Eigen::Vector3f>(mean) + t_;
    if (!(xc.z() > kNearPlane)) return false;
    const float u = fx_ * xc.x() / xc.z() + cx_, v = fy_ * xc.y() / xc.z() + cy_;
    if (!(u >= 0 && v >= 0 && u < width_ && v < height_)) return false;
    if (depth_) {
      const int dx = std::min(int(u * depth_sx_), depth_->width - 1);
      const int dy = std::min(int(v * depth_sy_), depth_->height - 1);
      if (xc.z() > slack_ * depth_->depth[size_t(dy) * depth_->width + dx]) return false;
    }
    x = int(u), y = int(v), z = xc.z();
    return true;
  }

 private:
  Eigen::Matrix3f R_;
  Eigen::Vector3f t_;
  float fx_, fy_, cx_, cy_, depth_sx_ = 0, depth_sy_ = 0, slack_;
  int width_, height_;
  const DepthMap* depth_ = nullptr;
};

// Per-Gaussian vote counts, filled one view at a time.
class LabelVotes {
 public:
  explicit LabelVotes(size_t num_gaussians);
  ~LabelVotes();
  LabelVotes(LabelVotes&&) noexcept;
  LabelVotes& operator=(LabelVotes&&) noexcept;

  // Every Gaussian visible in the view votes for the ID at the pixel of its
  // centre. ids must have the camera's size. depth (any size with the
  // camera's aspect ratio) is required for VoteVisibility::kDepth.
  void add_view(const GaussianModel& model, const Camera& camera, const IdMap& ids,
                const DepthMap* depth, const VoteOptions& options);

  size_t size() const;
  // The majority label of every Gaussian (ties: smallest ID; no vote: 0).
  std::vector<int32_t> labels() const;
  // Votes cast by Gaussian j, and how many of them went to its label.
  uint32_t votes(size_t j) const;
  uint32_t votes_for_label(size_t j) const;

  // How the IDs share Gaussians: per nonzero ID a, its votes; per pair a < b
  // of nonzero IDs, the sum over Gaussians of c_a c_b / n (c: the Gaussian's
  // votes for an ID, n: all its votes). shared / votes[a] is the share of
  // the views that see a's Gaussians in which they carry b.
  struct IdAssociation {
    std::map<int32_t, double> votes;
    std::map<std::pair<int32_t, int32_t>, double> shared;
    double association(int32_t a, int32_t b) const;  // shared(a, b) / votes[a]
  };
  IdAssociation id_association() const;

  // Counts every vote for an ID under the ID it maps to (IDs not in the map
  // stay): one object seen under several IDs becomes one label.
  void remap_ids(const std::map<int32_t, int32_t>& canonical);

 private:
  struct Storage;
  std::unique_ptr<Storage> storage_;
};

}  // namespace splat
