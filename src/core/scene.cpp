#include "collision_response/core/scene.h"

#include <cmath>
#include <set>

#include "collision_response/core/validation.h"

namespace collision_response::core {

Expected<Detection> parseDetection(const std::string& name, const std::string& field) {
  if (name == "continuous") return Detection::kContinuous;
  if (name == "discrete") return Detection::kDiscrete;
  return Error{field, "unknown detection '" + name + "'; known: continuous, discrete"};
}

const char* toString(Detection detection) {
  return detection == Detection::kContinuous ? "continuous" : "discrete";
}

Status addEffect(const std::string& name, const std::string& field, Effects& effects) {
  bool* flag = nullptr;
  if (name == "gravity") flag = &effects.gravity;
  if (name == "friction") flag = &effects.friction;
  if (name == "spin") flag = &effects.spin;
  if (flag == nullptr) {
    return Error{field, "unknown effect '" + name + "'; known: gravity, friction, spin"};
  }
  if (*flag) return Error{field, "effect '" + name + "' is listed twice"};
  *flag = true;
  return Ok{};
}

std::string toString(const Effects& effects) {
  std::string text;
  if (effects.gravity) text += "gravity";
  if (effects.friction) text += std::string(text.empty() ? "" : ", ") + "friction";
  if (effects.spin) text += std::string(text.empty() ? "" : ", ") + "spin";
  return text.empty() ? "none (the seed's model)" : text;
}

namespace {

std::string item(const std::string& prefix, const std::string& list, std::size_t index,
                 const std::string& key) {
  return prefix + "/" + list + "[" + std::to_string(index) + "]/" + key;
}

Status checkMaterial(const MaterialTable& materials, const std::string& name,
                     const std::string& field) {
  if (name.empty()) return Error{field, "is required (a material name)"};
  if (!materials.contains(name)) {
    std::string known;
    for (const std::string& entry : materials.names()) known += (known.empty() ? "" : ", ") + entry;
    return Error{field, "unknown material '" + name + "'; known: " + known};
  }
  return Ok{};
}

}  // namespace

Status validateScene(const Scene& scene, const std::string& prefix) {
  if (auto status = checkName(scene.fixed_frame, prefix + "/fixed_frame"); !status) return status;
  if (auto status = checkFinite(scene.gravity, prefix + "/gravity"); !status) return status;
  if (!std::isfinite(scene.restitution_threshold) || scene.restitution_threshold < 0.0) {
    return Error{prefix + "/restitution_threshold", "must be a finite number >= 0 m/s, got " +
                                                        formatNumber(scene.restitution_threshold)};
  }
  std::set<std::string> ids;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& body = scene.bodies[i];
    if (auto status = checkName(body.id, item(prefix, "bodies", i, "id")); !status) return status;
    if (!ids.insert(body.id).second) {
      return Error{item(prefix, "bodies", i, "id"), "duplicate id '" + body.id + "'"};
    }
    if (auto status = checkMass(body.mass, item(prefix, "bodies", i, "mass")); !status) {
      return status;
    }
    if (auto status = checkRadius(body.radius, item(prefix, "bodies", i, "radius")); !status) {
      return status;
    }
    if (auto status =
            checkMaterial(scene.materials, body.material, item(prefix, "bodies", i, "material"));
        !status) {
      return status;
    }
    if (auto status = checkFinite(body.position, item(prefix, "bodies", i, "position")); !status) {
      return status;
    }
    if (auto status = checkFinite(body.velocity, item(prefix, "bodies", i, "velocity")); !status) {
      return status;
    }
  }
  for (std::size_t i = 0; i < scene.obstacles.size(); ++i) {
    const ObstacleSpec& obstacle = scene.obstacles[i];
    if (auto status = checkName(obstacle.id, item(prefix, "obstacles", i, "id")); !status) {
      return status;
    }
    if (!ids.insert(obstacle.id).second) {
      return Error{item(prefix, "obstacles", i, "id"),
                   "duplicate id '" + obstacle.id + "' (ids are shared by bodies and obstacles)"};
    }
    if (auto status = checkMaterial(scene.materials, obstacle.material,
                                    item(prefix, "obstacles", i, "material"));
        !status) {
      return status;
    }
    if (obstacle.shape == ObstacleShape::kPlane) {
      if (auto status = checkFinite(obstacle.normal, item(prefix, "obstacles", i, "normal"));
          !status) {
        return status;
      }
      if (obstacle.normal == Eigen::Vector3d::Zero()) {
        return Error{item(prefix, "obstacles", i, "normal"), "must not be zero"};
      }
      if (auto status = checkFinite(obstacle.offset, item(prefix, "obstacles", i, "offset"));
          !status) {
        return status;
      }
    } else {
      if (auto status = checkFinite(obstacle.position, item(prefix, "obstacles", i, "position"));
          !status) {
        return status;
      }
      if (auto status = checkRadius(obstacle.radius, item(prefix, "obstacles", i, "radius"));
          !status) {
        return status;
      }
    }
  }
  // Every pair that can meet needs a coefficient of restitution.
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const auto check_pair = [&](const std::string& other_material, const std::string& other_id) {
      const auto value = scene.materials.restitution(scene.bodies[i].material, other_material);
      if (value) return Status(Ok{});
      return Status(Error{item(prefix, "bodies", i, "material"),
                          "no coefficient of restitution against '" + other_id + "' (" +
                              value.error().reason + ")"});
    };
    for (std::size_t j = i; j < scene.bodies.size(); ++j) {
      if (auto status = check_pair(scene.bodies[j].material, scene.bodies[j].id); !status) {
        return status;
      }
    }
    for (const ObstacleSpec& obstacle : scene.obstacles) {
      if (auto status = check_pair(obstacle.material, obstacle.id); !status) return status;
    }
  }
  return Ok{};
}

}  // namespace collision_response::core
