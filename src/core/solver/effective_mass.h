// The effective mass of a contact between two rigid bodies: how the relative velocity of the
// two surfaces at the contact point answers an impulse there. One formula for every solver and
// every shape (README, issue 42's build step 1); a sphere is the body whose lever arm lies along
// the normal.
#pragma once

#include <Eigen/Core>

namespace collision_response::core {

/// One side of a contact as the effective mass sees it. Every vector and tensor is in the one
/// common frame (the caller's).
struct ContactSide {
  /// 1/m, 1/kg; 0 for an immovable body (inverseMass in body.h).
  double inverse_mass = 0.0;
  /// I^-1 about the centre of mass, 1/(kg m^2), in the common frame (R I_body^-1 R^T); zero for
  /// a body that does not turn (immovable, a point, no spin effect).
  Eigen::Matrix3d inverse_inertia = Eigen::Matrix3d::Zero();
  /// r, m: from the centre of mass to the contact point.
  Eigen::Vector3d lever_arm = Eigen::Vector3d::Zero();
};

/// A sphere's I^-1 = 1 / (k m R^2) times the identity, from the solvers' spin factor 1/k
/// (friction.h, spinFactor: 5/2 solid, 3/2 hollow, 0 when it does not turn): (w / k) / R / R,
/// divided by R twice rather than by R^2, which overflows first.
inline Eigen::Matrix3d sphereInverseInertia(double inverse_mass, double spin_factor,
                                            double radius) {
  if (spin_factor == 0.0) return Eigen::Matrix3d::Zero();
  return Eigen::Matrix3d::Identity() * ((inverse_mass * spin_factor / radius) / radius);
}

/// The contact's inverse effective mass (Mirtich's collision matrix, "Impulse-based dynamic
/// simulation of rigid body systems", 1996): an impulse J on b at the contact point,
/// -J on a, changes the relative velocity of b's surface point to a's by K J, with
///
///   K = (w_a + w_b) 1 - [r_a]x I_a^-1 [r_a]x - [r_b]x I_b^-1 [r_b]x,
///
/// w = 1/m, r the lever arms, [r]x the cross-product matrix ([r]x v = r x v). Each side's
/// velocity change at its point is w J + (I^-1 (r x J)) x r, which is the side's term of K times
/// J. K is symmetric and positive semi-definite (definite where some side is movable).
inline Eigen::Matrix3d inverseEffectiveMass(const ContactSide& a, const ContactSide& b) {
  const auto side = [](const ContactSide& s) -> Eigen::Matrix3d {
    Eigen::Matrix3d cross;  // [r]x
    const Eigen::Vector3d& r = s.lever_arm;
    cross << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
    return -(cross * s.inverse_inertia * cross);
  };
  return (a.inverse_mass + b.inverse_mass) * Eigen::Matrix3d::Identity() + side(a) + side(b);
}

/// d.K.d, the entry of inverseEffectiveMass along a unit direction d (the normal: the inverse of
/// the effective mass along the line of impact, 1/kg). Since [r]x d = r x d and [r]x^T = -[r]x,
///
///   d.K.d = (w_a + w_b) + (r_a x d).I_a^-1 (r_a x d) + (r_b x d).I_b^-1 (r_b x d),
///
/// summed in this order, so that for spheres along their normal (r = R n: r x n is only the
/// rounding of R n, its term ~ eps^2 w, far below half an ulp of w_a + w_b) it is w_a + w_b to
/// the bit: the normal inverse mass the solvers of balls have always used. Every term is >= 0.
inline double inverseEffectiveMassAlong(const ContactSide& a, const ContactSide& b,
                                        const Eigen::Vector3d& direction) {
  const auto turning = [&](const ContactSide& s) {
    const Eigen::Vector3d moment_arm = s.lever_arm.cross(direction);
    return moment_arm.dot(s.inverse_inertia * moment_arm);
  };
  return (a.inverse_mass + b.inverse_mass) + turning(a) + turning(b);
}

}  // namespace collision_response::core
