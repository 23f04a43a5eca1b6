#include "synth/track_errors.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <stdexcept>

namespace synth {

TrackErrorOptions TrackErrorOptions::typical() {
  TrackErrorOptions o;
  o.id_switches = 0.5;  // every other track is lost and re-found once
  o.switch_run_views = 10;
  o.merges = 0.5;  // touching objects are one segment for a while
  o.merge_run_views = 6;
  o.late_objects = 0.2;
  o.late_fraction = 0.3;
  return o;
}

void TrackErrorOptions::Check() const {
  for (double v : {id_switches, merges, late_objects, late_fraction})
    if (!(v >= 0 && std::isfinite(v)))
      throw std::invalid_argument("track errors must be finite and >= 0");
  if (!(switch_run_views >= 1 && merge_run_views >= 1))
    throw std::invalid_argument("track error runs last at least 1 view");
  if (late_objects > 1 || late_fraction > 1)
    throw std::invalid_argument("late_objects and late_fraction are shares in [0, 1]");
}

std::vector<std::pair<int, int>> touching_pairs(const std::vector<splat::IdMap>& truth) {
  std::map<std::pair<int, int>, int> touching, together;
  for (const splat::IdMap& m : truth) {
    std::set<int> seen;
    std::map<std::pair<int, int>, int> edges;
    for (int y = 0; y < m.height; ++y) {
      for (int x = 0; x < m.width; ++x) {
        const int a = m.at(x, y);
        if (a) seen.insert(a);
        for (const auto& [nx, ny] : {std::pair{x + 1, y}, std::pair{x, y + 1}}) {
          if (nx >= m.width || ny >= m.height) continue;
          const int b = m.at(nx, ny);
          if (a && b && a != b) ++edges[{std::min(a, b), std::max(a, b)}];
        }
      }
    }
    for (auto a = seen.begin(); a != seen.end(); ++a)
      for (auto b = std::next(a); b != seen.end(); ++b) ++together[{*a, *b}];
    // A few pixels of contact are an accident of the view, not touching.
    for (const auto& [pair, n] : edges)
      if (n >= 8) ++touching[pair];
  }
  std::vector<std::pair<int, int>> pairs;
  for (const auto& [pair, n] : touching)
    if (5 * n >= together[pair]) pairs.push_back(pair);
  return pairs;
}

namespace {

using Rng = std::mt19937_64;

// Replaces `from` by `to` in views [begin, end).
void relabel(std::vector<splat::IdMap>& maps, size_t begin, size_t end, int from, int to) {
  for (size_t i = begin; i < std::min(end, maps.size()); ++i)
    for (uint16_t& id : maps[i].ids)
      if (id == from) id = uint16_t(to);
}

// A run of views: a uniform start and a geometric length of the given mean.
std::pair<size_t, size_t> draw_run(Rng& rng, size_t views, double mean_length) {
  const size_t begin = std::uniform_int_distribution<size_t>(0, views - 1)(rng);
  std::geometric_distribution<size_t> extra(1.0 / mean_length);
  return {begin, begin + 1 + extra(rng)};
}

}  // namespace

std::vector<int> apply_track_errors(std::vector<splat::IdMap>& maps,
                                    const std::vector<splat::IdMap>& truth,
                                    const std::vector<int>& object_ids, const TrackErrorOptions& o,
                                    uint64_t seed) {
  o.Check();
  std::vector<int> new_ids;
  if (!o.any() || maps.empty()) return new_ids;
  Rng rng(seed * 0xBF58476D1CE4E5B9ULL + 23);
  std::uniform_real_distribution<double> u01(0, 1);
  const size_t n = maps.size();
  for (int id : object_ids) {
    if (u01(rng) >= o.late_objects) continue;
    const size_t first = size_t(std::ceil(u01(rng) * o.late_fraction * double(n)));
    relabel(maps, 0, first, id, 0);
  }
  if (o.merges > 0) {
    for (const auto& [a, b] : touching_pairs(truth)) {
      const int count = std::poisson_distribution<int>(o.merges)(rng);
      for (int k = 0; k < count; ++k) {
        const auto [begin, end] = draw_run(rng, n, o.merge_run_views);
        const bool a_absorbs = u01(rng) < 0.5;
        relabel(maps, begin, end, a_absorbs ? b : a, a_absorbs ? a : b);
      }
    }
  }
  // New IDs follow the largest ID, within the 8 bits of the written maps.
  int next_id = *std::max_element(object_ids.begin(), object_ids.end()) + 1;
  for (int id : object_ids) {
    const int count = std::poisson_distribution<int>(o.id_switches)(rng);
    for (int k = 0; k < count && next_id <= 255; ++k) {
      const auto [begin, end] = draw_run(rng, n, o.switch_run_views);
      relabel(maps, begin, end, id, next_id);
      new_ids.push_back(next_id++);
    }
  }
  return new_ids;
}

}  // namespace synth
