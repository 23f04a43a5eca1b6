#pragma once
// The synthetic test-bed scene: named objects of several shapes on a textured
// ground plane inside a textured dome, with the hard cases that cause label
// contamination in the paper (a dark object in a dark region, a thin object, a
// small object, a semi-transparent object, objects that touch in view).

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace synth {

enum class Shape { kSphere, kBox, kCylinder, kCone };
const char* shape_name(Shape s);

// Solid (3D) textures, so a surface point has the same colour in every view
// and SIFT finds matches. Every pattern mixes base and accent colours.
enum class Pattern { kMottled, kStripes, kSpots, kChecker };

struct Material {
  Eigen::Vector3d base{0.5, 0.5, 0.5};
  Eigen::Vector3d accent{0.8, 0.8, 0.8};
  Pattern pattern = Pattern::kMottled;
  double frequency = 8.0;  // texture features per world unit
  double opacity = 1.0;    // < 1: semi-transparent, light passes through
};

// A canonical shape (unit sphere, cube [-1,1]^3, cylinder r=1 |y|<=1, cone with
// base r=1 at y=-1 and apex at y=+1) scaled by half_size, turned by yaw about
// the world up axis (y), and moved to position.
struct SceneObject {
  int id = 0;  // 1..C, the instance ID in every ID map
  std::string name;
  Shape shape = Shape::kSphere;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d half_size = Eigen::Vector3d::Ones();
  double yaw = 0;
  Material material;
  std::string hard_case;  // empty, or which contamination case it exercises
};

struct World {
  std::vector<SceneObject> objects;
  Eigen::Vector3d light_direction{0.4, 1.0, 0.3};  // towards the light
  double ambient = 0.35;
  // Glossy objects: Blinn-Phong highlights of this strength (0: Lambertian,
  // every colour view-independent). The ground and the dome stay matte.
  double specular = 0;
  double shininess = 32;
  double enclosure_radius = 7.0;  // the dome around everything
  Eigen::Vector3d look_at{0.0, 0.3, 0.0};
  // A dark region (on the ground and the dome behind it) around the dark object.
  Eigen::Vector2d dark_region_center{0, 0};  // x, z
  double dark_region_radius = 0;
  double dark_azimuth = 0, dark_azimuth_halfwidth = 0;       // dome sector, radians
  Eigen::Vector3d texture_offset = Eigen::Vector3d::Zero();  // varies the textures by seed
};

// The surfaces of a layout as surfaces.json holds them: every object's
// shape, pose, size and opacity; the ground plane (y = 0) and the dome's
// radius. Textures are left out: they are not needed to say where a surface is.
nlohmann::json world_to_json(const World& world);
// The inverse (textures default). Throws std::invalid_argument naming the
// field that is missing or wrong.
World world_from_json(const nlohmann::json& surfaces);

// The default scene of ten objects. The seed varies textures and colours, not
// the placement (objects must not intersect, and the touching pair must touch).
World default_world(uint64_t seed);

}  // namespace synth
