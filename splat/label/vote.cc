#include "splat/label/vote.h"

#include <tbb/concurrent_vector.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace splat {

void VoteOptions::Check() const {
  if (!(depth_tolerance >= 0)) throw std::invalid_argument("depth tolerance must be >= 0");
  if (!(min_surface_alpha > 0 && min_surface_alpha <= 1))
    throw std::invalid_argument("min_surface_alpha must be in (0, 1]");
  if (depth_max_width < 0) throw std::invalid_argument("depth_max_width must be >= 0");
}

DepthMap render_depth_map(const Renderer& renderer, const GaussianModel& model,
                          const Camera& camera, const VoteOptions& options,
                          std::unique_ptr<RenderState>* state) {
  Camera cam = camera;
  if (options.depth_max_width > 0 && camera.width > options.depth_max_width) {
    const int h = std::max(
        1, int(std::lround(double(camera.height) * options.depth_max_width / camera.width)));
    cam = camera.resized(options.depth_max_width, h);
  }
  RenderSettings settings;
  settings.color = false;  // depth and alpha only: no SH work
  settings.sh_degree = 0;
  const RenderOutput out = renderer.render(model, cam, settings, state);
  DepthMap map{cam.width, cam.height, std::vector<float>(out.depth.size())};
  for (size_t p = 0; p < map.depth.size(); ++p)
    map.depth[p] = out.alpha[p] >= options.min_surface_alpha
                       ? out.depth[p] / out.alpha[p]
                       : std::numeric_limits<float>::infinity();
  return map;
}

CentreVisibility::CentreVisibility(const Camera& camera, const DepthMap* depth,
                                   const VoteOptions& options)
    : R_(camera.R.cast<float>()),
      t_(camera.t.cast<float>()),
      fx_(float(camera.fx)),
      fy_(float(camera.fy)),
      cx_(float(camera.cx)),
      cy_(float(camera.cy)),
      slack_(1.f + options.depth_tolerance),
      width_(camera.width),
      height_(camera.height) {
  if (options.visibility != VoteVisibility::kDepth) return;
  if (!depth || depth->width <= 0 || depth->height <= 0)
    throw std::invalid_argument("depth culling needs a depth map");
  depth_ = depth;
  depth_sx_ = float(depth->width) / camera.width;
  depth_sy_ = float(depth->height) / camera.height;
}

// Most Gaussians see one to a few IDs over all views: six counters inline,
// and a list on the side for the few that see more. IDs are 16-bit (the ID
// maps'); a count stops at 65,535 views.
struct LabelVotes::Storage {
  static constexpr int kInline = 6;
  struct Slot {
    uint16_t id = 0, count = 0;
    void add() { count += count < 0xFFFF ? 1 : 0; }
  };
  struct Counters {
    std::array<Slot, kInline> slots{};
    uint32_t overflow = 0;  // 1 + index into `more`, 0 if none
  };
  static_assert(sizeof(Counters) == 28, "as small as three 32-bit counters were");
  std::vector<Counters> counters;
  tbb::concurrent_vector<std::vector<Slot>> more;

  void add(size_t j, uint16_t id) {
    Counters& c = counters[j];
    for (Slot& s : c.slots) {
      if (s.count && s.id == id) return s.add();
      if (!s.count) return void(s = {id, 1});
    }
    overflow_list(c, id).add();
  }

  // The slot of id on Gaussian c's list on the side (made if needed).
  Slot& overflow_list(Counters& c, uint16_t id) {
    if (!c.overflow) c.overflow = uint32_t(more.emplace_back() - more.begin()) + 1;
    std::vector<Slot>& list = more[c.overflow - 1];
    for (Slot& s : list)
      if (s.id == id) return s;
    list.push_back({id, 0});
    return list.back();
  }

  // Replaces Gaussian j's counts (id -> count, counts of 0 ignored).
  void set(size_t j, const std::map<uint16_t, uint32_t>& counts) {
    Counters& c = counters[j];
    c.slots = {};
    if (c.overflow) more[c.overflow - 1].clear();
    size_t k = 0;
    for (const auto& [id, n] : counts) {
      if (!n) continue;
      const Slot s{id, uint16_t(std::min<uint32_t>(n, 0xFFFF))};
      if (k < kInline)
        c.slots[k++] = s;
      else
        overflow_list(c, id) = s;
    }
  }

  template <typename F>
  void for_each_slot(size_t j, F&& f) const {
    const Counters& c = counters[j];
    for (const Slot& s : c.slots)
      if (s.count) f(s);
    if (c.overflow)
      for (const Slot& s : more[c.overflow - 1]) f(s);
  }

  Slot winner(size_t j) const {
    Slot best;
    for_each_slot(j, [&](const Slot& s) {
      if (s.count > best.count || (s.count == best.count && s.id < best.id)) best = s;
    });
    return best;
  }
};

LabelVotes::LabelVotes(size_t n) : storage_(std::make_unique<Storage>()) {
  storage_->counters.resize(n);
}
LabelVotes::~LabelVotes() = default;
LabelVotes::LabelVotes(LabelVotes&&) noexcept = default;
LabelVotes& LabelVotes::operator=(LabelVotes&&) noexcept = default;

size_t LabelVotes::size() const { return storage_->counters.size(); }

void LabelVotes::add_view(const GaussianModel& model, const Camera& camera, const IdMap& ids,
                          const DepthMap* depth, const VoteOptions& options) {
  if (model.size() != size()) throw std::invalid_argument("model size differs from the votes'");
  if (ids.width != camera.width || ids.height != camera.height)
    throw std::invalid_argument("the ID map must have the camera's size");
  const CentreVisibility visibility(camera, depth, options);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, size(), 16384), [&](const auto& range) {
    int x, y;
    float z;
    for (size_t j = range.begin(); j < range.end(); ++j)
      if (visibility.test(&model.means[3 * j], x, y, z)) storage_->add(j, ids.at(x, y));
  });
}

std::vector<int32_t> LabelVotes::labels() const {
  std::vector<int32_t> out(size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, size(), 16384), [&](const auto& range) {
    for (size_t j = range.begin(); j < range.end(); ++j) out[j] = int32_t(storage_->winner(j).id);
  });
  return out;
}

uint32_t LabelVotes::votes(size_t j) const {
  uint32_t n = 0;
  storage_->for_each_slot(j, [&](const Storage::Slot& s) { n += s.count; });
  return n;
}

uint32_t LabelVotes::votes_for_label(size_t j) const { return storage_->winner(j).count; }

double LabelVotes::IdAssociation::association(int32_t a, int32_t b) const {
  const auto v = votes.find(a);
  const auto s = shared.find({std::min(a, b), std::max(a, b)});
  if (v == votes.end() || s == shared.end() || v->second <= 0) return 0;
  return s->second / v->second;
}

LabelVotes::IdAssociation LabelVotes::id_association() const {
  IdAssociation a;
  std::vector<Storage::Slot> slots;
  for (size_t j = 0; j < size(); ++j) {
    slots.clear();
    uint32_t n = 0;
    storage_->for_each_slot(j, [&](const Storage::Slot& s) {
      n += s.count;
      if (s.id) slots.push_back(s);
    });
    for (size_t p = 0; p < slots.size(); ++p) {
      a.votes[slots[p].id] += slots[p].count;
      for (size_t q = 0; q < slots.size(); ++q) {
        if (slots[p].id >= slots[q].id) continue;
        a.shared[{slots[p].id, slots[q].id}] += double(slots[p].count) * slots[q].count / n;
      }
    }
  }
  return a;
}

void LabelVotes::remap_ids(const std::map<int32_t, int32_t>& canonical) {
  if (canonical.empty()) return;
  for (size_t j = 0; j < size(); ++j) {
    std::map<uint16_t, uint32_t> counts;
    bool changed = false;
    storage_->for_each_slot(j, [&](const Storage::Slot& s) {
      const auto it = canonical.find(s.id);
      const bool moved = it != canonical.end() && it->second != s.id;
      changed |= moved;
      counts[moved ? uint16_t(it->second) : s.id] += s.count;
    });
    if (changed) storage_->set(j, counts);
  }
}

}  // namespace splat
