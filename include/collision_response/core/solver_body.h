// The body and the contact point every solver works on (issue 42, build step 1): one struct
// each for the joint impulse solve (simultaneous.h), friction at an impact (friction.h), the
// contact forces and inelastic impacts (solver/contact_forces.h) and the stepped sub-step
// (solver/stepped_contact.h), each of which adds only what is its own.
#pragma once

#include <Eigen/Core>
#include <cstddef>

namespace collision_response::core {

/// Which of SolverBody's two descriptions of its inverse inertia holds.
enum class InverseInertiaKind {
  /// I^-1 = 1 / (k m r^2) times the identity (a sphere): read from spin_factor 1/k and radius,
  /// from which every ball formula of the solvers takes it.
  kIsotropic,
  /// I^-1 in the common frame (inverse_inertia), for the shaped bodies to come: read by the
  /// turn, the slip and the tangential inverse mass (src/core/solver/impulse_response.h); no
  /// body has one yet.
  kTensor,
};

/// A body as a solver sees it: inverse mass, inverse inertia, velocity and angular velocity.
/// An obstacle or an immovable body has inverse mass 0 and moves on at its velocity.
struct SolverBody {
  double inverse_mass = 0.0;                                   ///< 1/kg; 0: immovable
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          ///< m/s
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< rad/s
  InverseInertiaKind inertia_kind = InverseInertiaKind::kIsotropic;
  /// kIsotropic: 1/k of I = k m r^2 (5/2 solid, 3/2 hollow: friction.h, spinFactor); 0: does not
  /// turn (immovable, a point, no spin effect). Kept as a factor, not as 1/I = w / (k r^2): that
  /// underflows for large bodies (r = 1e145 m) while every quantity friction needs, w/k and
  /// (w/k)/r, does not.
  double spin_factor = 0.0;
  double radius = 0.0;  ///< m, kIsotropic; 0 for a plane
  /// kTensor: I^-1 about the centre of mass, 1/(kg m^2), in the common frame (R I_body^-1 R^T).
  Eigen::Matrix3d inverse_inertia = Eigen::Matrix3d::Zero();
};

/// A contact between bodies `a` and `b` (indices into the solve's bodies), as the narrow phase
/// gives it (ContactGeometry: normal, point, lever arms).
struct ContactPoint {
  std::size_t a = 0;
  std::size_t b = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  ///< unit, a -> b
  /// A point of the contact: the middle of the gap along the normal (ContactGeometry::point).
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  /// r_a, r_b, m: from each body's centre of mass (a shape's pose origin) to its own surface
  /// point at the contact; a ball's is R n (its b side -R n). Carried for the shaped bodies to
  /// come: the ball formulas compute with the radius and the normal, as before.
  Eigen::Vector3d lever_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d lever_b = Eigen::Vector3d::Zero();
};

}  // namespace collision_response::core
