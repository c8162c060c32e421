// A body as the core sees it: a sphere with a mass (or none: immovable) and a state.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>

#include "collision_response/core/friction.h"

namespace collision_response::core {

/// A sphere taking part in impacts. Every vector is in one common frame (the caller's).
struct Body {
  std::string id;        ///< unique name; empty for an anonymous body in a single collision
  double mass = 1.0;     ///< kg, > 0; +infinity for an immovable body (wall, floor, paddle)
  double radius = 0.0;   ///< m, >= 0; 0 is a point mass
  std::string material;  ///< a name in the MaterialTable; empty: none
  Eigen::Vector3d position = Eigen::Vector3d::Zero();          ///< m, centre of mass
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          ///< m/s, of the centre of mass
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< rad/s
  Inertia inertia = Inertia::kSolid;  ///< with the spin effect: solid or hollow sphere
};

/// The immovable limit m -> infinity of the seed's slides.
constexpr double kImmovableMass = std::numeric_limits<double>::infinity();

/// 1/m, and exactly 0 for an immovable body (IEEE 1/inf == +0). Every formula uses inverse
/// masses so that m -> infinity is an ordinary value, not a special case.
inline double inverseMass(double mass) { return 1.0 / mass; }
inline double inverseMass(const Body& body) { return inverseMass(body.mass); }
inline bool isImmovable(const Body& body) { return inverseMass(body) == 0.0; }

}  // namespace collision_response::core
