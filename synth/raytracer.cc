#include "synth/raytracer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace synth {
namespace {

using V = Eigen::Vector3d;
constexpr double kEps = 1e-6;

// ------------------------------------------------------------ textures ---

uint32_t hash3(int x, int y, int z) {
  uint32_t h = uint32_t(x) * 0x8da6b343u ^ uint32_t(y) * 0xd8163841u ^ uint32_t(z) * 0xcb1ab31fu;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return h;
}

double lattice(int x, int y, int z) { return (hash3(x, y, z) & 0xffffff) / double(0xffffff); }

double smooth(double t) { return t * t * (3 - 2 * t); }

// Trilinear value noise in [0, 1].
double value_noise(const V& p) {
  const double fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
  const int ix = int(fx), iy = int(fy), iz = int(fz);
  const double tx = smooth(p.x() - fx), ty = smooth(p.y() - fy), tz = smooth(p.z() - fz);
  double c[2][2];
  for (int dy = 0; dy < 2; ++dy)
    for (int dz = 0; dz < 2; ++dz)
      c[dy][dz] = lattice(ix, iy + dy, iz + dz) * (1 - tx) + lattice(ix + 1, iy + dy, iz + dz) * tx;
  const double y0 = c[0][0] * (1 - ty) + c[1][0] * ty;
  const double y1 = c[0][1] * (1 - ty) + c[1][1] * ty;
  return y0 * (1 - tz) + y1 * tz;
}

// Fractal noise in about [0, 1]: detail at several scales gives SIFT
// keypoints at every image resolution.
double fbm(const V& p, int octaves = 4) {
  double sum = 0, amp = 0.5, norm = 0;
  V q = p;
  for (int i = 0; i < octaves; ++i) {
    sum += amp * value_noise(q);
    norm += amp;
    amp *= 0.5;
    q = 2.03 * q + V(17.1, 3.7, 9.2);
  }
  return sum / norm;
}

double pattern_value(Pattern pattern, const V& p) {
  switch (pattern) {
    case Pattern::kMottled:
      return smooth(std::clamp(1.6 * fbm(p) - 0.3, 0.0, 1.0));
    case Pattern::kStripes: {
      const double s = std::sin(6.2832 * (p.y() + 0.6 * fbm(0.5 * p)));
      return s > 0 ? 1.0 : 0.0;
    }
    case Pattern::kSpots:
      return value_noise(1.3 * p) > 0.62 ? 1.0 : 0.0;
    case Pattern::kChecker: {
      const int c = int(std::floor(p.x()) + std::floor(p.y()) + std::floor(p.z()));
      return (c & 1) ? 0.85 * fbm(2.0 * p) + 0.15 : 0.3 * fbm(3.0 * p);
    }
  }
  return 0;
}

V hsv(double h, double s, double v) {
  h = 6.0 * (h - std::floor(h));
  const int i = int(h) % 6;
  const double f = h - std::floor(h);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  switch (i) {
    case 0:
      return {v, t, p};
    case 1:
      return {q, v, p};
    case 2:
      return {p, v, t};
    case 3:
      return {p, q, v};
    case 4:
      return {t, p, v};
    default:
      return {v, p, q};
  }
}

// ---------------------------------------------------- unit-shape hits ---
// Each returns the smallest t > kEps and the local normal.

using LocalHit = std::optional<std::pair<double, V>>;

LocalHit keep_nearest(LocalHit a, LocalHit b) {
  if (!a) return b;
  if (!b) return a;
  return a->first <= b->first ? a : b;
}

bool solve_quadratic(double a, double b, double c, double& t0, double& t1) {
  const double disc = b * b - 4 * a * c;
  if (disc < 0 || std::abs(a) < 1e-300) return false;
  const double sq = std::sqrt(disc);
  const double q = b < 0 ? -0.5 * (b - sq) : -0.5 * (b + sq);
  t0 = q / a;
  t1 = std::abs(q) > 1e-300 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

LocalHit hit_sphere(const V& o, const V& d) {
  double t0, t1;
  if (!solve_quadratic(d.dot(d), 2 * o.dot(d), o.dot(o) - 1, t0, t1)) return {};
  const double t = t0 > kEps ? t0 : t1;
  if (t <= kEps) return {};
  return std::make_pair(t, o + t * d);
}

LocalHit hit_box(const V& o, const V& d) {
  double tmin = -1e300, tmax = 1e300;
  int axis_min = 0, axis_max = 0;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-300) {
      if (std::abs(o[k]) > 1) return {};
      continue;
    }
    double ta = (-1 - o[k]) / d[k], tb = (1 - o[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    if (ta > tmin) tmin = ta, axis_min = k;
    if (tb < tmax) tmax = tb, axis_max = k;
  }
  if (tmin > tmax) return {};
  const bool from_outside = tmin > kEps;
  const double t = from_outside ? tmin : tmax;
  if (t <= kEps) return {};
  const int axis = from_outside ? axis_min : axis_max;
  V n = V::Zero();
  n[axis] = (o[axis] + t * d[axis]) > 0 ? 1 : -1;
  return std::make_pair(t, n);
}

// Cap at y = y0 (|x,z| <= radius).
LocalHit hit_cap(const V& o, const V& d, double y0, double radius) {
  if (std::abs(d.y()) < 1e-300) return {};
  const double t = (y0 - o.y()) / d.y();
  if (t <= kEps) return {};
  const V p = o + t * d;
  if (p.x() * p.x() + p.z() * p.z() > radius * radius) return {};
  return std::make_pair(t, V(0, y0 > 0 ? 1 : -1, 0));
}

LocalHit hit_cylinder(const V& o, const V& d) {
  LocalHit best;
  double t0, t1;
  if (solve_quadratic(d.x() * d.x() + d.z() * d.z(), 2 * (o.x() * d.x() + o.z() * d.z()),
                      o.x() * o.x() + o.z() * o.z() - 1, t0, t1)) {
    for (double t : {t0, t1}) {
      const V p = o + t * d;
      if (t > kEps && std::abs(p.y()) <= 1) {
        best = std::make_pair(t, V(p.x(), 0, p.z()));
        break;
      }
    }
  }
  best = keep_nearest(best, hit_cap(o, d, 1, 1));
  return keep_nearest(best, hit_cap(o, d, -1, 1));
}

// x^2 + z^2 = k^2 (1 - y)^2 with k = 1/2, y in [-1, 1], plus the base cap.
LocalHit hit_cone(const V& o, const V& d) {
  constexpr double k2 = 0.25;
  LocalHit best;
  const double a = d.x() * d.x() + d.z() * d.z() - k2 * d.y() * d.y();
  const double b = 2 * (o.x() * d.x() + o.z() * d.z() + k2 * (1 - o.y()) * d.y());
  const double c = o.x() * o.x() + o.z() * o.z() - k2 * (1 - o.y()) * (1 - o.y());
  double t0, t1;
  if (solve_quadratic(a, b, c, t0, t1)) {
    for (double t : {t0, t1}) {
      const V p = o + t * d;
      if (t > kEps && p.y() >= -1 && p.y() <= 1) {
        best = std::make_pair(t, V(p.x(), k2 * (1 - p.y()), p.z()));
        break;
      }
    }
  }
  return keep_nearest(best, hit_cap(o, d, -1, 1));
}

}  // namespace

RayTracer::RayTracer(const World& world)
    : world_(world), light_(world.light_direction.normalized()) {
  for (const SceneObject& o : world_.objects) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(o.yaw, V::UnitY()).toRotationMatrix();
    const Eigen::Matrix3d S_inv = o.half_size.cwiseInverse().asDiagonal();
    frames_.push_back({S_inv * R.transpose(), R * S_inv, 1.01 * o.half_size.norm()});
  }
}

std::optional<std::pair<double, V>> RayTracer::intersect_object(const SceneObject& o,
                                                                const V& origin,
                                                                const V& dir) const {
  const Frame& f = frames_[&o - world_.objects.data()];
  // Bounding-sphere rejection.
  const V oc = origin - o.position;
  const double b = oc.dot(dir), c = oc.squaredNorm() - f.bound_radius * f.bound_radius;
  if (c > 0 && (b > 0 || b * b < c)) return {};
  const V lo = f.world_to_local * oc, ld = f.world_to_local * dir;
  LocalHit h;
  switch (o.shape) {
    case Shape::kSphere:
      h = hit_sphere(lo, ld);
      break;
    case Shape::kBox:
      h = hit_box(lo, ld);
      break;
    case Shape::kCylinder:
      h = hit_cylinder(lo, ld);
      break;
    case Shape::kCone:
      h = hit_cone(lo, ld);
      break;
  }
  if (!h) return {};
  // Normals transform with the inverse transpose: R S^-1 for M = R S.
  return std::make_pair(h->first, V((f.normal_to_world * h->second).normalized()));
}

Hit RayTracer::intersect(const V& origin, const V& dir, bool skip_transparent,
                         int skip_object) const {
  Hit best;
  best.t = 1e300;
  // The dome (from inside: the far root) always bounds the ray.
  {
    const double b = origin.dot(dir);
    const double c = origin.squaredNorm() - world_.enclosure_radius * world_.enclosure_radius;
    best.t = -b + std::sqrt(std::max(0.0, b * b - c));
    best.object = Hit::kEnclosure;
    best.normal = -(origin + best.t * dir).normalized();
  }
  if (dir.y() < -1e-12) {
    const double t = -origin.y() / dir.y();
    if (t > kEps && t < best.t) {
      best.t = t;
      best.object = Hit::kGround;
      best.normal = V::UnitY();
    }
  }
  for (size_t i = 0; i < world_.objects.size(); ++i) {
    const SceneObject& o = world_.objects[i];
    if (int(i) == skip_object || (skip_transparent && o.material.opacity < 1)) continue;
    if (auto h = intersect_object(o, origin, dir); h && h->first < best.t) {
      best.t = h->first;
      best.object = int(i);
      best.normal = h->second;
    }
  }
  best.point = origin + best.t * dir;
  if (best.normal.dot(dir) > 0) best.normal = -best.normal;
  return best;
}

V RayTracer::albedo(const Hit& hit) const {
  const V p = hit.point + world_.texture_offset;
  if (hit.object >= 0) {
    const Material& m = world_.objects[hit.object].material;
    const double v =
        pattern_value(m.pattern, m.frequency * (hit.point - world_.objects[hit.object].position) +
                                     world_.texture_offset);
    const double grain = 0.8 + 0.4 * fbm(3.1 * m.frequency * p, 2);
    return (m.base * (1 - v) + m.accent * v) * grain;
  }
  if (hit.object == Hit::kGround) {
    const Eigen::Vector2d xz(hit.point.x(), hit.point.z());
    const double tile = pattern_value(Pattern::kChecker, 2.0 * p);
    const double hue = 0.08 + 0.12 * fbm(0.4 * p, 2);
    V c = hsv(hue, 0.35 + 0.3 * fbm(1.7 * p), 0.35 + 0.55 * tile) * (0.75 + 0.5 * fbm(9.0 * p, 3));
    // A dark mat under the dark object, still faintly textured.
    const double r = (xz - world_.dark_region_center).norm();
    if (r < world_.dark_region_radius) c = V::Constant(0.04) + 0.10 * fbm(6.0 * p) * V::Ones();
    return c;
  }
  // Dome: colourful blotches with fine detail; one dark sector behind the
  // dark object.
  const V dir = hit.point.normalized();
  const V q = 2.2 * dir * world_.enclosure_radius / 7.0 + world_.texture_offset;
  V c = hsv(fbm(0.35 * q, 3), 0.5 + 0.4 * fbm(1.1 * q), 0.3 + 0.6 * fbm(2.3 * q)) *
        (0.7 + 0.6 * fbm(7.0 * q, 3));
  double az = std::atan2(hit.point.z(), hit.point.x()) - world_.dark_azimuth;
  az = std::remainder(az, 2 * M_PI);
  if (std::abs(az) < world_.dark_azimuth_halfwidth && hit.point.y() < 3.0)
    c = V::Constant(0.04) + 0.10 * fbm(5.0 * q) * V::Ones();
  return c;
}

double RayTracer::light_visibility(const V& point) const {
  double visibility = 1.0;
  for (size_t i = 0; i < world_.objects.size(); ++i) {
    if (intersect_object(world_.objects[i], point, light_))
      visibility *= 1.0 - world_.objects[i].material.opacity;
    if (visibility <= 0) return 0;
  }
  return visibility;
}

V RayTracer::surface_color(const Hit& hit) const {
  double light = world_.ambient;
  if (hit.object != Hit::kEnclosure) {
    const double lambert = std::max(0.0, hit.normal.dot(light_));
    if (lambert > 0)
      light += (1 - world_.ambient) * lambert * light_visibility(hit.point + 1e-5 * hit.normal);
  } else {
    light = 1.0;  // the dome is self-lit
  }
  return (albedo(hit) * light).cwiseMin(1.0).cwiseMax(0.0);
}

V RayTracer::highlight(const Hit& hit, const V& dir) const {
  if (world_.specular <= 0 || hit.object < 0) return V::Zero();
  const V half = (light_ - dir).normalized();
  const double cosine = hit.normal.dot(half);
  if (cosine <= 0 || hit.normal.dot(light_) <= 0) return V::Zero();
  const double s = world_.specular * std::pow(cosine, world_.shininess);
  return V::Constant(s * light_visibility(hit.point + 1e-5 * hit.normal));
}

V RayTracer::trace(const V& origin, const V& dir) const {
  V color = V::Zero();
  double remaining = 1.0;
  int skip = -100;
  V o = origin;
  for (int bounce = 0; bounce < 4; ++bounce) {
    const Hit h = intersect(o, dir, false, skip);
    const double a = h.object >= 0 ? world_.objects[h.object].material.opacity : 1.0;
    color += remaining * a * (surface_color(h) + highlight(h, dir));
    remaining *= 1 - a;
    if (remaining <= 1e-4) break;
    // Pass through the semi-transparent object, ignoring its far side.
    skip = h.object;
    o = h.point;
  }
  return color.cwiseMin(1.0);
}

int RayTracer::instance_id(const V& origin, const V& dir) const {
  const Hit h = intersect(origin, dir);
  return h.object >= 0 ? world_.objects[h.object].id : 0;
}

}  // namespace synth
