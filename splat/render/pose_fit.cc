#include "splat/render/pose_fit.h"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "splat/binary_io.h"

namespace splat {
namespace {

Eigen::Vector3d vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }
std::array<double, 3> arr(const Eigen::Vector3d& v) { return {v[0], v[1], v[2]}; }

Eigen::Matrix3d exp_so3(const Eigen::Vector3d& omega) {
  const double angle = omega.norm();
  return angle > 0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix()
                   : Eigen::Matrix3d::Identity();
}

Eigen::Vector3d log_so3(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

// Adam with torch's constants; returns the step to take (to subtract).
std::array<double, 6> adam_step(const std::array<double, 6>& g, std::array<double, 6>& m,
                                std::array<double, 6>& v, uint32_t t, PoseStep lr) {
  constexpr double kBeta1 = 0.9, kBeta2 = 0.999, kEps = 1e-15;
  const double c1 = 1 - std::pow(kBeta1, t), c2 = 1 - std::pow(kBeta2, t);
  std::array<double, 6> step;
  for (int k = 0; k < 6; ++k) {
    m[k] = kBeta1 * m[k] + (1 - kBeta1) * g[k];
    v[k] = kBeta2 * v[k] + (1 - kBeta2) * g[k] * g[k];
    step[k] = (k < 3 ? lr.translation : lr.rotation) * (m[k] / c1) / (std::sqrt(v[k] / c2) + kEps);
  }
  return step;
}

}  // namespace

ViewPoseCorrections::ViewPoseCorrections(size_t views)
    : rho_(views, {0, 0, 0}),
      omega_(views, {0, 0, 0}),
      m_(views, std::array<double, 6>{}),
      v_(views, std::array<double, 6>{}),
      steps_(views, 0) {}

Camera ViewPoseCorrections::apply(size_t view, const Camera& camera) const {
  return moved_in_camera_frame(camera, vec(rho_.at(view)), vec(omega_.at(view)));
}

void ViewPoseCorrections::step(size_t view, const std::array<double, 6>& gradient, PoseStep lr) {
  const std::array<double, 6> s =
      adam_step(gradient, m_.at(view), v_.at(view), ++steps_.at(view), lr);
  // The step is a further move in the corrected camera's frame:
  // exp(d_omega) (exp(omega) x + rho) + d_rho.
  const Eigen::Matrix3d dR = exp_so3(-Eigen::Vector3d(s[3], s[4], s[5]));
  rho_[view] = arr(dR * vec(rho_[view]) - Eigen::Vector3d(s[0], s[1], s[2]));
  omega_[view] = arr(log_so3(dR * exp_so3(vec(omega_[view]))));
}

double ViewPoseCorrections::angle(size_t view) const { return vec(omega_.at(view)).norm(); }
double ViewPoseCorrections::distance(size_t view) const { return vec(rho_.at(view)).norm(); }

void ViewPoseCorrections::save(std::ostream& out) const {
  write_vector(out, rho_);
  write_vector(out, omega_);
  write_vector(out, m_);
  write_vector(out, v_);
  write_vector(out, steps_);
}

void ViewPoseCorrections::load(std::istream& in) {
  rho_ = read_vector<std::array<double, 3>>(in);
  omega_ = read_vector<std::array<double, 3>>(in);
  m_ = read_vector<std::array<double, 6>>(in);
  v_ = read_vector<std::array<double, 6>>(in);
  steps_ = read_vector<uint32_t>(in);
  const size_t n = rho_.size();
  if (omega_.size() != n || m_.size() != n || v_.size() != n || steps_.size() != n)
    throw std::runtime_error("pose corrections disagree in size");
}

void PoseFitOptions::Check() const {
  if (iterations < 0) throw std::invalid_argument("pose fit iterations must be >= 0");
  if (!(lr_rotation > 0 && lr_translation > 0))
    throw std::invalid_argument("pose fit learning rates must be > 0");
}

Camera fit_camera_to_photo(const Renderer& renderer, const GaussianModel& model,
                           const Camera& camera, const ImageRGB& photo, RenderSettings settings,
                           double scene_extent, const PoseFitOptions& options) {
  options.Check();
  if (photo.width != camera.width || photo.height != camera.height)
    throw std::invalid_argument("the photo's size differs from its camera's");
  settings.instance_labels.clear();
  settings.all_instance_labels = settings.instance_label_map = settings.baseline_label_map = false;
  settings.color = true;
  settings.depth = false;
  BackwardSettings with_camera_gradient;
  with_camera_gradient.camera_gradient = true;
  ViewPoseCorrections correction(1);
  std::unique_ptr<RenderState> state;
  RenderOutput out;
  RenderOutputGradients grads;
  GaussianGradients gaussian_grads;
  const double pixels = double(photo.data.size());
  for (int it = 0; it < options.iterations; ++it) {
    const Camera current = correction.apply(0, camera);
    renderer.render(model, current, settings, out, &state);
    grads.color.resize(out.color.size());
    for (size_t i = 0; i < grads.color.size(); ++i) {
      const float d = out.color[i] - photo.data[i];
      grads.color[i] = float((d > 0) - (d < 0)) / float(pixels);
    }
    renderer.backward(model, current, settings, with_camera_gradient, *state, grads,
                      gaussian_grads);
    // Log-linear decay to a tenth, so that the last steps settle.
    const double decay = std::pow(0.1, double(it) / std::max(1, options.iterations - 1));
    correction.step(
        0, gaussian_grads.camera,
        {float(options.lr_rotation * decay), float(options.lr_translation * scene_extent * decay)});
  }
  return correction.apply(0, camera);
}

}  // namespace splat
