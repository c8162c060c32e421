// The instant two bodies moving in straight lines first touch: the stable roots of doc/model.md,
// "Detection" (derived in doc/development.md, "The physics, and how it is made exact").
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "collision_response/core/impact.h"

namespace collision_response::core {

/// The power of two nearest below |value| (1 for 0): scaling by it is exact.
template <typename Scalar>
Scalar powerOfTwoBelow(Scalar value) {
  if (value == 0 || !std::isfinite(value)) return Scalar(1);
  int exponent = 0;
  std::frexp(value, &exponent);
  return std::ldexp(Scalar(1), exponent - 1);
}

/// The earliest t in [0, horizon] at which two spheres, moving in straight lines, come into
/// contact: |s + v t| = R with s = p_b - p_a and v = v_b - v_a at t = 0 and R = r_a + r_b.
/// Empty when they do not close (s.v >= 0), overlap already at t = 0 (they came into contact
/// before; an impact is found once, when it begins), pass each other, or touch after horizon.
/// Closing spheres whose gap is within the rounding of |s| (4 eps |s|) touch at t = 0.
///
/// |s + v t|^2 = R^2 is a t^2 + 2 b t + c = 0 with a = v.v, b = s.v, c = s.s - R^2. Both ways of
/// losing digits are avoided:
///  - c = (|s| - R)(|s| + R), the gap taken first, so a tiny gap keeps its digits;
///  - the discriminant b^2 - a c equals a R^2 - |v x s|^2 (Lagrange's identity), computed as
///    (|v| R - |v x s|)(|v| R + |v x s|) from the cross product: no difference of two large
///    nearly equal squares;
///  - the entering root (-b - sqrt(D)) / a is evaluated as c / (-b + sqrt(D)) (citardauq):
///    with b < 0 both terms of the denominator are >= 0, so nothing cancels.
/// Lengths and speeds are first scaled by powers of two (exact) so that the squares neither
/// overflow nor underflow for separations of 1e+-150 m and speeds of 1e+-150 m/s.
template <typename Scalar>
std::optional<Scalar> timeOfImpactSpheres(const Vector3<Scalar>& separation,
                                          const Vector3<Scalar>& relative_velocity,
                                          Scalar contact_distance, Scalar horizon) {
  const Scalar length_unit =
      powerOfTwoBelow(std::max(separation.template lpNorm<Eigen::Infinity>(), contact_distance));
  const Scalar speed_unit = powerOfTwoBelow(relative_velocity.template lpNorm<Eigen::Infinity>());
  const Vector3<Scalar> s = separation / length_unit;
  const Vector3<Scalar> v = relative_velocity / speed_unit;
  const Scalar radius = contact_distance / length_unit;

  const Scalar closing = s.dot(v);  // b
  if (!(closing < 0)) return std::nullopt;
  const Scalar distance = s.norm();
  const Scalar gap = distance - radius;
  if (gap < 0) return std::nullopt;
  // A gap within the rounding of the distance is contact now: whether closing spheres would
  // touch later (a graze) depends on digits the positions do not have.
  if (gap <= 4 * std::numeric_limits<Scalar>::epsilon() * distance) return Scalar(0);
  const Scalar speed = v.norm();
  // Too far to close the gap within the horizon even head-on (one unit of scaled time is
  // length_unit / speed_unit seconds).
  if (gap > speed * (horizon * (speed_unit / length_unit))) return std::nullopt;
  const Scalar speed_times_radius = speed * radius;
  const Scalar miss = v.cross(s).norm();  // |v x s|: how far off-centre the approach is
  const Scalar discriminant = (speed_times_radius - miss) * (speed_times_radius + miss);
  if (discriminant < 0) return std::nullopt;  // the spheres pass each other
  const Scalar scaled_time = gap * (distance + radius) / (std::sqrt(discriminant) - closing);
  // Back to seconds: one unit of scaled time is length_unit / speed_unit, a power of two.
  const Scalar time = scaled_time * (length_unit / speed_unit);
  if (!(time <= horizon)) return std::nullopt;
  return time;
}

/// The earliest t in [0, horizon] at which a sphere reaches a plane moving with it in straight
/// lines: gap + rate t = 0, with gap = n.p - offset - r the distance between the sphere's surface
/// and the plane at t = 0 and rate = n.(v_sphere - v_plane). Empty when the sphere moves away or
/// along the plane (rate >= 0), is already through it (gap < 0), or arrives after horizon.
template <typename Scalar>
std::optional<Scalar> timeOfImpactPlane(Scalar gap, Scalar rate, Scalar horizon) {
  if (!(rate < 0) || gap < 0) return std::nullopt;
  const Scalar time = gap / -rate;
  if (!(time <= horizon)) return std::nullopt;
  return time;
}

/// The earliest t in (0, horizon] at which a sphere under constant acceleration reaches a plane:
/// gap(t) = gap + rate t + (acceleration / 2) t^2 = 0 with gap decreasing there (entering), where
/// gap = n.p - offset - r, rate = n.(v_sphere - v_plane), acceleration = n.a_sphere. The gap may
/// start inside the touching band (a ball just bounced): the root there, where the ball leaves,
/// is not an entry; the one where it comes back is.
///
/// Roots of A t^2 + B t + C (A = acceleration/2, B = rate, C = gap) in the cancellation-free form:
/// q = -(B + sign(B) sqrt(B^2 - 4 A C)) / 2, roots q / A and C / q; -B and sign(B) sqrt(D) have the
/// same sign, so they add without cancellation (a falling ball's entry 2 gap / (sqrt(D) - rate)
/// keeps its digits for a 1e-12 m gap).
template <typename Scalar>
std::optional<Scalar> timeOfImpactPlaneBallistic(Scalar gap, Scalar rate, Scalar acceleration,
                                                 Scalar horizon) {
  if (acceleration == 0) {
    if (!(rate < 0) || gap < 0) return std::nullopt;
    const Scalar time = gap / -rate;
    if (!(time <= horizon)) return std::nullopt;
    return time;
  }
  // A gap and an acceleration so small that sqrt|a| sqrt|gap| would fall among the subnormals
  // (and lose its digits: 7e-313 m under 1.2e-319 m/s^2 came out 1 % early) are scaled up with
  // the rate by a power of two, 2^k (gap + rate t + a t^2 / 2) having the same roots; not so far
  // that the rate overflows (a rate that large leaves the product negligible anyway).
  if (gap != 0 && std::isfinite(gap) && std::isfinite(rate) && std::isfinite(acceleration) &&
      std::ilogb(acceleration) + std::ilogb(gap) < -1000) {
    int k = -(std::ilogb(acceleration) + std::ilogb(gap)) / 2;
    if (rate != 0) k = std::min(k, 1000 - std::ilogb(rate));
    if (k > 0) {
      return timeOfImpactPlaneBallistic(std::ldexp(gap, k), std::ldexp(rate, k),
                                        std::ldexp(acceleration, k), horizon);
    }
  }
  // Scaled by the larger of |rate| and sqrt(|2 a gap|), so that rate^2 - 2 a gap neither
  // overflows (rates of 1e155 and beyond) nor underflows: with u = sqrt|a| sqrt|gap| (no
  // overflow), 2 a gap / scale^2 = 2 sign(a gap) (u / scale)^2, at most 1 in size.
  const Scalar geometric = std::sqrt(std::abs(acceleration)) * std::sqrt(std::abs(gap));
  Scalar scale = std::max(std::abs(rate), std::sqrt(Scalar(2)) * geometric);
  // sqrt(2) u past the doubles: u itself is the scale (2 a gap / scale^2 is then at most 2).
  if (!std::isfinite(scale)) scale = std::max(std::abs(rate), geometric);
  if (!(scale > 0) || !std::isfinite(scale)) return std::nullopt;
  const Scalar scaled_rate = rate / scale;
  const Scalar scaled_geometric = geometric / scale;
  const Scalar sign = (acceleration < 0) != (gap < 0) ? Scalar(-1) : Scalar(1);
  const Scalar scaled_discriminant =
      scaled_rate * scaled_rate - 2 * sign * scaled_geometric * scaled_geometric;
  if (scaled_discriminant < 0) return std::nullopt;
  const Scalar scaled_root = std::sqrt(scaled_discriminant);
  const Scalar root = scaled_root * scale;
  std::optional<Scalar> best;
  const auto consider = [&](Scalar time) {
    const bool entering = rate + acceleration * time < 0;
    if (time >= 0 && time <= horizon && entering && (!best || time < *best)) best = time;
  };
  if (!std::isfinite(root)) {
    // sqrt(D) is beyond the doubles (a rate and a sqrt(2 a gap) near their largest): q in units
    // of `scale`, q_s = -(B / scale + sign(B) sqrt(D) / scale) / 2, at least 1/2 in size (one of
    // |B| / scale and sqrt(2 |a gap|) / scale is 1), and the roots from it: 2 q_s scale / a and
    // (gap / scale) / q_s.
    const Scalar scaled_q = -(scaled_rate + std::copysign(scaled_root, scaled_rate)) / 2;
    consider(2 * scaled_q * (scale / acceleration));
    consider(gap / scale / scaled_q);
    return best;
  }
  // Summed before halving where that cannot overflow: halving a subnormal rate first would
  // round away its last bits.
  const Scalar q = std::max(std::abs(rate), root) < std::numeric_limits<Scalar>::max() / 4
                       ? -(rate + std::copysign(root, rate)) / 2
                       : -(rate / 2 + std::copysign(root / 2, rate));
  // q / (a / 2) as 2 q / a where 2 q cannot overflow: halving a subnormal acceleration would
  // round away its last bits.
  const Scalar first_root = std::abs(q) < std::numeric_limits<Scalar>::max() / 2
                                ? 2 * q / acceleration
                                : q / (acceleration / 2);
  consider(first_root);
  if (q != 0) consider(gap / q);
  return best;
}

/// The earliest t in (0, horizon] at which two spheres with a relative acceleration a (one falls,
/// the other is held) come into contact: |s + v t + (a/2) t^2| = R, entering. The squared
/// distance minus R^2 is a quartic in t; its real roots are found on [0, horizon] (companion
/// matrix), each polished by Newton's method on the quartic, and the first entering one kept.
/// a = 0 is timeOfImpactSpheres.
std::optional<double> timeOfImpactSpheresAccelerated(const Eigen::Vector3d& separation,
                                                     const Eigen::Vector3d& relative_velocity,
                                                     const Eigen::Vector3d& relative_acceleration,
                                                     double contact_distance, double horizon);

}  // namespace collision_response::core
