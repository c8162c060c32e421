// One collision on request: validation, the choice of line of impact and restitution, and the
// impact itself. What ComputeCollision.srv serves, without ROS.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "collision_response/core/body.h"
#include "collision_response/core/expected.h"
#include "collision_response/core/impact.h"
#include "collision_response/core/materials.h"

namespace collision_response::core {

struct CollisionRequest {
  Body a;
  Body b;
  /// Line of impact from a to b, any length; zero: from a's centre to b's for two spheres, the
  /// narrow phase's for a sphere and a shaped body (from the sphere's centre to the shaped body's
  /// surface point nearest it), for two shaped bodies along their closest points (a to b).
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  /// m: where a shaped body (or both) is struck; none: found (a sphere and a shaped body: the
  /// narrow phase's; two shaped bodies: the middle of their closest points, refused where they
  /// overlap or meet flat, a face or an edge along a face or an edge). Two spheres refuse it.
  std::optional<Eigen::Vector3d> contact_point;
  /// Used when neither body names a material; must be 0 when both do.
  double restitution = 0.0;
  /// Coulomb mu, with the friction effect: used when neither body names a material; must be 0
  /// when both do (the pair's is used).
  double friction = 0.0;
  /// Effects to apply: "gravity" (accepted; an instantaneous impact does not feel it),
  /// "friction", "spin". Empty: the seed's frictionless, spinless model.
  std::vector<std::string> effects;
};

struct CollisionOutcome {
  ImpactResponse<double> impact;   ///< velocities after, impulse, energy lost
  Eigen::Vector3d line_of_impact;  ///< unit, a -> b
  Eigen::Vector3d contact_point = Eigen::Vector3d::Zero();  ///< m: given, or mid-gap
  /// m: where two shaped bodies' contact point was found, their surfaces' distance at the poses
  /// given (0 touching); none otherwise.
  std::optional<double> surface_gap;
  double restitution = 0.0;            ///< the coefficient used
  bool oblique = false;                ///< a velocity had a component across the line
  double friction_impulse = 0.0;       ///< N s, tangential (friction effect)
  bool sticking = false;               ///< friction stopped the slip
  Eigen::Vector3d angular_velocity_a;  ///< rad/s after (unchanged without spin)
  Eigen::Vector3d angular_velocity_b;  ///< rad/s after (unchanged without spin)
};

/// Validates every field of `request` (checkBody, checkBodyShape), picks the coefficient of
/// restitution and friction (the pair's from `materials` when both bodies name a material, the
/// request's when neither does; one without the other is an error), and resolves the impact.
/// Two balls (isBall): the normal impulse (resolveImpact), then with the friction effect Coulomb
/// friction (applyFriction), with the spin effect turning the bodies; the energy lost adds the
/// friction's work. Any other pair: one impact of two rigid bodies (resolveRigidImpact) at the
/// contact point, a shaped body by its lever arm and its world inverse inertia R I^-1 R^T (the
/// uniform solid of its shape, or its tensor), a ball by its radius along the normal and, with
/// the spin effect, its sphere's inertia (without it a ball does not turn); a shaped body turns
/// whatever the effects. Two shaped bodies without a contact point or normal: found from their
/// closest points at the poses given (convexDistance), refused where they overlap or meet flat.
Expected<CollisionOutcome> computeCollision(const CollisionRequest& request,
                                            const MaterialTable& materials);

}  // namespace collision_response::core
