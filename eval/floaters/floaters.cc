#include "eval/floaters/floaters.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <unordered_map>

#include "splat/render/renderer.h"

namespace study {
using V = Eigen::Vector3d;

void FloaterOptions::Check() const {
  if (!(distance > 0 && std::isfinite(distance)))
    throw std::invalid_argument("the floater distance must be > 0");
}

namespace {

// A point on the canonical shape's surface (sphere, cube [-1,1]^3, cylinder
// r=1 |y|<=1, cone with base r=1 at y=-1 and apex at y=+1), uniform in area
// once scaled by half_size.
V canonical_surface_point(synth::Shape shape, const V& half, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  const double a = 2 * M_PI * u(rng);
  switch (shape) {
    case synth::Shape::kSphere: {
      const double z = 2 * u(rng) - 1, r = std::sqrt(1 - z * z);
      return {r * std::cos(a), r * std::sin(a), z};
    }
    case synth::Shape::kBox: {
      // A face by its scaled area.
      const double areas[3] = {half.y() * half.z(), half.x() * half.z(), half.x() * half.y()};
      double pick = u(rng) * (areas[0] + areas[1] + areas[2]);
      int axis = 0;
      while (axis < 2 && pick > areas[axis]) pick -= areas[axis++];
      V p(2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1);
      p[axis] = u(rng) < 0.5 ? -1 : 1;
      return p;
    }
    case synth::Shape::kCylinder: {
      const double side = 2 * M_PI * 0.5 * (half.x() + half.z()) * 2 * half.y();
      const double caps = 2 * M_PI * half.x() * half.z();
      if (u(rng) * (side + caps) < side) return {std::cos(a), 2 * u(rng) - 1, std::sin(a)};
      const double r = std::sqrt(u(rng));
      return {r * std::cos(a), u(rng) < 0.5 ? -1.0 : 1.0, r * std::sin(a)};
    }
    case synth::Shape::kCone: {
      const double radius = 0.5 * (half.x() + half.z());
      const double side = M_PI * radius * std::hypot(radius, 2 * half.y());
      const double base = M_PI * half.x() * half.z();
      if (u(rng) * (side + base) < side) {
        const double t = std::sqrt(u(rng));  // radius share: area grows with it
        return {t * std::cos(a), 1 - 2 * t, t * std::sin(a)};
      }
      const double r = std::sqrt(u(rng));
      return {r * std::cos(a), -1, r * std::sin(a)};
    }
  }
  return V::Zero();
}

double surface_area(const synth::SceneObject& o) {
  const V& h = o.half_size;
  const double mean = (h.x() + h.y() + h.z()) / 3;
  switch (o.shape) {
    case synth::Shape::kBox:
      return 8 * (h.x() * h.y() + h.y() * h.z() + h.x() * h.z());
    case synth::Shape::kCylinder:
    case synth::Shape::kCone:
      return 4 * M_PI * std::max(h.x(), h.z()) * (h.y() + std::max(h.x(), h.z()));
    case synth::Shape::kSphere:
      return 4 * M_PI * mean * mean;
  }
  return 0;
}

// Points sampled densely on every object's surface, in a hash grid of cells
// as wide as the floater distance: the nearest surface within one cell of a
// point is among the 27 cells around it.
class SurfaceGrid {
 public:
  SurfaceGrid(const synth::World& world, double cell) : cell_(cell) {
    std::mt19937_64 rng(7);
    const double spacing = cell / 4;
    for (const synth::SceneObject& o : world.objects) {
      const size_t n =
          std::clamp<size_t>(size_t(4 * surface_area(o) / (spacing * spacing)), 2000, 4000000);
      const Eigen::Matrix3d R = Eigen::AngleAxisd(o.yaw, V::UnitY()).toRotationMatrix();
      for (size_t i = 0; i < n; ++i) {
        const V local = canonical_surface_point(o.shape, o.half_size, rng);
        const V p = o.position + R * o.half_size.cwiseProduct(local);
        cells_[key(p)].push_back({p.cast<float>(), o.id});
      }
    }
  }

  // Distance to the nearest object surface within `cell` and its object (0
  // and +infinity if none); also whether another object than that one is
  // within `near` (<= cell).
  void nearest(const V& p, double& distance, int32_t& object, int32_t skip_for_near, double near,
               bool& near_other) const {
    distance = std::numeric_limits<double>::infinity();
    object = 0;
    near_other = false;
    const Eigen::Vector3f q = p.cast<float>();
    const long cx = cell_index(p.x()), cy = cell_index(p.y()), cz = cell_index(p.z());
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(pack(cx + dx, cy + dy, cz + dz));
          if (it == cells_.end()) continue;
          for (const Sample& s : it->second) {
            const double d = (s.p - q).norm();
            if (d < distance) distance = d, object = s.object;
            if (s.object != skip_for_near && d <= near) near_other = true;
          }
        }
  }

 private:
  struct Sample {
    Eigen::Vector3f p;
    int32_t object;
  };
  long cell_index(double v) const { return long(std::floor(v / cell_)); }
  static uint64_t pack(long x, long y, long z) {
    const auto b = [](long v) { return uint64_t(v + (1 << 20)) & 0x1FFFFF; };
    return b(x) << 42 | b(y) << 21 | b(z);
  }
  uint64_t key(const V& p) const {
    return pack(cell_index(p.x()), cell_index(p.y()), cell_index(p.z()));
  }

  double cell_;
  std::unordered_map<uint64_t, std::vector<Sample>> cells_;
};

// Whether p lies inside the object (a Gaussian buried in a solid is no floater).
bool inside(const synth::SceneObject& o, const V& p) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(o.yaw, V::UnitY()).toRotationMatrix();
  const V q = (R.transpose() * (p - o.position)).cwiseQuotient(o.half_size);
  const double radial = std::hypot(q.x(), q.z());
  switch (o.shape) {
    case synth::Shape::kSphere:
      return q.norm() < 1;
    case synth::Shape::kBox:
      return q.cwiseAbs().maxCoeff() < 1;
    case synth::Shape::kCylinder:
      return radial < 1 && std::abs(q.y()) < 1;
    case synth::Shape::kCone:
      return std::abs(q.y()) < 1 && radial < 0.5 * (1 - q.y());
  }
  return false;
}

}  // namespace

SurfaceMatch match_surfaces(const splat::GaussianModel& model, const synth::World& world,
                            const FloaterOptions& o) {
  o.Check();
  const SurfaceGrid grid(world, 2 * o.distance);
  const size_t n = model.size();
  SurfaceMatch m{std::vector<uint8_t>(n), std::vector<uint8_t>(n), std::vector<int32_t>(n),
                 std::vector<uint8_t>(n)};
  const Eigen::Vector2d centre(world.look_at.x(), world.look_at.z());
  double region = 0;
  for (const synth::SceneObject& obj : world.objects)
    region =
        std::max(region, (Eigen::Vector2d(obj.position.x(), obj.position.z()) - centre).norm() +
                             obj.half_size.norm());
  region *= 1.5;
  tbb::parallel_for(size_t(0), n, [&](size_t j) {
    const V p(model.means[3 * j], model.means[3 * j + 1], model.means[3 * j + 2]);
    m.in_region[j] = (Eigen::Vector2d(p.x(), p.z()) - centre).norm() < region;
    const double ground = std::abs(p.y());
    const double dome = std::abs(world.enclosure_radius - p.norm());
    double d_object;
    int32_t object;
    bool near_other;
    grid.nearest(p, d_object, object, -1, 0, near_other);
    const double background = std::min(ground, dome);
    m.floater[j] = std::min(d_object, background) > o.distance;
    m.true_object[j] = !m.floater[j] && d_object <= background ? object : 0;
    if (m.floater[j])
      for (const synth::SceneObject& obj : world.objects)
        if (inside(obj, p)) m.floater[j] = 0, m.true_object[j] = obj.id;
    // Another object's surface within twice the distance: on a border.
    grid.nearest(p, d_object, object, m.true_object[j], 2 * o.distance, near_other);
    m.near_another[j] = near_other;
  });
  return m;
}

namespace {

// Sums of the occupancy maps of labels 1 and 2 given to the Gaussians by
// `group` (0: none), with instance opacity sigma or sigma*: one pair per view.
using Occupancy = std::vector<std::pair<double, double>>;
Occupancy occupancy(const splat::GaussianModel& model, const std::vector<int32_t>& group,
                    bool use_sigma_star, const std::vector<splat::Camera>& views) {
  splat::GaussianModel m = model;
  m.labels = group;
  m.has_labels = true;
  if (!use_sigma_star || !model.has_instance_opacity) m.instance_opacity_logits = m.opacity_logits;
  m.has_instance_opacity = true;
  splat::RenderSettings settings;
  settings.color = settings.depth = false;
  settings.sh_degree = 0;
  settings.instance_labels = {1, 2};
  const splat::CpuRenderer renderer;
  Occupancy sums;
  for (const splat::Camera& camera : views) {
    const splat::RenderOutput out = renderer.render(m, camera, settings);
    const size_t plane = size_t(out.width) * out.height;
    double first = 0, second = 0;
    for (size_t p = 0; p < plane; ++p) {
      first += out.instance_maps[p];
      second += out.instance_maps[plane + p];
    }
    sums.push_back({first, second});
  }
  return sums;
}

double share(const std::pair<double, double>& s) {
  return s.first + s.second > 0 ? s.first / (s.first + s.second) : 0;
}

// The share of label 1 pooled over the views.
double share(const Occupancy& views) {
  std::pair<double, double> all{0, 0};
  for (const auto& [first, second] : views) all.first += first, all.second += second;
  return share(all);
}

std::vector<double> shares_per_view(const Occupancy& views) {
  std::vector<double> shares;
  for (const auto& view : views) shares.push_back(share(view));
  return shares;
}

}  // namespace

FloaterReport measure_floaters(const splat::GaussianModel& model, const synth::World& world,
                               const std::vector<splat::Camera>& views, const FloaterOptions& o) {
  if (!model.has_labels) throw std::invalid_argument("the model has no labels (run op2gs-vote)");
  const SurfaceMatch match = match_surfaces(model, world, o);
  FloaterReport r;
  r.distance = o.distance;
  r.gaussians = model.size();
  std::map<int32_t, ObjectContamination> objects;
  for (const synth::SceneObject& obj : world.objects) {
    objects[obj.id].id = obj.id;
    objects[obj.id].name = obj.name;
  }
  std::vector<int32_t> floater_group(model.size()), region_floater_group(model.size()),
      floater_in_mask(model.size()), wrong_in_mask(model.size());
  for (size_t j = 0; j < model.size(); ++j) {
    const int32_t label = model.labels[j], truth = match.true_object[j];
    const bool floater = match.floater[j];
    r.floaters += floater;
    r.floaters_labelled += floater && label != 0;
    floater_group[j] = floater ? 1 : 2;
    region_floater_group[j] = floater && match.in_region[j] ? 1 : 2;
    r.region_gaussians += match.in_region[j];
    r.region_floaters += floater && match.in_region[j];
    floater_in_mask[j] = label == 0 ? 0 : floater ? 1 : 2;
    const bool wrong = label != truth || floater;
    wrong_in_mask[j] = label == 0 ? 0 : wrong ? 1 : 2;
    const double sigma = splat::sigmoid(model.opacity_logits[j]);
    const double sigma_star =
        model.has_instance_opacity ? splat::sigmoid(model.instance_opacity_logits[j]) : sigma;
    if (!floater && truth != 0) {
      ObjectContamination& t = objects[truth];
      t.id = truth;
      ++t.gaussians;
      t.wrong += label != truth;
    }
    if (label == 0) continue;
    ObjectContamination& l = objects[label];
    l.id = label;
    ++l.labelled;
    if (wrong) {
      ++l.labelled_wrongly;
      l.labelled_floaters += floater;
      l.labelled_border += !floater && match.near_another[j];
      l.mean_sigma_wrong += sigma, l.mean_sigma_star_wrong += sigma_star;
    } else {
      l.mean_sigma_right += sigma, l.mean_sigma_star_right += sigma_star;
    }
  }
  for (auto& [id, c] : objects) {
    const double wrong = double(std::max<size_t>(c.labelled_wrongly, 1));
    const double right = double(std::max<size_t>(c.labelled - c.labelled_wrongly, 1));
    c.mean_sigma_wrong /= wrong, c.mean_sigma_star_wrong /= wrong;
    c.mean_sigma_right /= right, c.mean_sigma_star_right /= right;
    r.objects.push_back(c);
  }
  if (!views.empty()) {
    const Occupancy floaters = occupancy(model, floater_group, false, views);
    const Occupancy region_floaters = occupancy(model, region_floater_group, false, views);
    r.floater_opacity_share = share(floaters);
    r.region_floater_opacity_share = share(region_floaters);
    r.view_floater_opacity_share = shares_per_view(floaters);
    r.view_region_floater_opacity_share = shares_per_view(region_floaters);
    r.mask_floater_share_sigma = share(occupancy(model, floater_in_mask, false, views));
    r.mask_floater_share_sigma_star = share(occupancy(model, floater_in_mask, true, views));
    r.mask_wrong_share_sigma = share(occupancy(model, wrong_in_mask, false, views));
    r.mask_wrong_share_sigma_star = share(occupancy(model, wrong_in_mask, true, views));
  }
  return r;
}

}  // namespace study
