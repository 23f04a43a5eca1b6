#include "splat/label/track_ids.h"

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <unordered_map>

namespace splat {

void IdCooccurrence::add_view(const std::vector<int32_t>& ids) {
  std::vector<int32_t> sorted;
  for (int32_t id : ids)
    if (id) sorted.push_back(id);
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  for (size_t p = 0; p < sorted.size(); ++p) {
    ++views_[sorted[p]];
    for (size_t q = p + 1; q < sorted.size(); ++q) ++together_[{sorted[p], sorted[q]}];
  }
}

size_t IdCooccurrence::views(int32_t id) const {
  const auto it = views_.find(id);
  return it == views_.end() ? 0 : it->second;
}

size_t IdCooccurrence::together(int32_t a, int32_t b) const {
  const auto it = together_.find({std::min(a, b), std::max(a, b)});
  return it == together_.end() ? 0 : it->second;
}

std::vector<int32_t> segments_in_map(const IdMap& map, double min_share) {
  std::map<int32_t, size_t> pixels;
  for (uint16_t id : map.ids)
    if (id) ++pixels[id];
  const double least = std::max(16.0, min_share * double(map.ids.size()));
  std::vector<int32_t> ids;
  for (const auto& [id, n] : pixels)
    if (double(n) >= least) ids.push_back(id);
  return ids;
}

void TrackIdOptions::Check() const {
  if (!(min_association > 0 && min_association <= 1))
    throw std::invalid_argument("the ID association threshold must be in (0, 1]");
  if (!(max_together >= 0 && max_together < 1))
    throw std::invalid_argument("the share of views seen together must be in [0, 1)");
  if (!(min_segment_share >= 0 && min_segment_share < 1))
    throw std::invalid_argument("the least segment share must be in [0, 1)");
  if (!(min_covered_share > 0 && min_covered_share <= 1))
    throw std::invalid_argument("the covered share must be in (0, 1]");
  if (min_visible < 1) throw std::invalid_argument("min_visible must be >= 1");
}

namespace {

// Union-find over IDs that keeps each group's members.
class Groups {
 public:
  int32_t root(int32_t id) {
    auto it = parent_.find(id);
    if (it == parent_.end()) {
      parent_[id] = id;
      members_[id] = {id};
      return id;
    }
    while (parent_[id] != id) id = parent_[id] = parent_[parent_[id]];
    return id;
  }
  const std::vector<int32_t>& members(int32_t root) { return members_[root]; }
  void join(int32_t a, int32_t b) {
    a = root(a), b = root(b);
    parent_[b] = a;
    auto& m = members_[a];
    m.insert(m.end(), members_[b].begin(), members_[b].end());
    members_.erase(b);
  }
  const std::map<int32_t, std::vector<int32_t>>& all() const { return members_; }

 private:
  std::map<int32_t, int32_t> parent_;
  std::map<int32_t, std::vector<int32_t>> members_;
};

}  // namespace

TrackIdResult find_switched_ids(const LabelVotes::IdAssociation& association,
                                const IdCooccurrence& cooccurrence, const TrackIdOptions& o) {
  o.Check();
  // Two IDs seen together in more than the tolerated share of views are two objects.
  const auto apart = [&](int32_t a, int32_t b) {
    const double rarer = double(std::min(cooccurrence.views(a), cooccurrence.views(b)));
    return double(cooccurrence.together(a, b)) <= o.max_together * rarer;
  };
  struct Candidate {
    double strength;
    int32_t a, b;
  };
  std::vector<Candidate> candidates;
  TrackIdResult result;
  for (const auto& [pair, shared] : association.shared) {
    const auto [a, b] = pair;
    const double strength = std::max(association.association(a, b), association.association(b, a));
    if (strength >= 0.1)
      result.pairs.push_back({a, b, association.association(a, b), association.association(b, a),
                              cooccurrence.together(a, b), cooccurrence.views(a),
                              cooccurrence.views(b)});
    if (strength >= o.min_association && apart(a, b)) candidates.push_back({strength, a, b});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return x.strength != y.strength ? x.strength > y.strength
                                    : std::pair(x.a, x.b) < std::pair(y.a, y.b);
  });
  Groups groups;
  for (const Candidate& c : candidates) {
    const int32_t ra = groups.root(c.a), rb = groups.root(c.b);
    if (ra == rb) continue;
    bool compatible = true;
    for (int32_t x : groups.members(ra))
      for (int32_t y : groups.members(rb)) compatible = compatible && apart(x, y);
    if (compatible) groups.join(ra, rb);
  }
  const auto votes = [&](int32_t id) {
    const auto it = association.votes.find(id);
    return it == association.votes.end() ? 0.0 : it->second;
  };
  for (const auto& [root, members] : groups.all()) {
    if (members.size() < 2) continue;
    JoinedIds g;
    g.kept = *std::max_element(members.begin(), members.end(), [&](int32_t x, int32_t y) {
      return votes(x) != votes(y) ? votes(x) < votes(y) : x > y;  // most votes, then smallest
    });
    for (int32_t id : members) {
      result.canonical[id] = g.kept;
      if (id != g.kept) g.joined.push_back(id);
    }
    std::sort(g.joined.begin(), g.joined.end());
    result.groups.push_back(std::move(g));
  }
  return result;
}

std::vector<MergedSegment> find_merged_segments(const GaussianModel& model,
                                                const std::vector<int32_t>& labels,
                                                const Camera& camera, const IdMap& ids,
                                                const DepthMap* depth, const VoteOptions& vote,
                                                const std::map<int32_t, int32_t>& canonical,
                                                const TrackIdOptions& o) {
  const CentreVisibility visibility(camera, depth, vote);
  // Per (segment ID, label): the visible Gaussians; per label: all of them.
  using Counts = std::unordered_map<uint64_t, uint32_t>;
  tbb::combinable<std::pair<Counts, Counts>> local;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, model.size(), 16384), [&](const auto& range) {
    auto& [pairs, visible] = local.local();
    int x, y;
    float z;
    for (size_t j = range.begin(); j < range.end(); ++j) {
      const int32_t label = labels[j];
      if (label == 0 || !visibility.test(&model.means[3 * j], x, y, z)) continue;
      int32_t id = ids.at(x, y);
      if (const auto it = canonical.find(id); it != canonical.end()) id = it->second;
      ++visible[uint32_t(label)];
      if (id != 0 && id != label) ++pairs[uint64_t(uint32_t(id)) << 32 | uint32_t(label)];
    }
  });
  Counts pairs, visible;
  local.combine_each([&](const std::pair<Counts, Counts>& c) {
    for (const auto& [k, n] : c.first) pairs[k] += n;
    for (const auto& [k, n] : c.second) visible[k] += n;
  });
  std::map<int32_t, std::vector<int32_t>> covers;
  for (const auto& [key, n] : pairs) {
    const int32_t id = int32_t(key >> 32), label = int32_t(key & 0xFFFFFFFFu);
    const uint32_t seen = visible[uint32_t(label)];
    if (seen >= uint32_t(o.min_visible) && double(n) >= o.min_covered_share * seen)
      covers[id].push_back(label);
  }
  std::vector<MergedSegment> out;
  for (auto& [id, labels_covered] : covers) {
    std::sort(labels_covered.begin(), labels_covered.end());
    out.push_back({id, labels_covered});
  }
  return out;
}

}  // namespace splat
