// A body as the core sees it in a single collision: a ball with a mass (or none: immovable) and
// a state, or a shaped body (issue 42: a box, cylinder or capsule, or a sphere given its tensor).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <optional>
#include <string>

#include "collision_response/core/friction.h"
#include "collision_response/core/mass_properties.h"
#include "collision_response/core/scene.h"

namespace collision_response::core {

/// A body taking part in one collision. Every vector is in one common frame (the caller's).
struct Body {
  std::string id;        ///< unique name; empty for an anonymous body in a single collision
  double mass = 1.0;     ///< kg, > 0; +infinity for an immovable body (wall, floor, paddle)
  double radius = 0.0;   ///< m, >= 0; 0 is a point mass
  std::string material;  ///< a name in the MaterialTable; empty: none
  Eigen::Vector3d position = Eigen::Vector3d::Zero();          ///< m, centre of mass
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          ///< m/s, of the centre of mass
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< rad/s
  Inertia inertia = Inertia::kSolid;  ///< with the spin effect: solid or hollow sphere
  /// Its shape, as a scene body's (BodySpec): a sphere of `radius`; a box of edges `size`; a
  /// cylinder or a capsule of `radius` and `length` along its z. (A mesh is not taken yet.)
  BodyShape shape = BodyShape::kSphere;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  ///< box: edge lengths, m; else zero
  double length = 0.0;                             ///< cylinder, capsule: m; else 0
  /// World (the common frame) from the body's frame, of unit length (checkOrientation's
  /// tolerance; normalised where used). All zero: not given, which only a ball may be (a sphere
  /// without a tensor, whose orientation does not matter).
  Eigen::Quaterniond orientation = Eigen::Quaterniond(0.0, 0.0, 0.0, 0.0);
  /// About the centre of mass in the body's frame; none: the uniform solid of its shape (a
  /// sphere's from `inertia`).
  std::optional<InertiaTensor> inertia_tensor;
};

/// A ball: a sphere of uniform mass (solid or hollow), answered by the balls' formulas. Every
/// other body (a box, cylinder or capsule, or a sphere given its tensor) turns as a rigid body
/// at its contact point (issue 42).
inline bool isBall(const Body& body) {
  return body.shape == BodyShape::kSphere && !body.inertia_tensor.has_value();
}

/// The immovable limit m -> infinity of the seed's slides.
constexpr double kImmovableMass = std::numeric_limits<double>::infinity();

/// 1/m, and exactly 0 for an immovable body (IEEE 1/inf == +0). Every formula uses inverse
/// masses so that m -> infinity is an ordinary value, not a special case.
inline double inverseMass(double mass) { return 1.0 / mass; }
inline double inverseMass(const Body& body) { return inverseMass(body.mass); }
inline bool isImmovable(const Body& body) { return inverseMass(body) == 0.0; }

}  // namespace collision_response::core
