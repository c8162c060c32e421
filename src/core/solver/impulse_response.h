// How a solver body answers an impulse at a contact point, in one place for the solvers of
// friction at an impact (cluster_solver.cpp), of a cluster's friction (cluster_solver.cpp) and
// of a stepped sub-step's (stepped_friction.cpp), issue 42's build step 1: the turn an impulse
// gives a body, the slip at a contact and the tangential inverse mass. A ball (kIsotropic) keeps
// its formulas word for word, with its radius and the normal, so that its bits do not move; a
// body with an inertia tensor (kTensor) takes the general ones, with the contact's lever arms.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "collision_response/core/solver_body.h"
#include "solver/effective_mass.h"

namespace collision_response::core {

/// What a solve's bodies may be: any (kAny: each function below asks each body its kind), or
/// balls only (kBalls: each takes the ball's formula without asking), which a solver tells once
/// for its bodies (allBalls) and runs with, so that the balls' sweeps pay nothing for the
/// shaped bodies.
enum class SolveBodies { kAny, kBalls };

/// Every body of `bodies` is a ball (kIsotropic).
template <class Body>
bool allBalls(const std::vector<Body>& bodies) {
  for (const SolverBody& body : bodies) {
    if (body.inertia_kind != InverseInertiaKind::kIsotropic) return false;
  }
  return true;
}

/// An impulse turns `body`: a ball with a spin factor (the spin effect on a movable ball; a
/// point's is 0: spinFactor, friction.h), a body with a nonzero inverse inertia tensor.
template <SolveBodies kBodies = SolveBodies::kAny>
inline bool turns(const SolverBody& body) {
  if (kBodies == SolveBodies::kBalls || body.inertia_kind == InverseInertiaKind::kIsotropic) {
    return body.spin_factor != 0.0;
  }
  return !body.inverse_inertia.isZero(0.0);
}

// The branches of a body given by its tensor, out of line (cluster_solver.cpp), so that the
// balls' branches stay small enough to be inlined where the solvers sweep and integrate.

/// I^-1 (r x J) of a body given by its tensor (turnOf's general branch); `Scalar` double or
/// long double.
template <class Scalar>
Eigen::Matrix<Scalar, 3, 1> tensorTurnOf(const SolverBody& body, const Eigen::Vector3d& lever,
                                         const Eigen::Matrix<Scalar, 3, 1>& impulse);
extern template Eigen::Vector3d tensorTurnOf<double>(const SolverBody&, const Eigen::Vector3d&,
                                                     const Eigen::Vector3d&);
extern template Eigen::Matrix<long double, 3, 1> tensorTurnOf<long double>(
    const SolverBody&, const Eigen::Vector3d&, const Eigen::Matrix<long double, 3, 1>&);

/// (w_b x r_b) - (w_a x r_a) where a side is given by its tensor (slipAt's general branch).
Eigen::Vector3d turningSlip(const SolverBody& a, const SolverBody& b, const ContactPoint& contact);

/// t.K.t where a side is given by its tensor (tangentialInverseMass's general branch).
double tensorTangentialInverseMass(const SolverBody& a, const SolverBody& b,
                                   const ContactPoint& contact, const Eigen::Vector3d& direction);

/// The change of `body`'s angular velocity from `impulse` on it at its contact point:
/// I^-1 (r x J), r its lever arm `lever()` (called only for a body given by its tensor). A
/// ball's r is R `outward` (the unit normal n on side a, -n on side b) and I^-1 = w / (k R^2)
/// (1/k its spin factor): (w (1/k) / R) (outward x J), divided by R once, as the solvers of
/// balls always have (`Scalar`: their precision, double or the contact group's long double).
/// Only for a body that turns (turns()).
template <class Scalar, SolveBodies kBodies = SolveBodies::kAny, class Lever>
inline Eigen::Matrix<Scalar, 3, 1> turnOf(const SolverBody& body,
                                          const Eigen::Matrix<Scalar, 3, 1>& outward, Lever&& lever,
                                          const Eigen::Matrix<Scalar, 3, 1>& impulse) {
  if (kBodies == SolveBodies::kAny && body.inertia_kind != InverseInertiaKind::kIsotropic) {
    return tensorTurnOf<Scalar>(body, lever(), impulse);
  }
  return (Scalar(body.inverse_mass) * Scalar(body.spin_factor) / Scalar(body.radius)) *
         outward.cross(impulse);
}

/// w x r of `body` at its contact point: its surface's velocity there from its turning. A
/// ball's r is R `outward` (n on side a, -n on side b), the others' their lever arm `lever`.
inline Eigen::Vector3d turningVelocity(const SolverBody& body, const Eigen::Vector3d& outward,
                                       const Eigen::Vector3d& lever) {
  if (body.inertia_kind == InverseInertiaKind::kIsotropic) {
    return body.angular_velocity.cross(body.radius * outward);
  }
  return body.angular_velocity.cross(lever);
}

/// The slip at `contact`: the velocity of b's surface point relative to a's,
/// u = (v_b + w_b x r_b) - (v_a + w_a x r_a), less its part along the normal, u - (u.n) n
/// (friction.h). kSpin false: bodies do not turn (no rotational terms).
template <bool kSpin, SolveBodies kBodies = SolveBodies::kAny>
inline Eigen::Vector3d slipAt(const SolverBody& a, const SolverBody& b,
                              const ContactPoint& contact) {
  const Eigen::Vector3d& normal = contact.normal;
  Eigen::Vector3d slip = b.velocity - a.velocity;
  if constexpr (kSpin) {
    if (kBodies == SolveBodies::kBalls || (a.inertia_kind == InverseInertiaKind::kIsotropic &&
                                           b.inertia_kind == InverseInertiaKind::kIsotropic)) {
      slip += b.angular_velocity.cross(-b.radius * normal) -
              a.angular_velocity.cross(a.radius * normal);
    } else {
      slip += turningSlip(a, b, contact);
    }
  }
  return slip - slip.dot(normal) * normal;
}

/// One side of `contact` as the effective mass sees it (effective_mass.h): a ball's inverse
/// inertia from its spin factor (sphereInverseInertia), 0 where it does not turn.
inline ContactSide contactSideOf(const SolverBody& body, const Eigen::Vector3d& lever) {
  ContactSide side;
  side.inverse_mass = body.inverse_mass;
  if (turns(body)) {
    side.inverse_inertia =
        body.inertia_kind == InverseInertiaKind::kIsotropic
            ? sphereInverseInertia(body.inverse_mass, body.spin_factor, body.radius)
            : body.inverse_inertia;
  }
  side.lever_arm = lever;
  return side;
}

/// The tangential inverse mass of `contact` along the unit tangent `direction()` (called only
/// where it is needed): how fast the slip along it answers an impulse along it, t.K.t
/// (inverseEffectiveMassAlong, effective_mass.h). Two balls: W_t = w_a + w_b + r_a^2 / I_a +
/// r_b^2 / I_b, where r^2 / I = w / k for a ball, the same along every tangent, summed as
/// (w_a + w_b) + (w_a / k_a + w_b / k_b) as the ball solvers always have. kSpin false: bodies do
/// not turn, w_a + w_b.
template <bool kSpin, SolveBodies kBodies = SolveBodies::kAny, class Direction>
inline double tangentialInverseMass(const SolverBody& a, const SolverBody& b,
                                    const ContactPoint& contact, Direction&& direction) {
  double inverse_mass = a.inverse_mass + b.inverse_mass;
  if constexpr (kSpin) {
    if (kBodies == SolveBodies::kBalls || (a.inertia_kind == InverseInertiaKind::kIsotropic &&
                                           b.inertia_kind == InverseInertiaKind::kIsotropic)) {
      inverse_mass += a.inverse_mass * a.spin_factor + b.inverse_mass * b.spin_factor;
    } else {
      inverse_mass = tensorTangentialInverseMass(a, b, contact, direction());
    }
  }
  return inverse_mass;
}

}  // namespace collision_response::core
