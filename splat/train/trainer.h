#pragma once
// Stage one: the reference 3DGS training recipe
// (docs/gaussian-splatting.md) on a scene folder.
//
// One iteration, as the reference's train.py orders it (iterations count
// from 1): set the position learning rate; every 1,000 iterations raise the SH
// degree; take a random training view (each view once per epoch); render;
// L1 + SSIM loss and its gradient; backward; accumulate densification
// statistics, densify and prune, reset opacity; Adam step (skipped for the
// parameters that densification or the reset replaced this iteration, as
// torch skips parameters without a gradient, and after the schedule's last
// iteration). The SH rest's Adam step is taken inside the backward pass
// where it can be (Trainer::backward): the same values, one pass over memory
// fewer.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "splat/checkpoint.h"
#include "splat/gaussians.h"
#include "splat/packed_id_map.h"
#include "splat/pose_file.h"
#include "splat/render/pose_fit.h"
#include "splat/render/renderer.h"
#include "splat/scene.h"
#include "splat/train/adam.h"
#include "splat/train/densify.h"
#include "splat/train/exposure.h"
#include "splat/train/half_views.h"
#include "splat/train/image_loss.h"
#include "splat/train/object_loss.h"
#include "splat/train/resolution_schedule.h"
#include "splat/view_split.h"

namespace splat {

// Pose refinement: a learned correction of every training view's camera pose
// (render/pose_fit.h), for captures whose poses are a pixel or so off (video
// frames with blur and rolling shutter), which otherwise blur the model and
// its masks. Off by default: the reference recipe has none. The step sizes
// decay log-linearly over the schedule, as the position's do.
struct PoseRefinementOptions {
  bool enabled = false;
  // The model is a blur of large Gaussians before densification has given
  // it detail; its pose gradients only start to mean something after that.
  int from_iteration = 1000;
  float lr_rotation_init = 2e-4f;  // radians per step
  float lr_rotation_final = 2e-5f;
  float lr_translation_init = 2e-4f;  // times the scene extent
  float lr_translation_final = 2e-5f;

  void Check() const;  // throws std::invalid_argument with a one-line message
};

struct TrainOptions {
  SceneOptions scene;
  SplitRule split = SplitRule::kAuto;  // auto: images_train/ if present, else every 8th
  uint64_t seed = 0;

  int total_iterations = 30000;  // the schedule's length (learning rate decay, last step)
  int sh_degree = 3;
  int sh_increase_every = 1000;
  float background[3] = {0, 0, 0};

  float lr_position_init = 1.6e-4f;  // times the scene extent
  float lr_position_final = 1.6e-6f;
  // The position learning rate stays at lr_position_init until this
  // iteration, then decays log-linearly to lr_position_final at the
  // schedule's end. 0, the reference recipe: it decays from iteration 0.
  int lr_position_hold_until = 0;
  float lr_sh_dc = 2.5e-3f;
  float lr_sh_rest = 2.5e-3f / 20;
  float lr_opacity = 0.05f;
  float lr_scale = 5e-3f;
  float lr_rotation = 1e-3f;
  float lr_instance_opacity = 0.05f;  // sigma*, once stage two has added it
  // sigma* at the start of stage two: < 0 from sigma (the paper), else this
  // value for every Gaussian (the initialisation's sensitivity study).
  float instance_opacity_init = -1;
  ImageLossOptions loss;
  ObjectLossOptions object_loss;  // stage two: lambda_o > 0

  // Adam steps only the Gaussians in view; those out of view keep their
  // values and moments (GaussianAdam::Culled::kKeep). Off in the reference
  // recipe, whose culled Gaussians step on with zero gradients.
  bool sparse_adam = false;
  // Stage one's training views rendered with fewer pixels while the model is
  // coarse (resolution_schedule.h); off in the reference recipe. Stage two
  // always trains at full resolution, as its ID maps are.
  ResolutionScheduleOptions resolution_schedule;
  // Late in the schedule, each iteration trains on one half of its view
  // (half_views.h); off in the reference recipe.
  HalfViewOptions half_views;

  int densify_from = 500;
  int densify_until = 15000;
  int densify_every = 100;
  int opacity_reset_every = 3000;
  DensifyOptions densify;
  // A learned colour transform per training view (exposure.h); off in the
  // reference recipe. A checkpoint made with it keeps it on.
  ExposureOptions exposure;
  // Learned corrections of the training views' poses; a checkpoint made with
  // them keeps them on.
  PoseRefinementOptions poses;
  // evaluate(): the test views' poses fitted to their photos first (as
  // BARF evaluates models trained with pose refinement); off by default.
  PoseFitOptions test_pose_fit;

  // Throws std::invalid_argument with a one-line message.
  void Check() const;
};

struct IterationStats {
  int iteration = 0;
  ImageLoss loss;
  double psnr = 0;  // of this iteration's training view
  size_t gaussians = 0;
  float lr_position = 0;
  int sh_degree = 0;
  double downscale = 1;          // of this iteration's render (the resolution schedule)
  bool half_view = false;        // the render is one half of the view (half_views.h)
  double object_loss = 0;        // L_obj before its weight (stage two)
  std::vector<int32_t> objects;  // the objects sampled for it
  DensifyResult densified;       // what densification did this iteration, if anything
  bool opacity_reset = false;
  int threads = 0;  // its worker threads, when run_training alternates them (0: not set)
};

struct ViewMetrics {
  std::string name;
  double psnr = 0, ssim = 0;
  // PSNR of the right half after a colour transform fitted on the left half
  // (exposure.h, psnr_after_fit): NeRF in the Wild's protocol.
  double psnr_fitted = 0;
};

// Raised when training produces a non-finite loss; nothing is saved then.
class TrainingDiverged : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Trainer {
 public:
  // Loads the scene (lazily) and splits its views.
  Trainer(const std::filesystem::path& scene_dir, const TrainOptions& options);

  // Starts from the scene's SfM points. Throws InputError if there are none.
  void initialize_from_sfm();
  // Continues exactly where the checkpoint stopped.
  void load_checkpoint(const std::filesystem::path& file);
  void save_checkpoint(const std::filesystem::path& file) const;

  // Stage two: gives the Gaussians their labels (one per Gaussian) and adds
  // the instance opacity sigma*, initialised from sigma. Throws InputError if
  // the object loss is on and a training view has no ID map.
  void start_instance_learning(const std::vector<int32_t>& labels);
  // A new random stream (the order of the views, the objects sampled) in
  // place of the one the checkpoint continues.
  void reseed(uint64_t seed) { rng_.seed(seed); }

  // Decodes the training views (as far as the view cache holds them) and, in
  // stage two, their ID maps, on all cores, so that no iteration of the
  // first epoch waits on a decode on one core. Returns how many of each.
  struct Preloaded {
    size_t views = 0, id_maps = 0;
  };
  Preloaded preload_training_inputs();

  // Runs iterations until `iteration() == until`; calls on_iteration after
  // each one. Throws TrainingDiverged on a non-finite loss.
  void train_until(int until, const std::function<void(const IterationStats&)>& on_iteration = {});

  // Renders the test views; writes PNGs into render_dir if not empty.
  std::vector<ViewMetrics> evaluate(const std::vector<size_t>& views,
                                    const std::filesystem::path& render_dir = {});

  int iteration() const { return iteration_; }
  const GaussianModel& model() const { return model_; }
  GaussianModel& model() { return model_; }
  const ViewSplit& split() const { return split_; }
  Scene& scene() { return *scene_; }
  const TrainOptions& options() const { return options_; }
  float position_learning_rate(int iteration) const;
  float exposure_learning_rate(int iteration) const;
  PoseStep pose_learning_rate(int iteration) const;  // translation in scene units
  bool compensates_exposure() const { return exposure_.size() > 0; }
  const ViewColorTransforms& exposure() const { return exposure_; }
  bool refines_poses() const { return poses_.size() > 0; }
  // The view's camera with its learned pose correction, if any.
  Camera camera_of(size_t view) const;
  // The training views' refined poses (pose_file.h), empty unless refining.
  std::vector<NamedPose> refined_poses() const;
  // The largest correction so far: rotation (radians) and translation.
  std::pair<double, double> largest_pose_correction() const;

 private:
  size_t next_view();
  RenderSettings render_settings() const;
  bool learns_instances() const;
  // The view's ID map at its camera's size, packed (it is kept for the
  // whole run), and the objects it shows.
  struct ObjectMap {
    PackedIdMap ids;
    std::vector<int32_t> objects;
  };
  const ObjectMap& object_map(size_t view);
  // The object loss's ID map folder, resolved on first use.
  const std::filesystem::path& id_map_folder();

  // One iteration of train_until, in its phases. A Step is what the phases
  // of one iteration share.
  struct Step {
    size_t view = 0;
    Camera camera;
    RenderSettings settings;
    BackwardSettings backward;
    const ObjectMap* objects = nullptr;       // the view's objects when stage two learns sigma*
    const IdMap* ids = nullptr;               // its ID map at the render's size
    const ImageRGB* target = nullptr;         // the photo at the render's size
    double loss_weight = 1;                   // the render's share of the view (half_views.h)
    std::array<float, 2> ndc_scale = {1, 1};  // DensificationStats::add's, for a half view
  };
  Step start_step(IterationStats& st);
  void use_half_view(Step& step, IterationStats& st);
  void forward_and_loss(const Step& step, IterationStats& st);
  // Whether iteration it takes Adam's step, and whether it densifies.
  bool steps(int it) const { return it < options_.total_iterations; }
  bool densifies(int it) const;
  GaussianAdam::Culled culled_gaussians() const;
  // Returns whether the SH rest took its Adam step inside the renderer's
  // backward pass (GaussianAdam::begin_sh_rest_step): on every iteration
  // that steps, does not densify and needs no camera gradient.
  bool backward(const Step& step, const IterationStats& st);
  // Densification and opacity resets; which parameter arrays Adam must not
  // step (they were replaced or reset).
  std::array<bool, kParamGroups> densify_or_reset(const Step& step, IterationStats& st);
  void optimiser_step(const Step& step, const IterationStats& st,
                      const std::array<bool, kParamGroups>& skip);

  TrainOptions options_;
  std::unique_ptr<Scene> scene_;
  ViewSplit split_;
  double extent_ = 0;
  GaussianModel model_;
  GaussianAdam adam_{0};
  DensificationStats stats_;
  int iteration_ = 0;
  int sh_degree_ = 0;
  std::mt19937_64 rng_;
  std::vector<size_t> view_stack_;
  std::filesystem::path id_map_folder_;
  std::vector<std::unique_ptr<ObjectMap>> object_maps_;  // per view, loaded on first use
  // Vote protection (ObjectLossOptions::protected_agreement), read on first
  // use: the protected Gaussians, the labels that render them apart from the
  // others (split_labels), and the offset of the others' labels.
  std::vector<uint8_t> protected_;
  std::vector<int32_t> split_labels_;
  int32_t split_offset_ = 0;
  bool protects() const { return options_.object_loss.protected_agreement > 0; }
  void read_protection();
  CpuRenderer renderer_;
  // Reused from iteration to iteration.
  std::unique_ptr<RenderState> render_state_;
  RenderOutput render_out_;
  std::shared_ptr<const PackedImageRGB> held_view_;  // the training view as the cache holds it
  ImageRGB target_;             // the training view's photo, decoded from codes, reused
  ImageRGB downscaled_target_;  // the photo at the resolution schedule's size
  ImageRGB half_target_;        // the half of the photo a half view trains on
  IdMap view_ids_;              // the step's view's ID map, unpacked
  IdMap half_ids_;              // and the half of it
  PixelRect half_;              // the half, in the view's pixels
  RenderOutputGradients out_grads_;
  GaussianGradients grads_;
  ImageLossBuffers loss_buffers_;
  ViewColorTransforms exposure_;  // empty unless exposure compensation is on
  std::vector<float> exposed_;    // the render through the view's transform
  ViewPoseCorrections poses_;     // empty unless pose refinement is on
};

}  // namespace splat
