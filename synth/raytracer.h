#pragma once
// A small ray tracer for the synthetic scene: exact intersections with the
// canonical shapes, Lambertian shading with one directional light, hard
// shadows and semi-transparent surfaces. Colours are view-independent, so
// multi-view geometry (SfM) and 3DGS fit the images exactly, unless the
// layout asks for specular highlights (World::specular).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

#include "synth/world.h"

namespace synth {

// What a ray hit. object >= 0 is an index into World::objects;
// kGround and kEnclosure are the background surfaces (instance ID 0).
struct Hit {
  static constexpr int kGround = -1;
  static constexpr int kEnclosure = -2;
  double t = 0;
  int object = kGround;
  Eigen::Vector3d point;
  Eigen::Vector3d normal;  // unit, facing the ray's origin
};

class RayTracer {
 public:
  explicit RayTracer(const World& world);

  // Nearest hit along origin + t * dir (dir unit, t > 1e-6). With
  // skip_transparent, semi-transparent objects are ignored; skip_object
  // ignores one object index.
  Hit intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                bool skip_transparent = false, int skip_object = -100) const;

  // Colour seen along a ray, blending through semi-transparent objects.
  Eigen::Vector3d trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const;

  // Instance ID of the first surface along the ray (0 for background).
  int instance_id(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const;

  // Shaded colour of the surface at a hit, without transparency.
  Eigen::Vector3d surface_color(const Hit& hit) const;
  // The view-dependent specular highlight at a hit seen along dir (zero
  // unless the layout is glossy).
  Eigen::Vector3d highlight(const Hit& hit, const Eigen::Vector3d& dir) const;

  const World& world() const { return world_; }

 private:
  std::optional<std::pair<double, Eigen::Vector3d>> intersect_object(
      const SceneObject& o, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const;
  Eigen::Vector3d albedo(const Hit& hit) const;
  double light_visibility(const Eigen::Vector3d& point) const;

  World world_;
  Eigen::Vector3d light_;
  struct Frame {
    Eigen::Matrix3d world_to_local;   // S^-1 R^T
    Eigen::Matrix3d normal_to_world;  // R S^-1
    double bound_radius;              // bounding sphere for early rejection
  };
  std::vector<Frame> frames_;
};

}  // namespace synth
