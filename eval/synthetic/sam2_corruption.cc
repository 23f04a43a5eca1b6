#include "eval/synthetic/sam2_corruption.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

namespace synth {

void Sam2CorruptionOptions::Check() const {
  for (double v : {strength, boundary_jitter_px, miss_probability, miss_radius, leak_probability,
                   leak_radius, spurious_blobs, spurious_radius})
    if (!(v >= 0)) throw std::invalid_argument("SAM2 corruption values must be >= 0");
}

namespace {

using Rng = std::mt19937_64;

cv::Mat as_mat(splat::IdMap& m) { return cv::Mat(m.height, m.width, CV_16U, m.ids.data()); }

// Moves every boundary by a smooth random displacement field.
void jitter_boundaries(splat::IdMap& map, double amplitude, Rng& rng) {
  if (amplitude <= 0) return;
  constexpr int kCell = 12;  // pixels between independent displacement samples
  const int gw = map.width / kCell + 2, gh = map.height / kCell + 2;
  std::uniform_real_distribution<float> u(-float(amplitude), float(amplitude));
  cv::Mat coarse_x(gh, gw, CV_32F), coarse_y(gh, gw, CV_32F);
  for (int y = 0; y < gh; ++y)
    for (int x = 0; x < gw; ++x)
      coarse_x.at<float>(y, x) = u(rng), coarse_y.at<float>(y, x) = u(rng);
  cv::Mat dx, dy;
  cv::resize(coarse_x, dx, cv::Size(map.width, map.height), 0, 0, cv::INTER_CUBIC);
  cv::resize(coarse_y, dy, cv::Size(map.width, map.height), 0, 0, cv::INTER_CUBIC);
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) dx.at<float>(y, x) += x, dy.at<float>(y, x) += y;
  splat::IdMap src = map;
  cv::Mat dst = as_mat(map);
  cv::remap(as_mat(src), dst, dx, dy, cv::INTER_NEAREST, cv::BORDER_REPLICATE);
}

struct ObjectPixels {
  std::vector<int> pixels;              // indices into the map
  std::vector<int> boundary_to_object;  // pixels next to another object
  std::vector<int> boundary_to_background;
};

std::map<int, ObjectPixels> collect(const splat::IdMap& m) {
  std::map<int, ObjectPixels> objects;
  for (int y = 0; y < m.height; ++y) {
    for (int x = 0; x < m.width; ++x) {
      const int id = m.at(x, y);
      if (id == 0) continue;
      const int i = y * m.width + x;
      auto& o = objects[id];
      o.pixels.push_back(i);
      const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
      for (int k = 0; k < 4; ++k) {
        if (nx[k] < 0 || ny[k] < 0 || nx[k] >= m.width || ny[k] >= m.height) continue;
        const int other = m.at(nx[k], ny[k]);
        if (other == id) continue;
        (other == 0 ? o.boundary_to_background : o.boundary_to_object).push_back(i);
        break;
      }
    }
  }
  return objects;
}

// Paints `id` into a disc, either only over pixels that hold `only_over`
// (when >= 0) or only over pixels that do not hold `except` (when >= 0).
void paint_disc(splat::IdMap& m, int cx, int cy, double radius, int id, int only_over, int except) {
  const int r = int(std::ceil(radius));
  for (int y = std::max(0, cy - r); y <= std::min(m.height - 1, cy + r); ++y) {
    for (int x = std::max(0, cx - r); x <= std::min(m.width - 1, cx + r); ++x) {
      if ((x - cx) * (x - cx) + (y - cy) * (y - cy) > radius * radius) continue;
      uint16_t& v = m.at(x, y);
      if (only_over >= 0 && v != only_over) continue;
      if (except >= 0 && v == except) continue;
      v = uint16_t(id);
    }
  }
}

template <typename T>
const T& pick(const std::vector<T>& v, Rng& rng) {
  return v[std::uniform_int_distribution<size_t>(0, v.size() - 1)(rng)];
}

}  // namespace

splat::IdMap corrupt_like_sam2(const splat::IdMap& truth, const std::vector<int>& object_ids,
                               const Sam2CorruptionOptions& o, uint64_t seed) {
  o.Check();
  splat::IdMap map = truth;
  if (o.strength == 0) return map;
  Rng rng(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  const double s = o.strength;
  const auto objects = collect(truth);

  for (const auto& [id, px] : objects) {
    const double radius = std::sqrt(px.pixels.size() / M_PI);
    if (u01(rng) < std::min(1.0, s * o.miss_probability)) {
      const int c = pick(px.pixels, rng);
      paint_disc(map, c % map.width, c / map.width,
                 std::max(1.5, o.miss_radius * radius * (0.6 + 0.8 * u01(rng))), 0, id, -1);
    }
    if (u01(rng) < std::min(1.0, s * o.leak_probability)) {
      const auto& edge =
          px.boundary_to_object.empty() ? px.boundary_to_background : px.boundary_to_object;
      if (!edge.empty()) {
        const int c = pick(edge, rng);
        paint_disc(map, c % map.width, c / map.width,
                   std::max(2.0, o.leak_radius * radius * (0.6 + 0.8 * u01(rng))), id, -1, id);
      }
    }
  }
  if (!object_ids.empty()) {
    const int blobs = std::poisson_distribution<int>(s * o.spurious_blobs)(rng);
    const double diag = std::hypot(map.width, map.height);
    for (int b = 0; b < blobs; ++b) {
      const int x = std::uniform_int_distribution<int>(0, map.width - 1)(rng);
      const int y = std::uniform_int_distribution<int>(0, map.height - 1)(rng);
      paint_disc(map, x, y, std::max(1.5, o.spurious_radius * diag * (0.5 + u01(rng))),
                 pick(object_ids, rng), -1, -1);
    }
  }
  jitter_boundaries(map, s * o.boundary_jitter_px, rng);
  return map;
}

}  // namespace synth
