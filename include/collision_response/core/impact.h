// The impact of two bodies along a line of impact: the seed's momentum and restitution laws,
// in the inverse-mass form that survives extreme mass ratios and infinite masses.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

namespace collision_response::core {

template <typename Scalar>
using Vector3 = Eigen::Matrix<Scalar, 3, 1>;

/// What one impact does to the two bodies' linear velocities.
template <typename Scalar>
struct ImpactResponse {
  Vector3<Scalar> velocity_a;  ///< m/s, a after the impact
  Vector3<Scalar> velocity_b;  ///< m/s, b after the impact
  /// N s, >= 0: the normal impulse; b receives +impulse along the line of impact, a -impulse.
  Scalar normal_impulse = 0;
  /// m/s: -(v_b - v_a).n before the impact; > 0 when the bodies approach.
  Scalar approach_speed = 0;
  /// J, >= 0: (1/2) mu (1 - e^2) d^2, the kinetic energy the impact takes away.
  Scalar energy_lost = 0;
  /// false when the bodies separate or slide along each other: velocities are left untouched.
  bool approaching = false;
};

/// share x, with share = w / W: as (w / W) x while the share is a normal double, as (w x) / W
/// when it would underflow (a mass ratio beyond ~1e308: the heavy body's share of the change is
/// still a double after the product, not before). Each term depends only on its own w, so
/// swapping the bodies swaps the terms exactly.
template <typename Scalar>
Scalar shareOf(Scalar inverse_mass, Scalar total_inverse_mass, Scalar value) {
  const Scalar share = inverse_mass / total_inverse_mass;
  if (share >= std::numeric_limits<Scalar>::min() || inverse_mass == 0) return share * value;
  return inverse_mass * value / total_inverse_mass;
}

/// Resolves a frictionless impact (the seed's model) along the unit `line_of_impact` n, which
/// points from a to b.
///
/// With w = 1/m (0 when immovable), W = w_a + w_b, share_a = w_a / W, share_b = w_b / W and the
/// normal components u_a = v_a.n, u_b = v_b.n, d = u_b - u_a (approaching when d < 0):
///
///   centre-of-mass normal velocity  u_cm = share_b u_a + share_a u_b
///   u_a' = u_cm + e share_a d,   u_b' = u_cm - e share_b d
///
/// which is the seed's combined formula v_a' = (m_a v_a + m_b v_b + e m_b (v_b - v_a)) / (m_a +
/// m_b) divided through by m_a m_b. Only the normal component changes; the perpendicular one is
/// carried over (oblique impacts). This form never forms a momentum or a kinetic energy, so
/// mass ratios of 1e+-15 and m = inf are ordinary; and it is exact where the physics is exact:
/// a still wall gives u_a' = e (0 - u_a) = -e u_a to the last bit, e = 0 gives u_a' = u_b' =
/// u_cm bit for bit. (The impulse form u_a + (1 + e) share_a d rounds 1 + e and is not exact.)
///
/// The normal impulse is J = (1 + e) mu (-d) and the energy lost (1/2) mu (1 - e)(1 + e) d^2,
/// with mu = 1/W the reduced mass; mu (-d) is formed first so that the product does not
/// overflow where the answer is finite.
///
/// Preconditions (see validation.h): finite velocities, |n| = 1, 0 <= e <= 1, w_a, w_b >= 0 and
/// W > 0 (not both immovable).
template <typename Scalar>
ImpactResponse<Scalar> resolveImpact(Scalar inverse_mass_a, const Vector3<Scalar>& velocity_a,
                                     Scalar inverse_mass_b, const Vector3<Scalar>& velocity_b,
                                     const Vector3<Scalar>& line_of_impact, Scalar restitution) {
  const Vector3<Scalar>& n = line_of_impact;
  const Scalar normal_a = velocity_a.dot(n);
  const Scalar normal_b = velocity_b.dot(n);
  const Scalar relative_normal = normal_b - normal_a;  // d

  ImpactResponse<Scalar> response;
  response.velocity_a = velocity_a;
  response.velocity_b = velocity_b;
  response.approach_speed = -relative_normal;
  response.approaching = relative_normal < 0;
  if (!response.approaching) return response;

  const Scalar total_inverse_mass = inverse_mass_a + inverse_mass_b;  // W
  const Scalar centre_of_mass_normal = shareOf(inverse_mass_b, total_inverse_mass, normal_a) +
                                       shareOf(inverse_mass_a, total_inverse_mass, normal_b);
  const Scalar normal_a_after =
      centre_of_mass_normal +
      restitution * shareOf(inverse_mass_a, total_inverse_mass, relative_normal);
  const Scalar normal_b_after =
      centre_of_mass_normal -
      restitution * shareOf(inverse_mass_b, total_inverse_mass, relative_normal);

  // Perpendicular parts carried over unchanged, normal parts replaced.
  response.velocity_a = (velocity_a - normal_a * n) + normal_a_after * n;
  response.velocity_b = (velocity_b - normal_b * n) + normal_b_after * n;

  const Scalar reduced_mass = Scalar(1) / total_inverse_mass;  // mu, kg
  const Scalar normal_momentum = reduced_mass * response.approach_speed;
  response.normal_impulse = (Scalar(1) + restitution) * normal_momentum;
  response.energy_lost = Scalar(0.5) * (Scalar(1) - restitution) * (Scalar(1) + restitution) *
                         normal_momentum * response.approach_speed;
  return response;
}

/// True when a velocity has a component across the line of impact (the seed's oblique impact):
/// |v_perp| > 1e-9 |v| in the max norm (an angle of more than about 1e-9 rad; 64 ulps in float).
/// The margin keeps rounding and measured data (a velocity through tf, a derived normal) from
/// calling a direct impact oblique. Max norms: no squares, so no overflow.
template <typename Scalar>
bool hasObliqueComponent(const Vector3<Scalar>& velocity, const Vector3<Scalar>& line_of_impact) {
  const Vector3<Scalar> perpendicular = velocity - velocity.dot(line_of_impact) * line_of_impact;
  const Scalar tolerance = std::max(Scalar(1e-9), 64 * std::numeric_limits<Scalar>::epsilon());
  return perpendicular.template lpNorm<Eigen::Infinity>() >
         tolerance * velocity.template lpNorm<Eigen::Infinity>();
}

}  // namespace collision_response::core
