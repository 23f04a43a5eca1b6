#include "splat/train/exposure.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

#include "splat/binary_io.h"
#include "splat/image_quality.h"

namespace splat {

void ExposureOptions::Check() const {
  if (!(lr_init > 0 && lr_final > 0))
    throw std::invalid_argument("exposure learning rates must be > 0");
  if (!(regularization >= 0)) throw std::invalid_argument("exposure regularisation must be >= 0");
}

namespace {
constexpr std::array<float, 12> kIdentity = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
}

ViewColorTransforms::ViewColorTransforms(size_t views)
    : params_(views, kIdentity),
      m_(views, std::array<float, 12>{}),
      v_(views, std::array<float, 12>{}),
      steps_(views, 0) {}

void ViewColorTransforms::apply(size_t view, std::span<const float> in,
                                std::span<float> out) const {
  const std::array<float, 12>& p = params_.at(view);
  for (size_t i = 0; i + 2 < in.size(); i += 3) {
    const float r = in[i], g = in[i + 1], b = in[i + 2];
    for (int c = 0; c < 3; ++c)
      out[i + c] = p[3 * c] * r + p[3 * c + 1] * g + p[3 * c + 2] * b + p[9 + c];
  }
}

void ViewColorTransforms::backward_and_step(size_t view, std::span<const float> in,
                                            std::span<float> grad, float lr, float regularization) {
  std::array<float, 12>& p = params_.at(view);
  std::array<double, 12> g{};
  for (size_t i = 0; i + 2 < in.size(); i += 3) {
    const float x[3] = {in[i], in[i + 1], in[i + 2]};
    const float d[3] = {grad[i], grad[i + 1], grad[i + 2]};
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 3; ++k) g[3 * c + k] += double(d[c]) * x[k];
      g[9 + c] += d[c];
    }
    // dLoss/d(in) = A^T dLoss/d(out).
    for (int k = 0; k < 3; ++k) grad[i + k] = p[k] * d[0] + p[3 + k] * d[1] + p[6 + k] * d[2];
  }
  // Adam with the reference's constants, as torch.optim.Adam.
  constexpr float kBeta1 = 0.9f, kBeta2 = 0.999f, kEps = 1e-15f;
  const uint32_t t = ++steps_[view];
  const float c1 = 1 - std::pow(kBeta1, float(t)), c2 = 1 - std::pow(kBeta2, float(t));
  for (int k = 0; k < 12; ++k) {
    const float gk = float(g[k]) + 2 * regularization * (p[k] - kIdentity[k]);
    m_[view][k] = kBeta1 * m_[view][k] + (1 - kBeta1) * gk;
    v_[view][k] = kBeta2 * v_[view][k] + (1 - kBeta2) * gk * gk;
    p[k] -= lr * (m_[view][k] / c1) / (std::sqrt(v_[view][k] / c2) + kEps);
  }
}

void ViewColorTransforms::save(std::ostream& out) const {
  std::vector<float> flat;
  for (const auto* group : {&params_, &m_, &v_})
    for (const auto& a : *group) flat.insert(flat.end(), a.begin(), a.end());
  write_vector(out, flat);
  write_vector(out, steps_);
}

void ViewColorTransforms::load(std::istream& in) {
  const std::vector<float> flat = read_vector<float>(in);
  const std::vector<uint32_t> steps = read_vector<uint32_t>(in);
  if (flat.size() != 36 * steps.size())
    throw std::runtime_error("exposure transforms disagree in size");
  *this = ViewColorTransforms(steps.size());
  steps_ = steps;
  for (size_t v = 0; v < steps.size(); ++v)
    for (int k = 0; k < 12; ++k) {
      params_[v][k] = flat[12 * v + k];
      m_[v][k] = flat[12 * (steps.size() + v) + k];
      v_[v][k] = flat[12 * (2 * steps.size() + v) + k];
    }
}

double psnr_after_fit(std::span<const float> render, std::span<const float> photo, int width,
                      int height, int fit_width) {
  // Normal equations of [r g b 1] -> each photo channel over the left part.
  Eigen::Matrix4d XtX = Eigen::Matrix4d::Zero();
  Eigen::Matrix<double, 4, 3> XtY = Eigen::Matrix<double, 4, 3>::Zero();
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < fit_width; ++x) {
      const size_t i = 3 * (size_t(y) * width + x);
      const double r[4] = {render[i], render[i + 1], render[i + 2], 1};
      for (int a = 0; a < 4; ++a) {
        for (int b = 0; b < 4; ++b) XtX(a, b) += r[a] * r[b];
        for (int c = 0; c < 3; ++c) XtY(a, c) += r[a] * photo[i + c];
      }
    }
  XtX.diagonal().array() += 1e-6;  // a flat left half leaves the fit unique
  const Eigen::Matrix<double, 4, 3> M = XtX.ldlt().solve(XtY);
  std::vector<float> fitted, truth;
  for (int y = 0; y < height; ++y)
    for (int x = fit_width; x < width; ++x) {
      const size_t i = 3 * (size_t(y) * width + x);
      const double r[4] = {render[i], render[i + 1], render[i + 2], 1};
      for (int k = 0; k < 3; ++k) {
        const double c = r[0] * M(0, k) + r[1] * M(1, k) + r[2] * M(2, k) + r[3] * M(3, k);
        fitted.push_back(float(std::clamp(c, 0.0, 1.0)));
        truth.push_back(photo[i + k]);
      }
    }
  return psnr(fitted, truth);
}

}  // namespace splat
