#include "splat/train/trainer.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>

#include "splat/atomic_file.h"
#include "splat/dataset_layout.h"
#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/image_quality.h"
#include "splat/train/initialize.h"

namespace splat {
namespace fs = std::filesystem;

namespace {
// The reference's get_expon_lr_func: log-linear from init at iteration
// `from` (0 in the reference) to final at the end of the schedule. Every
// decaying learning rate uses it.
double log_linear_decay(int iteration, int total_iterations, float init, float final,
                        int from = 0) {
  const double t = std::clamp(double(iteration - from) / (total_iterations - from), 0.0, 1.0);
  return std::exp((1 - t) * std::log(init) + t * std::log(final));
}
}  // namespace

void PoseRefinementOptions::Check() const {
  if (from_iteration < 1) throw std::invalid_argument("pose refinement must start at >= 1");
  for (float lr : {lr_rotation_init, lr_rotation_final, lr_translation_init, lr_translation_final})
    if (!(lr > 0)) throw std::invalid_argument("pose refinement learning rates must be > 0");
}

void TrainOptions::Check() const {
  scene.Check();
  auto fail = [](const std::string& s) { throw std::invalid_argument(s); };
  if (total_iterations < 1) fail("total_iterations must be >= 1");
  if (sh_degree < 0 || sh_degree > 3) fail("sh_degree must be 0..3");
  if (sh_increase_every < 1) fail("sh_increase_every must be >= 1");
  if (lr_position_hold_until < 0 || lr_position_hold_until >= total_iterations)
    fail("the position learning rate's hold must end within the schedule");
  exposure.Check();
  poses.Check();
  test_pose_fit.Check();
  resolution_schedule.Check();
  half_views.Check();
  if (instance_opacity_init >= 1 || (instance_opacity_init >= 0 && instance_opacity_init <= 0))
    fail("the initial instance opacity must be in (0, 1), or negative for sigma's");
  if (densify_every < 1 || opacity_reset_every < 1) fail("densification intervals must be >= 1");
  for (float lr : {lr_position_init, lr_position_final, lr_sh_dc, lr_sh_rest, lr_opacity, lr_scale,
                   lr_rotation, lr_instance_opacity})
    if (!(lr >= 0)) fail("learning rates must be >= 0");
  if (!(loss.lambda_ssim >= 0 && loss.lambda_ssim <= 1)) fail("lambda_ssim must be in [0, 1]");
  object_loss.Check();
}

Trainer::Trainer(const fs::path& scene_dir, const TrainOptions& options)
    : options_(options), rng_(options.seed) {
  options_.Check();
  scene_ = Scene::load(scene_dir, options_.scene);
  split_ = split_views(*scene_, options_.split);
  extent_ = scene_->extent();
  if (options_.exposure.enabled) exposure_ = ViewColorTransforms(scene_->views().size());
  if (options_.poses.enabled) poses_ = ViewPoseCorrections(scene_->views().size());
}

Camera Trainer::camera_of(size_t view) const {
  const Camera& camera = scene_->views()[view].camera;
  return refines_poses() ? poses_.apply(view, camera) : camera;
}

std::vector<NamedPose> Trainer::refined_poses() const {
  std::vector<NamedPose> poses;
  if (!refines_poses()) return poses;
  for (size_t v : split_.train) {
    const Camera c = camera_of(v);
    poses.push_back({scene_->views()[v].name, c.R, c.t});
  }
  return poses;
}

std::pair<double, double> Trainer::largest_pose_correction() const {
  double angle = 0, distance = 0;
  if (!refines_poses()) return {angle, distance};
  for (size_t v : split_.train) {
    angle = std::max(angle, poses_.angle(v));
    distance = std::max(distance, poses_.distance(v));
  }
  return {angle, distance};
}

void Trainer::initialize_from_sfm() {
  if (scene_->points().empty())
    throw InputError(scene_->root() / options_.scene.sparse_dir,
                     "the COLMAP model has no 3D points to start from (run op2gs-sfm)");
  model_ = initialize_from_points(scene_->points(), scene_->point_colors());
  adam_ = GaussianAdam(model_.size());
  stats_.reset(model_.size());
  iteration_ = 0;
  sh_degree_ = 0;
  view_stack_.clear();
}

void Trainer::start_instance_learning(const std::vector<int32_t>& labels) {
  if (labels.size() != model_.size())
    throw std::invalid_argument(
        fmt::format("{} labels for {} Gaussians", labels.size(), model_.size()));
  model_.labels = labels;
  model_.has_labels = true;
  model_.instance_opacity_logits = model_.opacity_logits;  // sigma* starts as sigma
  if (options_.instance_opacity_init >= 0)
    std::fill(model_.instance_opacity_logits.begin(), model_.instance_opacity_logits.end(),
              logit(options_.instance_opacity_init));
  model_.has_instance_opacity = true;
  adam_.reset_moments(ParamGroup::kInstanceOpacity);
  if (options_.object_loss.weight <= 0) return;
  for (size_t v : split_.train) {
    const View& view = scene_->views()[v];
    check_id_map_header(require_id_map(id_map_folder(), view.name), view.camera.width,
                        view.camera.height);
  }
}

Trainer::Preloaded Trainer::preload_training_inputs() {
  Preloaded p;
  p.views = scene_->preload(split_.train);
  if (!learns_instances()) return p;
  // Sized and resolved before the threads fill their own views' entries.
  if (object_maps_.size() != scene_->views().size()) object_maps_.resize(scene_->views().size());
  id_map_folder();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, split_.train.size(), 1), [&](const auto& r) {
    for (size_t k = r.begin(); k < r.end(); ++k) object_map(split_.train[k]);
  });
  p.id_maps = split_.train.size();
  return p;
}

const fs::path& Trainer::id_map_folder() {
  if (id_map_folder_.empty())
    id_map_folder_ =
        scene_->root() / resolve_id_map_folder(scene_->root(), options_.object_loss.id_maps);
  return id_map_folder_;
}

bool Trainer::learns_instances() const {
  return options_.object_loss.weight > 0 && model_.has_labels && model_.has_instance_opacity;
}

const Trainer::ObjectMap& Trainer::object_map(size_t view) {
  if (object_maps_.size() != scene_->views().size()) object_maps_.resize(scene_->views().size());
  if (!object_maps_[view]) {
    const View& v = scene_->views()[view];
    const fs::path file = require_id_map(id_map_folder(), v.name);
    auto m = std::make_unique<ObjectMap>();
    IdMap ids = read_id_map_for_view(file, v.camera.width, v.camera.height);
    remap_ids(ids, options_.object_loss.id_remap);
    m->objects = objects_in_map(ids);
    m->ids = PackedIdMap::pack(ids);
    if (const auto it = options_.object_loss.ignored_ids.find(v.name);
        it != options_.object_loss.ignored_ids.end())
      std::erase_if(m->objects, [&](int32_t id) {
        return std::find(it->second.begin(), it->second.end(), id) != it->second.end();
      });
    object_maps_[view] = std::move(m);
  }
  return *object_maps_[view];
}

void Trainer::read_protection() {
  if (protected_.size() == model_.size()) return;
  protected_ = read_protected_gaussians(options_.object_loss.label_agreement,
                                        options_.object_loss.protected_agreement, model_.size());
  split_offset_ = split_label_offset(model_.labels);
  split_labels_ = split_labels(model_.labels, protected_, split_offset_);
}

float Trainer::position_learning_rate(int iteration) const {
  return float(log_linear_decay(iteration, options_.total_iterations, options_.lr_position_init,
                                options_.lr_position_final, options_.lr_position_hold_until) *
               extent_);
}

size_t Trainer::next_view() {
  if (view_stack_.empty()) view_stack_ = split_.train;
  const size_t k = std::uniform_int_distribution<size_t>(0, view_stack_.size() - 1)(rng_);
  const size_t view = view_stack_[k];
  view_stack_.erase(view_stack_.begin() + long(k));
  return view;
}

RenderSettings Trainer::render_settings() const {
  RenderSettings s;
  std::copy_n(options_.background, 3, s.background);
  s.sh_degree = sh_degree_;
  s.depth = false;  // no loss term reads it
  return s;
}

void Trainer::train_until(int until,
                          const std::function<void(const IterationStats&)>& on_iteration) {
  while (iteration_ < until) {
    IterationStats st;
    const Step step = start_step(st);
    forward_and_loss(step, st);
    const bool sh_rest_stepped = backward(step, st);
    std::array<bool, kParamGroups> skip = densify_or_reset(step, st);
    skip[int(ParamGroup::kShRest)] |= sh_rest_stepped;
    optimiser_step(step, st, skip);
    st.gaussians = model_.size();
    if (on_iteration) on_iteration(st);
  }
}

// The next iteration's view, learning rate, SH degree and render settings;
// in stage two, the objects whose maps this step renders.
Trainer::Step Trainer::start_step(IterationStats& st) {
  const TrainOptions& o = options_;
  const int it = ++iteration_;
  st.iteration = it;
  st.lr_position = position_learning_rate(it);
  if (it % o.sh_increase_every == 0 && sh_degree_ < o.sh_degree) ++sh_degree_;
  st.sh_degree = sh_degree_;

  Step step;
  step.view = next_view();
  step.camera = camera_of(step.view);
  // A photo the cache holds as floats (resized or not 8-bit) is read in
  // place; one held as 8-bit codes is decoded into target_.
  held_view_ = scene_->packed_image(step.view);
  if (const ImageRGB* floats = held_view_->floats()) {
    step.target = floats;
  } else {
    held_view_->unpack_into(target_);
    step.target = &target_;
  }
  st.downscale = learns_instances() ? 1 : training_downscale(o.resolution_schedule, it);
  if (st.downscale > 1) {
    const ImageRGB& photo = *step.target;
    const auto [w, h] = downscaled_size(photo.width, photo.height, st.downscale);
    step.camera = step.camera.resized(w, h);
    downscaled_target_ = resize_area(photo, w, h);
    step.target = &downscaled_target_;
  }
  if (o.half_views.applies(it)) use_half_view(step, st);
  step.settings = render_settings();
  // Adam reads grads_.visible and steps the culled Gaussians with zero
  // gradients without reading them.
  step.backward.zero_culled_gradients = false;
  step.backward.camera_gradient = refines_poses() && it >= o.poses.from_iteration;
  step.objects = learns_instances() ? &object_map(step.view) : nullptr;
  if (step.objects) {
    step.objects->ids.unpack_into(view_ids_);
    step.ids = &view_ids_;
    if (st.half_view) {
      half_ids_ = crop(view_ids_, half_);
      step.ids = &half_ids_;
    }
    st.objects = sample_objects(step.objects->objects, o.object_loss.objects_per_step, rng_);
    step.settings.instance_labels = st.objects;
    if (protects()) {
      // Each object's protected Gaussians, whose map reaches sigma* only,
      // then its others.
      read_protection();
      step.settings.labels = split_labels_;
      for (int32_t id : st.objects) step.settings.instance_labels.push_back(id + split_offset_);
      step.backward.maps_without_geometry_gradient = int(st.objects.size());
    }
    if (!o.object_loss.reshapes_geometry)
      step.backward.maps_without_geometry_gradient = int(step.settings.instance_labels.size());
  }
  return step;
}

// The render, the image loss (through the view's exposure transform) and,
// in stage two, the object loss; their gradients with respect to the render.
void Trainer::forward_and_loss(const Step& step, IterationStats& st) {
  const TrainOptions& o = options_;
  renderer_.render(model_, step.camera, step.settings, render_out_, &render_state_);
  std::span<const float> shown = render_out_.color;
  if (compensates_exposure()) {
    exposed_.resize(render_out_.color.size());
    exposure_.apply(step.view, render_out_.color, exposed_);
    shown = exposed_;
  }
  st.loss = image_loss(shown, *step.target, o.loss, &out_grads_.color, &loss_buffers_);
  if (step.loss_weight != 1)
    for (float& g : out_grads_.color) g *= float(step.loss_weight);
  const float object_weight = o.object_loss.weight * float(step.loss_weight);
  if (step.objects && protects())
    st.object_loss =
        split_object_loss(render_out_.instance_maps, st.objects, *step.ids, object_weight,
                          &out_grads_.instance_maps, o.object_loss.pixel_loss);
  else if (step.objects)
    st.object_loss =
        object_loss(render_out_.instance_maps, render_out_.instance_map_labels, *step.ids,
                    object_weight, &out_grads_.instance_maps, o.object_loss.pixel_loss);
  else
    out_grads_.instance_maps.clear();
  if (!std::isfinite(st.loss.total) || !std::isfinite(st.object_loss))
    throw TrainingDiverged(
        fmt::format("the loss is not finite at iteration {} (view {}); "
                    "nothing was saved after the last checkpoint",
                    st.iteration, scene_->views()[step.view].name));
  st.psnr = 10 * std::log10(1.0 / std::max(st.loss.mse, 1e-20));  // as psnr() computes it
}

// The step trains on one half of its view: the camera, the photo and, in
// stage two, the ID map cut to it, and the loss weighted by its share.
void Trainer::use_half_view(Step& step, IterationStats& st) {
  const Camera c = step.camera;
  half_ = training_half(c.width, c.height, step.view, st.iteration, split_.train.size());
  step.loss_weight = half_share(half_, c.width, c.height);
  step.ndc_scale = {float(c.width) / half_.width, float(c.height) / half_.height};
  step.camera = c.cropped(half_.x, half_.y, half_.width, half_.height);
  half_target_ = crop(*step.target, half_);
  step.target = &half_target_;
  st.half_view = true;
}

// The exposure transform's step, the renderer's backward pass into the
// Gaussians' gradients (and with it the SH rest's Adam step), and the
// camera's correction when poses are refined.
bool Trainer::backward(const Step& step, const IterationStats& st) {
  const TrainOptions& o = options_;
  const int it = st.iteration;
  if (compensates_exposure()) {
    // The last iteration of the schedule takes no step, as for the Gaussians.
    const float lr = steps(it) ? exposure_learning_rate(it) : 0.f;
    exposure_.backward_and_step(step.view, render_out_.color, out_grads_.color, lr,
                                o.exposure.regularization);
  }
  BackwardSettings settings = step.backward;
  std::optional<GaussianAdam::ShRestStep> sh_rest_step;
  if (steps(it) && !densifies(it) && !settings.camera_gradient && o.lr_sh_rest > 0) {
    sh_rest_step.emplace(
        adam_.begin_sh_rest_step(model_, o.lr_sh_rest, sh_degree_, culled_gaussians()));
    settings.sh_rest_sink = &*sh_rest_step;
  }
  renderer_.backward(model_, step.camera, step.settings, settings, *render_state_, out_grads_,
                     grads_);
  if (settings.camera_gradient && steps(it))
    poses_.step(step.view, grads_.camera, pose_learning_rate(it));
  return sh_rest_step.has_value();
}

bool Trainer::densifies(int it) const {
  const TrainOptions& o = options_;
  return it < o.densify_until && it > o.densify_from && it % o.densify_every == 0;
}

GaussianAdam::Culled Trainer::culled_gaussians() const {
  return options_.sparse_adam ? GaussianAdam::Culled::kKeep : GaussianAdam::Culled::kZeroGradients;
}

std::array<bool, kParamGroups> Trainer::densify_or_reset(const Step& step, IterationStats& st) {
  const TrainOptions& o = options_;
  const int it = st.iteration;
  std::array<bool, kParamGroups> skip{};
  if (it >= o.densify_until) return skip;
  stats_.add(grads_, render_out_.radii, step.ndc_scale);
  if (densifies(it)) {
    st.densified = densify_and_prune(model_, adam_, stats_, extent_, it > o.opacity_reset_every,
                                     rng_, o.densify);
    skip.fill(true);  // every parameter array was replaced
  }
  if (it % o.opacity_reset_every == 0) {
    reset_opacity(model_, adam_);
    skip[int(ParamGroup::kOpacity)] = true;
    st.opacity_reset = true;
  }
  return skip;
}

// Adam's step of every parameter array (none on the schedule's last
// iteration); in stage two with protection, sigma* kept in its mask.
void Trainer::optimiser_step(const Step& step, const IterationStats& st,
                             const std::array<bool, kParamGroups>& skip) {
  const TrainOptions& o = options_;
  if (!steps(st.iteration)) return;
  const std::array<float, kParamGroups> lr = {
      st.lr_position,
      o.lr_sh_dc,
      o.lr_sh_rest,
      o.lr_opacity,
      o.lr_scale,
      o.lr_rotation,
      model_.has_instance_opacity ? o.lr_instance_opacity : 0.f};
  adam_.step(model_, grads_, lr, skip, sh_degree_, culled_gaussians());
  if (step.objects && protects())
    keep_in_mask(model_.instance_opacity_logits, model_.opacity_logits, protected_);
}

std::vector<ViewMetrics> Trainer::evaluate(const std::vector<size_t>& views,
                                           const fs::path& render_dir) {
  std::vector<ViewMetrics> metrics;
  RenderSettings settings = render_settings();
  settings.sh_degree = sh_degree_;
  for (size_t v : views) {
    const View& view = scene_->views()[v];
    Camera camera = camera_of(v);
    const bool fit = options_.test_pose_fit.iterations > 0 &&
                     std::find(split_.train.begin(), split_.train.end(), v) == split_.train.end();
    if (fit)
      camera = fit_camera_to_photo(renderer_, model_, camera, *scene_->image(v), settings, extent_,
                                   options_.test_pose_fit);
    const RenderOutput out = renderer_.render(model_, camera, settings);
    const auto target = scene_->image(v);
    ViewMetrics m{view.name, psnr(out.color, target->data),
                  ssim(out.color, target->data, target->width, target->height),
                  psnr_after_fit(out.color, target->data, out.width, out.height, out.width / 2)};
    metrics.push_back(m);
    if (!render_dir.empty()) {
      ImageRGB image(out.width, out.height);
      for (size_t i = 0; i < image.data.size(); ++i)
        image.data[i] = std::clamp(out.color[i], 0.f, 1.f);
      write_image_rgb(render_dir / (fs::path(view.name).stem().string() + ".png"), image);
    }
  }
  return metrics;
}

// ------------------------------------------------------------ checkpoint ---
// The model first (splat/checkpoint.h), then the trainer's own state.

float Trainer::exposure_learning_rate(int iteration) const {
  const ExposureOptions& e = options_.exposure;
  return float(log_linear_decay(iteration, options_.total_iterations, e.lr_init, e.lr_final));
}

PoseStep Trainer::pose_learning_rate(int iteration) const {
  const PoseRefinementOptions& p = options_.poses;
  auto decay = [&](float init, float final) {
    return log_linear_decay(iteration, options_.total_iterations, init, final);
  };
  return {float(decay(p.lr_rotation_init, p.lr_rotation_final)),
          float(decay(p.lr_translation_init, p.lr_translation_final) * extent_)};
}

}  // namespace splat
