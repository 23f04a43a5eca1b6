#include "synth/world.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>

namespace synth {

const char* shape_name(Shape s) {
  switch (s) {
    case Shape::kSphere:
      return "sphere";
    case Shape::kBox:
      return "box";
    case Shape::kCylinder:
      return "cylinder";
    case Shape::kCone:
      return "cone";
  }
  return "?";
}

namespace {

Eigen::Vector3d vector3(const nlohmann::json& j, const char* field) {
  const nlohmann::json& v = j.at(field);
  if (!v.is_array() || v.size() != 3)
    throw std::invalid_argument(std::string("surfaces: ") + field + " is not three numbers");
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

}  // namespace

nlohmann::json world_to_json(const World& world) {
  const auto array = [](const Eigen::Vector3d& v) { return nlohmann::json{v.x(), v.y(), v.z()}; };
  nlohmann::json objects = nlohmann::json::array();
  for (const SceneObject& o : world.objects)
    objects.push_back({{"id", o.id},
                       {"name", o.name},
                       {"shape", shape_name(o.shape)},
                       {"position", array(o.position)},
                       {"half_size", array(o.half_size)},
                       {"yaw", o.yaw},
                       {"opacity", o.material.opacity}});
  return {{"objects", objects},
          {"ground_y", 0.0},
          {"enclosure_radius", world.enclosure_radius},
          {"look_at", array(world.look_at)},
          {"light_direction", array(world.light_direction)}};
}

World world_from_json(const nlohmann::json& j) {
  try {
    World world;
    world.enclosure_radius = j.at("enclosure_radius").get<double>();
    world.look_at = vector3(j, "look_at");
    world.light_direction = vector3(j, "light_direction");
    for (const nlohmann::json& jo : j.at("objects")) {
      SceneObject o;
      o.id = jo.at("id").get<int>();
      o.name = jo.at("name").get<std::string>();
      const std::string shape = jo.at("shape").get<std::string>();
      bool known = false;
      for (Shape s : {Shape::kSphere, Shape::kBox, Shape::kCylinder, Shape::kCone})
        if (shape == shape_name(s)) o.shape = s, known = true;
      if (!known) throw std::invalid_argument("surfaces: unknown shape '" + shape + "'");
      o.position = vector3(jo, "position");
      o.half_size = vector3(jo, "half_size");
      o.yaw = jo.at("yaw").get<double>();
      o.material.opacity = jo.at("opacity").get<double>();
      world.objects.push_back(o);
    }
    return world;
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("surfaces: ") + e.what());
  }
}

namespace {

SceneObject make(int id, const char* name, Shape shape, Eigen::Vector3d pos, Eigen::Vector3d half,
                 double yaw, Material m, const char* hard_case = "") {
  SceneObject o;
  o.id = id;
  o.name = name;
  o.shape = shape;
  o.position = pos;
  o.half_size = half;
  o.yaw = yaw;
  o.material = m;
  o.hard_case = hard_case;
  return o;
}

Material mat(Eigen::Vector3d base, Eigen::Vector3d accent, Pattern p, double freq,
             double opacity = 1.0) {
  return Material{base, accent, p, freq, opacity};
}

}  // namespace

World default_world(uint64_t seed) {
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // Colours vary a little with the seed; hues stay those the names promise.
  auto tint = [&](Eigen::Vector3d c) {
    for (int k = 0; k < 3; ++k) c[k] = std::clamp(c[k] + 0.04 * u(rng), 0.0, 1.0);
    return c;
  };
  using V = Eigen::Vector3d;
  World L;
  L.texture_offset = V(100 * u(rng), 100 * u(rng), 100 * u(rng));
  const double crate_yaw = 0.4;
  const V crate_pos(0.55, 0.30, -0.50);
  // The yellow crate sits flush against the blue crate's +x face (touching).
  const V crate_x_axis(std::cos(crate_yaw), 0, -std::sin(crate_yaw));
  const V small_crate_pos = crate_pos + 0.52 * crate_x_axis + V(0, -0.08, 0) +
                            0.05 * V(std::sin(crate_yaw), 0, std::cos(crate_yaw));

  L.objects = {
      make(1, "red ball", Shape::kSphere, V(-0.9, 0.32, 0.4), V(0.32, 0.32, 0.32), 0,
           mat(tint(V(0.75, 0.08, 0.06)), tint(V(0.95, 0.55, 0.35)), Pattern::kSpots, 9)),
      make(2, "blue crate", Shape::kBox, crate_pos, V(0.3, 0.3, 0.3), crate_yaw,
           mat(tint(V(0.10, 0.20, 0.70)), tint(V(0.55, 0.70, 0.95)), Pattern::kChecker, 7),
           "touching"),
      make(3, "yellow crate", Shape::kBox, small_crate_pos, V(0.22, 0.22, 0.22), crate_yaw,
           mat(tint(V(0.90, 0.78, 0.10)), tint(V(0.60, 0.45, 0.05)), Pattern::kMottled, 10),
           "touching"),
      make(4, "green can", Shape::kCylinder, V(0.05, 0.35, 0.8), V(0.2, 0.35, 0.2), 0.3,
           mat(tint(V(0.10, 0.60, 0.15)), tint(V(0.85, 0.95, 0.75)), Pattern::kStripes, 9)),
      make(5, "purple cone", Shape::kCone, V(-0.25, 0.4, -0.75), V(0.3, 0.4, 0.3), 0,
           mat(tint(V(0.45, 0.12, 0.55)), tint(V(0.85, 0.60, 0.90)), Pattern::kStripes, 8)),
      make(6, "thin pole", Shape::kCylinder, V(1.0, 0.6, 0.05), V(0.025, 0.6, 0.025), 0,
           mat(tint(V(0.95, 0.45, 0.05)), tint(V(0.30, 0.12, 0.02)), Pattern::kStripes, 12),
           "thin"),
      make(7, "small marble", Shape::kSphere, V(-0.4, 0.07, 0.55), V(0.07, 0.07, 0.07), 0,
           mat(tint(V(0.95, 0.75, 0.85)), tint(V(0.55, 0.15, 0.40)), Pattern::kMottled, 30),
           "small"),
      make(8, "dark vase", Shape::kSphere, V(-1.05, 0.35, -0.45), V(0.2, 0.35, 0.2), 0,
           mat(V(0.05, 0.05, 0.06), V(0.11, 0.10, 0.10), Pattern::kMottled, 10),
           "dark object in a dark region"),
      make(9, "glass sphere", Shape::kSphere, V(0.6, 0.28, 0.55), V(0.28, 0.28, 0.28), 0,
           mat(tint(V(0.55, 0.90, 0.95)), tint(V(0.85, 0.98, 1.0)), Pattern::kMottled, 5, 0.4),
           "semi-transparent"),
      make(10, "brown book", Shape::kBox, V(-0.2, 0.06, -0.05), V(0.25, 0.06, 0.18), -0.5,
           mat(tint(V(0.45, 0.25, 0.10)), tint(V(0.80, 0.65, 0.45)), Pattern::kStripes, 14)),
  };
  L.look_at = V(0.0, 0.3, 0.0);
  L.dark_region_center = Eigen::Vector2d(-1.05, -0.45);
  L.dark_region_radius = 0.55;
  // The dome sector seen behind the vase from the opposite side of the orbit.
  L.dark_azimuth = std::atan2(-0.45, -1.05);
  L.dark_azimuth_halfwidth = 0.45;
  return L;
}

}  // namespace synth
