#include "collision_response/core/body_shape.h"

#include <cmath>

#include "collision_response/core/validation.h"
#include "geometry/narrow_phase.h"

namespace collision_response::core {

Shape shapeOf(const BodySpec& body) {
  switch (body.shape) {
    case BodyShape::kSphere:
      return Sphere{Eigen::Vector3d::Zero(), body.radius};
    case BodyShape::kBox:
      return Cuboid{0.5 * body.size};
    case BodyShape::kCylinder:
      return Cylinder{body.radius, 0.5 * body.length};
    case BodyShape::kCapsule:
      return Capsule{body.radius, 0.5 * body.length};
    case BodyShape::kMesh:
      return Mesh{body.mesh};
  }
  return Sphere{Eigen::Vector3d::Zero(), body.radius};
}

Expected<BodyShape> parseBodyShape(const std::string& name, const std::string& field) {
  if (name == "sphere") return BodyShape::kSphere;
  if (name == "box") return BodyShape::kBox;
  if (name == "cylinder") return BodyShape::kCylinder;
  if (name == "capsule") return BodyShape::kCapsule;
  if (name == "mesh") return BodyShape::kMesh;
  return Error{field,
               "unknown body shape '" + name + "'; known: sphere, box, cylinder, capsule, mesh"};
}

const char* toString(BodyShape shape) {
  switch (shape) {
    case BodyShape::kSphere:
      return "sphere";
    case BodyShape::kBox:
      return "box";
    case BodyShape::kCylinder:
      return "cylinder";
    case BodyShape::kCapsule:
      return "capsule";
    case BodyShape::kMesh:
      return "mesh";
  }
  return "sphere";
}

Status checkBodyShape(const BodySpec& body, const std::function<std::string(const char*)>& field) {
  if (auto status = checkShape(shapeOf(body), field); !status) return status;
  if (body.inertia_tensor) {
    return checkInertiaTensor(*body.inertia_tensor, field("inertia"));
  }
  if (body.inertia == Inertia::kHollow && body.shape != BodyShape::kSphere) {
    return Error{field("inertia"), std::string("`hollow` is a sphere's (a thin shell); a ") +
                                       toString(body.shape) +
                                       " is a uniform solid (`solid`) or is given its tensor "
                                       "{ixx, iyy, izz, ixy, ixz, iyz}"};
  }
  // A sphere's inertia is its spin factor's (friction.h), a point's none; an immovable body is
  // turned by no inertia of its own.
  if (body.shape == BodyShape::kSphere || !std::isfinite(body.mass)) return Ok{};
  const auto properties =
      uniformMassProperties(shapeOf(body), body.mass, body.inertia,
                            field(body.shape == BodyShape::kMesh ? "resource" : "shape"));
  if (!properties) return properties.error();
  return Ok{};
}

Expected<MassProperties> bodyMassProperties(const BodySpec& body, const std::string& field) {
  auto properties = uniformMassProperties(shapeOf(body), body.mass, body.inertia, field);
  if (!properties || !body.inertia_tensor) return properties;
  properties.value().centre_of_mass = Eigen::Vector3d::Zero();
  properties.value().inertia = body.inertia_tensor->matrix();
  return properties;
}

BodySpec shapeSpecOf(const Body& body) {
  BodySpec spec;
  spec.id = body.id;
  spec.mass = body.mass;
  spec.radius = body.radius;
  spec.inertia = body.inertia;
  spec.shape = body.shape;
  spec.size = body.size;
  spec.length = body.length;
  spec.inertia_tensor = body.inertia_tensor;
  return spec;
}

namespace {

/// A number of `body` its shape does not have must be 0 (named `field`): nothing is ignored.
/// (Its field's name `prefix`.`key` is built only for the error: a ball's request, the common
/// one, builds none.)
Status unusedIsZero(bool is_zero, const Body& body, const std::string& prefix, const char* key,
                    const char* which) {
  if (is_zero) return Ok{};
  return Error{prefix + "." + key,
               std::string("must be 0: a ") + toString(body.shape) + " has no " + which +
                   " (a box has edges `size`; a cylinder and a capsule a `radius` and a "
                   "`length`; a sphere a `radius`)"};
}

}  // namespace

Status checkBodyShape(const Body& body, const std::string& prefix) {
  if (body.shape == BodyShape::kMesh) {
    return Error{prefix + ".shape",
                 "not yet: a mesh body in a single collision (no mesh resource is loaded here); "
                 "a box, cylinder, capsule or sphere is taken"};
  }
  const bool round = body.shape == BodyShape::kSphere || body.shape == BodyShape::kCylinder ||
                     body.shape == BodyShape::kCapsule;
  if (auto status = unusedIsZero(round || body.radius == 0.0, body, prefix, "radius", "radius");
      !status) {
    return status;
  }
  if (auto status = unusedIsZero(body.shape == BodyShape::kBox || body.size.isZero(0.0), body,
                                 prefix, "size", "edges (`size`)");
      !status) {
    return status;
  }
  if (auto status = unusedIsZero(body.shape == BodyShape::kCylinder ||
                                     body.shape == BodyShape::kCapsule || body.length == 0.0,
                                 body, prefix, "length", "length");
      !status) {
    return status;
  }
  if (body.inertia_tensor && body.inertia == Inertia::kHollow) {
    return Error{prefix + ".inertia",
                 "is `hollow` while " + prefix +
                     ".inertia_tensor is given: give one (the tensor says how the mass is spread)"};
  }
  const Eigen::Quaterniond& orientation = body.orientation;
  // A ball's radius and inertia are checkBody's; its orientation does not matter, and is checked
  // only where given (checkOrientation builds the field's name only for an error).
  if (isBall(body)) {
    if (orientation.coeffs().isZero(0.0) || isRotation(orientation)) return Ok{};
    return checkOrientation(orientation, prefix + ".orientation");
  }
  const auto field = [&](const char* key) {
    const std::string name = key;
    if (name == "inertia" && body.inertia_tensor) return prefix + ".inertia_tensor";
    return prefix + "." + name;
  };
  if (auto status = checkBodyShape(shapeSpecOf(body), field); !status) return status;
  if (orientation.coeffs().isZero(0.0)) {
    return Error{prefix + ".orientation",
                 std::string("is zero (not given): a ") + toString(body.shape) +
                     (body.shape == BodyShape::kSphere ? " given its tensor" : "") +
                     " needs its orientation, world from body ([0, 0, 0, 1] as [x, y, z, w]: not "
                     "turned)"};
  }
  if (isRotation(orientation)) return Ok{};
  return checkOrientation(orientation, prefix + ".orientation");
}

Status checkOnlySpheresMove(const Scene& scene, const std::string& prefix) {
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& body = scene.bodies[i];
    const std::string where = prefix + "/bodies[" + std::to_string(i) + "]/";
    if (body.shape != BodyShape::kSphere) {
      return Error{where + "shape", std::string("not yet: only spheres move (body '") + body.id +
                                        "' is a " + toString(body.shape) +
                                        "; a ball's prediction holds the other bodies as spheres)"};
    }
    if (body.inertia_tensor) {
      return Error{where + "inertia", "not yet: only spheres of uniform mass move (body '" +
                                          body.id +
                                          "' is given an inertia tensor; use `solid` or `hollow`)"};
    }
  }
  return Ok{};
}

}  // namespace collision_response::core
