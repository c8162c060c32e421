#include "collision_response/core/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <tuple>
#include <utility>
#include <variant>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/mass_properties.h"
#include "collision_response/core/validation.h"
#include "geometry/air_flight.h"
#include "geometry/finite_shapes.h"
#include "geometry/narrow_phase.h"
#include "monitor/shaped_motion.h"

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
  if (name == "drag") flag = &effects.drag;
  if (name == "magnus") flag = &effects.magnus;
  if (flag == nullptr) {
    return Error{field,
                 "unknown effect '" + name + "'; known: gravity, friction, spin, drag, magnus"};
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
  if (effects.drag) text += std::string(text.empty() ? "" : ", ") + "drag";
  if (effects.magnus) text += std::string(text.empty() ? "" : ", ") + "magnus";
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
  return materials.checkMaterial(name, field);
}

/// The air (drag and magnus effects): a density, an integrator tolerance the integrator can meet
/// (as the contact integrator's), and Magnus only with the spin that makes it.
Status checkAir(const Scene& scene, const std::string& prefix) {
  if (!(std::isfinite(scene.air_density) && scene.air_density >= 0)) {
    return Error{prefix + "/air_density",
                 "must be a finite density >= 0 (kg/m^3), got " + formatNumber(scene.air_density)};
  }
  if (!(scene.flight_integration_tolerance >= 1e-14 &&
        scene.flight_integration_tolerance <= 1e-3)) {
    return Error{
        prefix + "/flight_integration_tolerance",
        "must be in [1e-14, 1e-3], got " + formatNumber(scene.flight_integration_tolerance)};
  }
  if (scene.effects.air() && scene.air_density > kMaxAirDensity) {
    return Error{prefix + "/air_density",
                 "must be at most " + formatNumber(kMaxAirDensity) +
                     " kg/m^3 (denser than any liquid: a flight through it could not be "
                     "integrated), got " +
                     formatNumber(scene.air_density)};
  }
  if (scene.effects.magnus && !scene.effects.spin) {
    return Error{prefix + "/effects",
                 "names magnus without spin: the Magnus force comes from the spin, which only "
                 "the spin effect carries (add spin)"};
  }
  return Ok{};
}

/// A body's flight through air (drag, magnus) within what its integrator can follow: each air
/// factor rho C A / (2 m) at most kMaxAirFactor (a C_d or C_L of 1e300 froze the body, the
/// integrator stalled at its first step).
Status checkAirFactors(const Scene& scene, const BodySpec& body, const std::string& prefix,
                       std::size_t i) {
  if (!scene.effects.air()) return Ok{};
  const AirFactors air =
      bodyAirFactors(body, scene.air_density, scene.effects.drag, scene.effects.magnus);
  for (const auto& [factor, key, symbol] : {std::make_tuple(air.drag, "drag_coefficient", "C_d"),
                                            std::make_tuple(air.lift, "lift_coefficient", "C_L")}) {
    if (factor <= kMaxAirFactor) continue;
    const bool shaped = isShapedBody(body);
    char section[32];  // six figures: an area to read, not to parse
    std::snprintf(section, sizeof section, "%.6g", meanCrossSection(shapeOf(body)));
    const std::string area = shaped ? "mean cross-section " + std::string(section) + " m^2"
                                    : "radius " + formatNumber(body.radius) + " m";
    return Error{item(prefix, "bodies", i, key),
                 std::string("with air_density ") + formatNumber(scene.air_density) + " kg/m^3, " +
                     area + " and mass " + formatNumber(body.mass) + " kg, the air factor rho " +
                     symbol + (shaped ? " A" : " pi r^2") + " / (2 m) is " + formatNumber(factor) +
                     " 1/m, above " + formatNumber(kMaxAirFactor) +
                     " 1/m: a flight that stiff could not be integrated (it would stall, the "
                     "body held still); lower " +
                     symbol + " or the density, or raise the mass"};
  }
  return Ok{};
}

/// The scene-wide settings: frame, gravity, threshold, integrator tolerance, stepped clusters.
Status checkSettings(const Scene& scene, const std::string& prefix) {
  if (auto status = checkFrameId(scene.fixed_frame, prefix + "/fixed_frame"); !status) {
    return status;
  }
  if (auto status = checkFinite(scene.gravity, prefix + "/gravity"); !status) return status;
  if (auto status =
          checkRestitutionThreshold(scene.restitution_threshold, prefix + "/restitution_threshold");
      !status) {
    return status;
  }
  // The integrator of curved lasting contact (doc/model.md, "Lasting contact") can meet an error
  // per step down to about 1e-14 in doubles; above 1e-3 its contacts would open by millimetres.
  if (!(scene.contact_integration_tolerance >= 1e-14 &&
        scene.contact_integration_tolerance <= 1e-3)) {
    return Error{
        prefix + "/contact_integration_tolerance",
        "must be in [1e-14, 1e-3], got " + formatNumber(scene.contact_integration_tolerance)};
  }
  if (auto status = checkAir(scene, prefix); !status) return status;
  // Stepped clusters: a count of bodies (0: never), and a sub-step from 0.1 ms (far above the
  // resolution of a time line of ROS stamps, 2.4e-7 s in 2026) to a second.
  if (!(scene.stepped_cluster_min_bodies >= 0)) {
    return Error{prefix + "/stepped_cluster_min_bodies",
                 "must be 0 (never) or a number of bodies, got " +
                     std::to_string(scene.stepped_cluster_min_bodies)};
  }
  if (!(scene.stepped_cluster_time_step >= 1e-4 && scene.stepped_cluster_time_step <= 1.0)) {
    return Error{prefix + "/stepped_cluster_time_step",
                 "must be in [1e-4, 1] s, got " + formatNumber(scene.stepped_cluster_time_step)};
  }
  if (!(scene.exact_work_budget >= 0)) {
    return Error{prefix + "/exact_work_budget",
                 "must be 0 (no budget) or a number of solves, got " +
                     std::to_string(scene.exact_work_budget)};
  }
  return Ok{};
}

/// Each body: a unique id, mass, radius, material, and a finite initial state (its spin only with
/// the spin effect). `ids` collects the ids, shared with the obstacles.
Status checkBodies(const Scene& scene, const std::string& prefix, std::set<std::string>& ids) {
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
    const auto key = [&](const char* name) { return item(prefix, "bodies", i, name); };
    if (auto status = checkBodyShape(body, key); !status) return status;
    if (auto status =
            checkMaterial(scene.materials, body.material, item(prefix, "bodies", i, "material"));
        !status) {
      return status;
    }
    // Where the monitor resolves contacts (a stack placed past it once fell through its floor).
    if (auto status = checkResolvablePosition(body.position, item(prefix, "bodies", i, "position"));
        !status) {
      return status;
    }
    if (auto status = checkFinite(body.velocity, item(prefix, "bodies", i, "velocity")); !status) {
      return status;
    }
    if (auto status = checkAirCoefficient(body.drag_coefficient,
                                          item(prefix, "bodies", i, "drag_coefficient"));
        !status) {
      return status;
    }
    if (auto status = checkAirCoefficient(body.lift_coefficient,
                                          item(prefix, "bodies", i, "lift_coefficient"));
        !status) {
      return status;
    }
    if (auto status = checkAirFactors(scene, body, prefix, i); !status) return status;
    const std::string angular = item(prefix, "bodies", i, "angular_velocity");
    if (auto status = checkFinite(body.angular_velocity, angular); !status) return status;
    // A shaped body turns whatever the effects (its shape makes every impulse turn it): the
    // spin effect is a ball's.
    if (!scene.effects.spin && !isShapedBody(body) &&
        body.angular_velocity != Eigen::Vector3d::Zero()) {
      return Error{angular,
                   "is nonzero but the scene's effects do not include spin: without it the model "
                   "has no spin, so the value would be ignored (add spin to effects, or remove "
                   "the key)"};
    }
  }
  return Ok{};
}

/// The radius of the smallest sphere about an obstacle's position that holds it (0: a plane, a
/// point).
double reachOf(const Shape& shape) {
  if (const auto* sphere = std::get_if<Sphere>(&shape)) return sphere->radius;
  if (const auto* box = std::get_if<Cuboid>(&shape)) return boundingRadius(*box);
  if (const auto* cylinder = std::get_if<Cylinder>(&shape)) return boundingRadius(*cylinder);
  if (const auto* capsule = std::get_if<Capsule>(&shape)) return boundingRadius(*capsule);
  if (const auto* mesh = std::get_if<Mesh>(&shape)) return boundingRadius(*mesh);
  return 0.0;
}

/// An obstacle's numbers where the monitor resolves its contacts, as a body's position is
/// checked (kMaxResolvedCoordinate): a plane's offset, every extent, and the position.
template <class Field>
Status checkResolvableObstacle(const ObstacleSpec& obstacle, const Field& field) {
  if (obstacle.shape == ObstacleShape::kPlane) {
    return checkResolvableLength(obstacle.offset, field("offset"));
  }
  if (obstacle.shape == ObstacleShape::kBox) {
    for (int axis = 0; axis < 3; ++axis) {
      if (auto status = checkResolvableLength(obstacle.size[axis], field("size")); !status) {
        return status;
      }
    }
  }
  if (obstacle.shape != ObstacleShape::kMesh) {
    if (auto status = checkResolvableLength(obstacle.radius, field("radius")); !status) {
      return status;
    }
    if (auto status = checkResolvableLength(obstacle.length, field("length")); !status) {
      return status;
    }
  }
  return checkResolvablePosition(obstacle.position, field("position"));
}

/// Each obstacle: an id unique among bodies and obstacles, a material, a frame, and its shape's
/// numbers (a plane's nonzero normal and offset, a sphere's centre and radius).
Status checkObstacles(const Scene& scene, const std::string& prefix, std::set<std::string>& ids) {
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
    if (!obstacle.frame.empty()) {
      if (auto status = checkFrameId(obstacle.frame, item(prefix, "obstacles", i, "frame"));
          !status) {
        return status;
      }
    }
    const auto field = [&](const char* key) { return item(prefix, "obstacles", i, key); };
    if (auto status = checkShape(shapeOf(obstacle), field); !status) return status;
    if (auto status = checkResolvableObstacle(obstacle, field); !status) return status;
  }
  return Ok{};
}

/// Every pair of participants that can meet has a coefficient of restitution; the first pair
/// that has none is named, in the order a check of every pair would meet it.
Status checkEveryPairHasRestitution(const Scene& scene, const std::string& prefix) {
  // Every pair that can meet needs a coefficient of restitution. The coefficient depends on the
  // two materials only, so each pair of distinct materials is checked once, at the first body
  // (in the scene's order) that makes it: linear in the bodies, where a check of every pair of
  // bodies grew with their square (minutes of start-up for 30,000 bodies).
  std::map<std::string, std::size_t> first_body_of;  // material -> first body made of it
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    first_body_of.emplace(scene.bodies[i].material, i);
  }
  // material -> the first participant made of it, numbered bodies first, then obstacles.
  std::map<std::string, std::size_t> others;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) others.emplace(scene.bodies[i].material, i);
  for (std::size_t i = 0; i < scene.obstacles.size(); ++i) {
    others.emplace(scene.obstacles[i].material, scene.bodies.size() + i);
  }
  // The first failing pair in the order a check of every pair would meet it: by body, then by
  // the other participant.
  std::optional<std::pair<std::pair<std::size_t, std::size_t>, Error>> first_failure;
  for (const auto& [material, body] : first_body_of) {
    for (const auto& [other_material, other] : others) {
      const auto value = scene.materials.restitution(material, other_material);
      if (value) continue;
      // Two bodies: met first at the earlier of the two, against the later one.
      const bool other_is_body = other < scene.bodies.size();
      const std::size_t at_body = other_is_body ? std::min(body, other) : body;
      const std::size_t against = other_is_body ? std::max(body, other) : other;
      const auto where = std::make_pair(at_body, against);
      if (first_failure && first_failure->first <= where) continue;
      const std::string& against_id = against < scene.bodies.size()
                                          ? scene.bodies[against].id
                                          : scene.obstacles[against - scene.bodies.size()].id;
      first_failure.emplace(where, Error{item(prefix, "bodies", at_body, "material"),
                                         "no coefficient of restitution against '" + against_id +
                                             "' (" + value.error().reason + ")"});
    }
  }
  if (first_failure) return first_failure->second;
  return Ok{};
}

/// The shaped bodies the monitor moves (doc/model.md, "Shaped bodies in the monitor"): a box, a
/// cylinder, a capsule, a mesh (its convex hull), or a sphere given a tensor, of finite mass, by
/// gravity (and the air where the scene asks); an immovable shaped body and what principalBody
/// refuses (a cylinder's or capsule's tensor with products of inertia) are refused:
/// "not yet".
Status checkMonitoredShapes(const Scene& scene, const std::string& prefix) {
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& body = scene.bodies[i];
    if (!isShapedBody(body)) continue;
    if (!std::isfinite(body.mass)) {
      return Error{item(prefix, "bodies", i, "mass"),
                   "not yet: an immovable shaped body (body '" + body.id + "' is a " +
                       toString(body.shape) + "); give it a finite mass"};
    }
    // Its initial orientation is where the scene player's motion of it starts.
    if (auto status = checkOrientation(body.orientation, item(prefix, "bodies", i, "orientation"));
        !status) {
      return status;
    }
    if (auto principal = principalBody(body, "body"); !principal) {
      const std::string& field = principal.error().field;
      const std::string key = field.substr(field.find('.') + 1);
      return Error{item(prefix, "bodies", i, key), principal.error().reason};
    }
  }
  return Ok{};
}

}  // namespace

Status validateScene(const Scene& scene, const std::string& prefix, MovingShapes moving) {
  if (auto status = checkSettings(scene, prefix); !status) return status;
  std::set<std::string> ids;  // shared by bodies and obstacles
  if (auto status = checkBodies(scene, prefix, ids); !status) return status;
  if (auto status = checkObstacles(scene, prefix, ids); !status) return status;
  if (auto status = checkEveryPairHasRestitution(scene, prefix); !status) return status;
  if (moving == MovingShapes::kAny) return Ok{};
  if (moving == MovingShapes::kMonitored) return checkMonitoredShapes(scene, prefix);
  return checkOnlySpheresMove(scene, prefix);
}

std::vector<std::string> bodiesStartingInside(const Scene& scene) {
  const auto depth = [](double metres) {  // six figures: a depth to read, not to parse
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", metres);
    return std::string(text);
  };
  std::vector<std::string> warnings;
  for (const ObstacleSpec& obstacle : scene.obstacles) {
    if (!obstacle.frame.empty()) continue;
    const PlacedShape placed = placeFixed(obstacle);
    for (const BodySpec& body : scene.bodies) {
      if (body.shape != BodyShape::kSphere) continue;  // not a ball of its radius
      const ContactGeometry g = contactGeometry(body.position, body.radius, placed, 1e-9, [] {
        return Eigen::Vector3d(Eigen::Vector3d::Zero());
      });
      if (!(g.gap < -g.tolerance)) continue;
      warnings.push_back("body '" + body.id + "' at " + formatVector(body.position) + " starts " +
                         depth(-g.gap) + " m inside obstacle '" + obstacle.id + "'");
    }
  }
  return warnings;
}

std::vector<std::string> obstaclesBeyondResolution(const Scene& scene, const std::string& prefix) {
  std::vector<std::string> warnings;
  for (std::size_t i = 0; i < scene.obstacles.size(); ++i) {
    const ObstacleSpec& obstacle = scene.obstacles[i];
    if (obstacle.shape == ObstacleShape::kPlane) continue;
    const Status status = checkResolvableObstaclePosition(
        obstacle.position, reachOf(shapeOf(obstacle)), item(prefix, "obstacles", i, "position"));
    if (!status) {
      warnings.push_back(status.error().message() + ": a body touches obstacle '" + obstacle.id +
                         "' from as far as it is large (its contacts are coarse)");
    }
  }
  return warnings;
}

void normalizePlanes(Scene& scene) {
  for (ObstacleSpec& obstacle : scene.obstacles) setShape(obstacle, normalized(shapeOf(obstacle)));
}

}  // namespace collision_response::core
