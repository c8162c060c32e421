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

Status checkOnlySpheresMove(const Scene& scene, const std::string& prefix) {
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& body = scene.bodies[i];
    const std::string where = prefix + "/bodies[" + std::to_string(i) + "]/";
    if (body.shape != BodyShape::kSphere) {
      return Error{where + "shape",
                   std::string("not yet: only spheres move (body '") + body.id + "' is a " +
                       toString(body.shape) +
                       "; its shape and mass are checked, and the model takes them with issue "
                       "42's next steps)"};
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
