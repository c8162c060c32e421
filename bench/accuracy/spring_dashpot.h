// MuJoCo's bounce through solref: the damping of a unilateral linear spring-dashpot contact that
// gives a coefficient of restitution (used by the accuracy benchmark's MuJoCo and by the cube
// tosses' MuJoCo, bench/cube_tosses/mujoco.cpp). A unilateral spring-dashpot lets go when its
// force returns to zero, before the penetration does; its coefficient of restitution is then
//   e = exp(-(beta / w) (pi - atan2(2 beta w, w^2 - beta^2))),  beta = b / 2, w^2 = k - beta^2
// (T. Schwager, T. Poeschel, "Coefficient of restitution and linear-dashpot model revisited",
// Granular Matter 9 (2007) 465), inverted for b by bisection.
#pragma once

#include <cmath>

namespace collision_response::bench {

/// The coefficient of restitution of a unilateral spring-dashpot of damping ratio zeta (above).
inline double springDashpotRestitution(double zeta) {
  constexpr double kPi = 3.14159265358979323846;
  if (zeta <= 0) return 1.0;
  if (zeta >= 1) return 0.0;
  const double w = std::sqrt(1 - zeta * zeta);  // in units of sqrt(k)
  return std::exp(-(zeta / w) * (kPi - std::atan2(2 * zeta * w, w * w - zeta * zeta)));
}

/// The damping ratio zeta = b / (2 sqrt(k)) that gives `restitution`.
inline double dampingRatioFor(double restitution) {
  if (restitution >= 1) return 0.0;
  double low = 0, high = 1;  // e falls from 1 to 0 as zeta goes from 0 to 1
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (low + high);
    (springDashpotRestitution(mid) > restitution ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

/// A direct solref (-stiffness, -damping) for MuJoCo.
struct SpringDashpot {
  double stiffness = 0.0;  ///< k, 1/s^2
  double damping = 0.0;    ///< b, 1/s
};

/// The contact that gives `restitution` with its half period pi / sqrt(k) spanning
/// `contact_steps` time steps of `dt` s.
inline SpringDashpot springDashpotFor(double restitution, double dt, double contact_steps) {
  constexpr double kPi = 3.14159265358979323846;
  const double omega = kPi / (contact_steps * dt);  // sqrt(k)
  return {omega * omega, 2 * dampingRatioFor(restitution) * omega};
}

}  // namespace collision_response::bench
