// A scene body's shape and mass (issue 42, build step 2): its shape in its own frame, the checks
// of its shape and inertia keys, and its mass properties. The monitor moves spheres, boxes,
// cylinders, capsules and meshes (their convex hulls); what it does not move yet is refused by
// name (validateScene), so that nothing silently becomes a ball.
#pragma once

#include <functional>
#include <string>

#include "collision_response/core/body.h"
#include "collision_response/core/expected.h"
#include "collision_response/core/mass_properties.h"
#include "collision_response/core/scene.h"
#include "collision_response/core/shape.h"

namespace collision_response::core {

/// Whether a body moves as a rigid body of its shape rather than as a ball: any shape but a
/// sphere, or a sphere given a tensor. Such a body turns whatever the effects (the spin effect
/// is a ball's).
inline bool isShapedBody(const BodySpec& body) {
  return body.shape != BodyShape::kSphere || body.inertia_tensor.has_value();
}

/// The body's shape in its own frame: a sphere about the origin, a box, a cylinder or a capsule
/// (half its `size` or `length`), or its mesh (whose convex hull the body is).
Shape shapeOf(const BodySpec& body);

/// `sphere` | `box` | `cylinder` | `capsule` | `mesh`; anything else an error naming `field`.
Expected<BodyShape> parseBodyShape(const std::string& name, const std::string& field);
const char* toString(BodyShape shape);

/// A body's shape and inertia, named as its scene keys (`field("size")`, `field("inertia")`
/// ...): the shape's numbers as an obstacle's (a box's edges, a cylinder's radius and length
/// > 0, a capsule's length >= 0, a mesh loaded); `hollow` only for a sphere (a thin shell); a
/// given tensor (checkInertiaTensor, its entries `inertia.ixx` ...); and for a movable body
/// without a tensor, the uniform solid's mass properties (a mesh whose hull has no volume, a
/// body whose moments are beyond the range of double).
Status checkBodyShape(const BodySpec& body, const std::function<std::string(const char*)>& field);

/// The body's mass properties in its own frame: the uniform solid of its shape
/// (uniformMassProperties; a mesh's centre of mass is its hull's centroid), or with a given
/// tensor, the shape's volume, the tensor, and the centre of mass at the body's origin. For a
/// movable body (finite mass) of nonzero size that checkBodyShape accepted.
Expected<MassProperties> bodyMassProperties(const BodySpec& body, const std::string& field);

/// A single collision's body (Body, body.h) as a scene body of its shape, mass and inertia, for
/// checkBodyShape, shapeOf and the mass properties.
BodySpec shapeSpecOf(const Body& body);

/// A single collision's body: its shape, inertia and orientation, named as ComputeCollision's
/// fields under `prefix` ("a.shape", "a.size", "a.inertia_tensor.ixy", "a.orientation"): a mesh
/// is refused (not yet in a single collision: no resource is loaded there); a number another
/// shape has and this one has not must be 0 (a box's radius, a sphere's size, ...), so that no
/// value is silently ignored; the shape's numbers and the inertia as checkBodyShape has them (a
/// tensor given and `hollow` both is refused); the orientation all zero (not given) only for a
/// ball (isBall), otherwise checkOrientation's.
Status checkBodyShape(const Body& body, const std::string& prefix);

/// Where only spheres may move (a ball's prediction holds the scene's other bodies as spheres:
/// MovingShapes::kSpheresOnly), the first body that is not a sphere, or a sphere given a tensor,
/// is refused, naming its `shape` (or `inertia`) key under `prefix` and the body: "not yet: only
/// spheres move".
Status checkOnlySpheresMove(const Scene& scene, const std::string& prefix);

}  // namespace collision_response::core
