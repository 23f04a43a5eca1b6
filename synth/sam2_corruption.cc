#include "synth/sam2_corruption.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

namespace synth {

void Sam2CorruptionOptions::Check() const {
  for (double v : {strength, boundary_jitter_px, miss_probability, miss_radius, leak_probability,
                   leak_radius, spurious_blobs, spurious_radius, border_bias, small_object_area})
    if (!(v >= 0)) throw std::invalid_argument("SAM2 corruption values must be >= 0");
  if (!(lose_small_objects >= 0 && lose_small_objects <= 1))
    throw std::invalid_argument("the share of small objects lost must be in [0, 1]");
  if (!(persistence_views >= 1))
    throw std::invalid_argument("SAM2 error persistence must be >= 1 view");
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

double equivalent_radius(const ObjectPixels& px) { return std::sqrt(px.pixels.size() / M_PI); }

// Erases a disc of the object around pixel `centre`; `size` in [0.6, 1.4]
// scales the radius.
void miss_part(splat::IdMap& map, int id, const ObjectPixels& px, int centre, double size,
               const Sam2CorruptionOptions& o) {
  paint_disc(map, centre % map.width, centre / map.width,
             std::max(1.5, o.miss_radius * equivalent_radius(px) * size), 0, id, -1);
}

// The pixels a leak starts from: the object's edge with another object, else
// with the background.
const std::vector<int>& leak_edge(const ObjectPixels& px) {
  return px.boundary_to_object.empty() ? px.boundary_to_background : px.boundary_to_object;
}

// Spills the object over a disc around edge pixel `centre`.
void leak_part(splat::IdMap& map, int id, const ObjectPixels& px, int centre, double size,
               const Sam2CorruptionOptions& o) {
  paint_disc(map, centre % map.width, centre / map.width,
             std::max(2.0, o.leak_radius * equivalent_radius(px) * size), id, -1, id);
}

// Stray blobs of random IDs, then the boundary jitter: the errors that do not
// carry over from view to view.
void blobs_and_jitter(splat::IdMap& map, const std::vector<int>& object_ids,
                      const Sam2CorruptionOptions& o, Rng& rng) {
  std::uniform_real_distribution<double> u01(0, 1);
  const double s = o.strength;
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
}

// A miss or a leak that lasts over a run of views: where it sits relative to
// the object's bounding box, and its size, stay the same while the object
// moves in the image, as a part SAM2 lost stays lost.
struct PersistentError {
  bool active = false;
  double fx = 0, fy = 0;  // position in the object's bounding box, [0, 1]
  double size = 1;
};

struct ObjectErrors {
  PersistentError miss, leak;
};

// Of `candidates`, the pixel nearest to the point (fx, fy) of the bounding
// box of the object's pixels.
int nearest_to_box_point(const splat::IdMap& map, const ObjectPixels& px,
                         const std::vector<int>& candidates, double fx, double fy) {
  int x0 = map.width, y0 = map.height, x1 = -1, y1 = -1;
  for (int i : px.pixels) {
    x0 = std::min(x0, i % map.width), x1 = std::max(x1, i % map.width);
    y0 = std::min(y0, i / map.width), y1 = std::max(y1, i / map.width);
  }
  const double tx = x0 + fx * (x1 - x0), ty = y0 + fy * (y1 - y0);
  int best = candidates.front();
  double best_d = 1e300;
  for (int i : candidates) {
    const double d = std::hypot(i % map.width - tx, i / map.width - ty);
    if (d < best_d) best_d = d, best = i;
  }
  return best;
}

// What holds for each object over the whole video (Sam2CorruptionOptions'
// border bias and small objects lost), from its own generator.
struct VideoErrors {
  std::map<int, double> bias;  // fraction of the equivalent radius; < 0 erodes
  std::map<int, bool> lost;    // never tracked while small
};

VideoErrors draw_video_errors(const std::vector<int>& object_ids, const Sam2CorruptionOptions& o,
                              uint64_t seed) {
  VideoErrors v;
  if (o.border_bias <= 0 && o.lose_small_objects <= 0) return v;
  Rng rng(seed ^ 0x3c6ef372fe94f82bULL);
  std::uniform_real_distribution<double> u01(0, 1);
  for (int id : object_ids) {
    v.bias[id] = o.strength * o.border_bias * (2 * u01(rng) - 1);
    v.lost[id] = u01(rng) < std::min(1.0, o.strength * o.lose_small_objects);
  }
  return v;
}

// Erodes (bias < 0) or dilates over the background (bias > 0: pixels that
// are background in `truth` and in `map`) one object's pixels of `map` by
// |bias| times its equivalent radius in `truth`.
void apply_border_bias(splat::IdMap& map, const splat::IdMap& truth, int id, const ObjectPixels& px,
                       double bias) {
  const int r = int(std::lround(std::abs(bias) * equivalent_radius(px)));
  if (r == 0) return;
  cv::Mat mask(map.height, map.width, CV_8U, cv::Scalar(0));
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) mask.at<uint8_t>(y, x) = map.at(x, y) == id;
  const cv::Mat disc = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
  cv::Mat changed;
  if (bias < 0)
    cv::erode(mask, changed, disc);
  else
    cv::dilate(mask, changed, disc);
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      uint16_t& v = map.at(x, y);
      const bool in = changed.at<uint8_t>(y, x);
      if (bias < 0 && v == id && !in) v = 0;
      if (bias > 0 && v == 0 && truth.at(x, y) == 0 && in) v = uint16_t(id);
    }
}

// The whole-video errors of one view, after its per-view errors.
void apply_video_errors(splat::IdMap& map, const splat::IdMap& truth, const VideoErrors& v,
                        const Sam2CorruptionOptions& o) {
  if (v.bias.empty() && v.lost.empty()) return;
  const double image_area = double(truth.width) * truth.height;
  for (const auto& [id, px] : collect(truth)) {
    const auto lost = v.lost.find(id);
    if (lost != v.lost.end() && lost->second &&
        px.pixels.size() < o.small_object_area * image_area) {
      for (uint16_t& value : map.ids)
        if (value == id) value = 0;
      continue;
    }
    const auto bias = v.bias.find(id);
    if (bias != v.bias.end()) apply_border_bias(map, truth, id, px, bias->second);
  }
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
  for (const auto& [id, px] : collect(truth)) {
    if (u01(rng) < std::min(1.0, s * o.miss_probability)) {
      const int centre = pick(px.pixels, rng);
      miss_part(map, id, px, centre, 0.6 + 0.8 * u01(rng), o);
    }
    if (u01(rng) < std::min(1.0, s * o.leak_probability) && !leak_edge(px).empty()) {
      const int centre = pick(leak_edge(px), rng);
      leak_part(map, id, px, centre, 0.6 + 0.8 * u01(rng), o);
    }
  }
  blobs_and_jitter(map, object_ids, o, rng);
  apply_video_errors(map, truth, draw_video_errors(object_ids, o, seed), o);
  return map;
}

std::vector<splat::IdMap> corrupt_sequence_like_sam2(const std::vector<splat::IdMap>& truth,
                                                     const std::vector<int>& object_ids,
                                                     const Sam2CorruptionOptions& o,
                                                     uint64_t seed) {
  o.Check();
  std::vector<splat::IdMap> out(truth.size());
  const auto view_seed = [&](size_t i) { return seed * 31337 + i; };
  const VideoErrors video = draw_video_errors(object_ids, o, seed);
  Sam2CorruptionOptions per_view = o;  // the whole-video errors are added here, once
  per_view.border_bias = per_view.lose_small_objects = 0;
  if (o.persistence_views <= 1) {  // independent views
    tbb::parallel_for(size_t(0), truth.size(), [&](size_t i) {
      out[i] = corrupt_like_sam2(truth[i], object_ids, per_view, view_seed(i));
      if (o.strength > 0) apply_video_errors(out[i], truth[i], video, o);
    });
    return out;
  }
  // Each object's misses and leaks, drawn at the start of each run of views.
  // A run ends after each view with probability 1 / persistence_views, so
  // runs last persistence_views views on average and every view still has a
  // miss with probability strength * miss_probability, as without runs.
  Rng rng(seed ^ 0x5a3d2c1bULL);
  std::uniform_real_distribution<double> u01(0, 1);
  const double s = o.strength;
  const auto draw = [&](double probability) {
    PersistentError e;
    e.active = u01(rng) < std::min(1.0, s * probability);
    e.fx = u01(rng), e.fy = u01(rng), e.size = 0.6 + 0.8 * u01(rng);
    return e;
  };
  std::vector<std::map<int, ObjectErrors>> plan(truth.size());
  for (int id : object_ids) {
    ObjectErrors current;
    for (size_t i = 0; i < truth.size(); ++i) {
      if (i == 0 || u01(rng) < 1.0 / o.persistence_views)
        current = {draw(o.miss_probability), draw(o.leak_probability)};
      plan[i][id] = current;
    }
  }
  tbb::parallel_for(size_t(0), truth.size(), [&](size_t i) {
    splat::IdMap map = truth[i];
    if (s > 0) {
      for (const auto& [id, px] : collect(truth[i])) {
        const auto it = plan[i].find(id);
        if (it == plan[i].end()) continue;
        const ObjectErrors& e = it->second;
        if (e.miss.active)
          miss_part(map, id, px, nearest_to_box_point(map, px, px.pixels, e.miss.fx, e.miss.fy),
                    e.miss.size, o);
        if (e.leak.active && !leak_edge(px).empty())
          leak_part(map, id, px, nearest_to_box_point(map, px, leak_edge(px), e.leak.fx, e.leak.fy),
                    e.leak.size, o);
      }
      Rng view_rng(view_seed(i));
      blobs_and_jitter(map, object_ids, o, view_rng);
      apply_video_errors(map, truth[i], video, o);
    }
    out[i] = std::move(map);
  });
  return out;
}

}  // namespace synth
