#include "collision_response/core/time_of_impact.h"

#include <unsupported/Eigen/Polynomials>
#include <vector>

namespace collision_response::core {

std::optional<double> timeOfImpactSpheresAccelerated(const Eigen::Vector3d& separation,
                                                     const Eigen::Vector3d& relative_velocity,
                                                     const Eigen::Vector3d& relative_acceleration,
                                                     double contact_distance, double horizon) {
  if (relative_acceleration == Eigen::Vector3d::Zero()) {
    return timeOfImpactSpheres<double>(separation, relative_velocity, contact_distance, horizon);
  }
  if (!(horizon > 0)) return std::nullopt;
  // Units in which every term is at most about 1: lengths by a power of two L near the sizes;
  // time by T, the least of the horizon, the time to cross L at the speed and the time to cross
  // it under the acceleration. Then p(tau) = s + v tau + (a/2) tau^2 with |s| ~ 1, |v| <= 1,
  // |a| <= 1 and the horizon is tau <= horizon / T.
  const double length =
      powerOfTwoBelow(std::max(separation.lpNorm<Eigen::Infinity>(), contact_distance));
  const double speed = relative_velocity.lpNorm<Eigen::Infinity>();
  const double acceleration = relative_acceleration.lpNorm<Eigen::Infinity>();
  double unit = horizon;
  if (speed > 0) unit = std::min(unit, length / speed);
  unit = std::min(unit, std::sqrt(length / acceleration));
  if (!(unit > 0) || !std::isfinite(unit)) return std::nullopt;
  const Eigen::Vector3d s = separation / length;
  const Eigen::Vector3d v = relative_velocity * (unit / length);
  const Eigen::Vector3d a = relative_acceleration * (unit * unit / length);
  const double radius = contact_distance / length;
  const double reach = horizon / unit;  // the horizon in units of T
  const double distance = s.norm();
  // Too far to close the gap within the horizon even head-on and accelerating all the way.
  if (distance - radius > (v.norm() + 0.5 * a.norm() * reach) * reach) return std::nullopt;

  // |p(tau)|^2 - R^2, a quartic; leading terms that vanish against the others are dropped so
  // that the companion matrix never divides by (nearly) zero.
  std::vector<double> coefficients = {(distance - radius) * (distance + radius), 2 * s.dot(v),
                                      v.dot(v) + s.dot(a), v.dot(a), 0.25 * a.dot(a)};
  double largest = 0;
  for (const double c : coefficients) largest = std::max(largest, std::abs(c));
  while (coefficients.size() > 1 && std::abs(coefficients.back()) <= 1e-250 * largest) {
    coefficients.pop_back();
  }
  std::vector<double> roots;
  if (coefficients.size() == 2) {
    roots.push_back(-coefficients[0] / coefficients[1]);
  } else if (coefficients.size() > 2) {
    const Eigen::VectorXd polynomial = Eigen::Map<const Eigen::VectorXd>(
        coefficients.data(), static_cast<Eigen::Index>(coefficients.size()));
    Eigen::PolynomialSolver<double, Eigen::Dynamic> solver(polynomial);
    solver.realRoots(roots, 1e-6 * std::max(1.0, reach));
  }

  const auto position = [&](double tau) -> Eigen::Vector3d {
    return s + tau * (v + 0.5 * tau * a);
  };
  const auto velocity = [&](double tau) -> Eigen::Vector3d { return v + tau * a; };
  std::optional<double> best;
  for (double tau : roots) {
    if (!std::isfinite(tau) || tau < -1e-6 || tau > reach * (1 + 1e-6) + 1e-6) continue;
    for (int iteration = 0; iteration < 4; ++iteration) {  // Newton on |p|^2 - R^2
      const Eigen::Vector3d p = position(tau);
      const double value = (p.norm() - radius) * (p.norm() + radius);
      const double slope = 2 * p.dot(velocity(tau));
      if (!(slope != 0)) break;
      tau -= value / slope;
    }
    if (!(tau >= 0 && tau <= reach)) continue;
    if (!(position(tau).dot(velocity(tau)) < 0)) continue;  // leaving or grazing, not entering
    if (std::abs(position(tau).norm() - radius) > 1e-6 * (radius + distance)) {
      continue;  // a spurious root of the companion matrix
    }
    const double time = std::min(tau * unit, horizon);
    if (!best || time < *best) best = time;
  }
  return best;
}

}  // namespace collision_response::core
