#include "splat/train/footprint_weight.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace splat {

void FootprintWeights::compute(std::span<const float> maps, const std::vector<int32_t>& labels,
                               const IdMap& ids, double q) {
  const size_t pixels = ids.ids.size();
  if (maps.size() != labels.size() * pixels)
    throw std::invalid_argument("FootprintWeights: map sizes differ");
  width_ = ids.width;
  height_ = ids.height;
  labels_ = labels;
  sums_.resize(labels.size());
  agreement_.resize(pixels);
  for (size_t j = 0; j < labels.size(); ++j) {
    const float* S = &maps[j * pixels];
    const int32_t label = labels[j];
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 1 << 16), [&](const auto& r) {
      for (size_t p = r.begin(); p < r.end(); ++p) {
        const float s = std::clamp(S[p], 0.f, 1.f);
        const float prob = ids.ids[p] == label ? s : 1 - s;
        // Most pixels are far from the object (prob 1) or deep in it.
        agreement_[p] = prob >= 1 ? 1.f : prob <= 0 ? 0.f : float(std::pow(double(prob), q));
      }
    });
    sums_[j].resize(size_t(width_ + 1) * size_t(height_ + 1));
    const cv::Mat plane(height_, width_, CV_32F, agreement_.data());
    cv::Mat sums(height_ + 1, width_ + 1, CV_64F, sums_[j].data());
    cv::integral(plane, sums, CV_64F);  // into sums_[j]: the size and type match
  }
}

double FootprintWeights::box_mean(size_t plane, int x0, int y0, int x1, int y1) const {
  const std::vector<double>& s = sums_.at(plane);
  const auto at = [&](int x, int y) { return s[size_t(y) * size_t(width_ + 1) + size_t(x)]; };
  const double sum = at(x1, y1) - at(x1, y0) - at(x0, y1) + at(x0, y0);
  return sum / (double(x1 - x0) * double(y1 - y0));
}

double FootprintWeights::weight(size_t plane, float x, float y, int32_t radius) const {
  // The pixel holding the mean (centres at +0.5), moved onto the image for a
  // Gaussian whose mean lies off it but whose tail reaches in.
  const int cx = std::clamp(int(std::floor(x)), 0, width_ - 1);
  const int cy = std::clamp(int(std::floor(y)), 0, height_ - 1);
  const int h = radius / 3;
  return box_mean(plane, std::max(cx - h, 0), std::max(cy - h, 0), std::min(cx + h + 1, width_),
                  std::min(cy + h + 1, height_));
}

std::vector<float> FootprintWeights::per_gaussian(std::span<const int32_t> gaussian_labels,
                                                  std::span<const uint8_t> visible,
                                                  std::span<const float> mean2d,
                                                  std::span<const int32_t> radii) const {
  const size_t n = gaussian_labels.size();
  if (visible.size() != n || mean2d.size() != 2 * n || radii.size() != n)
    throw std::invalid_argument("FootprintWeights: one value per Gaussian expected");
  std::vector<float> weights(n, 1.f);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16384), [&](const auto& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      if (!visible[i] || radii[i] <= 0) continue;
      const auto plane = std::find(labels_.begin(), labels_.end(), gaussian_labels[i]);
      if (plane == labels_.end()) continue;
      weights[i] = float(
          weight(size_t(plane - labels_.begin()), mean2d[2 * i], mean2d[2 * i + 1], radii[i]));
    }
  });
  return weights;
}

void add_weighted(GaussianGradients& into, const GaussianGradients& from,
                  std::span<const float> weights) {
  const size_t n = weights.size();
  struct Array {
    std::vector<float>& into;
    const std::vector<float>& from;
    size_t width;
  };
  const Array arrays[] = {{into.means, from.means, 3},
                          {into.sh_dc, from.sh_dc, 3},
                          {into.sh_rest, from.sh_rest, kShRestFloats},
                          {into.opacity_logits, from.opacity_logits, 1},
                          {into.log_scales, from.log_scales, 3},
                          {into.rotations, from.rotations, 4},
                          {into.instance_opacity_logits, from.instance_opacity_logits, 1},
                          {into.mean2d_ndc, from.mean2d_ndc, 2}};
  if (into.visible.size() != n || from.visible.size() != n)
    throw std::invalid_argument("add_weighted: one weight per Gaussian expected");
  for (const Array& a : arrays)
    if (a.into.size() != a.width * n || a.from.size() != a.width * n)
      throw std::invalid_argument("add_weighted: gradients of other sizes");
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16384), [&](const auto& r) {
    for (const Array& a : arrays)
      for (size_t i = r.begin(); i < r.end(); ++i) {
        if (!into.visible[i]) continue;
        for (size_t k = a.width * i; k < a.width * (i + 1); ++k)
          a.into[k] += weights[i] * a.from[k];
      }
  });
  for (size_t k = 0; k < into.camera.size(); ++k) into.camera[k] += from.camera[k];
}

}  // namespace splat
