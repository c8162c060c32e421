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
  const Eigen::Vector3d& s = separation;
  const Eigen::Vector3d& v = relative_velocity;
  const Eigen::Vector3d& a = relative_acceleration;
  const double distance = s.norm();
  // Too far to close the gap within the horizon even head-on and accelerating all the way.
  if (distance - contact_distance > (v.norm() + 0.5 * a.norm() * horizon) * horizon) {
    return std::nullopt;
  }
  // |p(t)|^2 - R^2 with p = s + v t + (a/2) t^2, in the time unit `horizon` (t = tau horizon).
  const double h = horizon;
  Eigen::Matrix<double, 5, 1> coefficients;
  coefficients << (distance - contact_distance) * (distance + contact_distance), 2 * s.dot(v) * h,
      (v.dot(v) + s.dot(a)) * h * h, v.dot(a) * h * h * h, 0.25 * a.dot(a) * h * h * h * h;
  Eigen::PolynomialSolver<double, 4> solver(coefficients);
  std::vector<double> roots;
  solver.realRoots(roots, 1e-6);

  const auto position = [&](double t) -> Eigen::Vector3d { return s + t * (v + 0.5 * t * a); };
  const auto velocity = [&](double t) -> Eigen::Vector3d { return v + t * a; };
  std::optional<double> best;
  for (const double root : roots) {
    if (root < -1e-6 || root > 1 + 1e-6) continue;
    double t = root * h;
    for (int iteration = 0; iteration < 4; ++iteration) {  // Newton on |p|^2 - R^2
      const Eigen::Vector3d p = position(t);
      const double value = (p.norm() - contact_distance) * (p.norm() + contact_distance);
      const double slope = 2 * p.dot(velocity(t));
      if (slope == 0) break;
      t -= value / slope;
    }
    if (!(t >= 0 && t <= horizon)) continue;
    if (!(position(t).dot(velocity(t)) < 0)) continue;  // leaving or grazing, not entering
    if (std::abs(position(t).norm() - contact_distance) > 1e-6 * (contact_distance + distance)) {
      continue;  // a spurious root of the companion matrix
    }
    if (!best || t < *best) best = t;
  }
  return best;
}

}  // namespace collision_response::core
