// Motion between impacts: straight lines, or parabolas under gravity; and resting on a plane.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <optional>
#include <vector>

#include "collision_response/core/shape.h"

namespace collision_response::core {

/// p + v dt + (a/2) dt^2, evaluated as p + dt (v + (dt/2) a): with a = 0 it is p + dt v to the
/// bit, so a scene without gravity moves exactly as the straight-line model.
inline Eigen::Vector3d positionAfter(const Eigen::Vector3d& position,
                                     const Eigen::Vector3d& velocity,
                                     const Eigen::Vector3d& acceleration, double dt) {
  return position + dt * (velocity + (0.5 * dt) * acceleration);
}

inline Eigen::Vector3d velocityAfter(const Eigen::Vector3d& velocity,
                                     const Eigen::Vector3d& acceleration, double dt) {
  return velocity + dt * acceleration;
}

/// The slowest bounce off a plane that leaves the touching band: a ball leaving at u under the
/// pressing acceleration g_n rises u^2 / (2 g_n); below sqrt(2 g_n band) it stays within `band`
/// of the plane, so it rests instead (this ends the endless shrinking bounces of e < 1 after
/// finitely many impacts, the rest at most `band` from the exact answer).
inline double restSpeed(double pressing_acceleration, double band) {
  return std::sqrt(2.0 * pressing_acceleration * band);
}

/// The touching band of a sphere of `radius` on a plane: `contact_tolerance` of the radius plus
/// the rounding of the position.
inline double touchingBand(double radius, double contact_tolerance, const Eigen::Vector3d& position,
                           double offset) {
  constexpr double kEps = 2.220446049250313e-16;
  return contact_tolerance * radius +
         16 * kEps * (position.lpNorm<Eigen::Infinity>() + std::abs(offset) + radius);
}

/// The plane (index into `planes`) a sphere rests on under `gravity`: gravity presses it into
/// the plane, it touches the plane (within the band) and moves along it, neither into it nor
/// away from it faster than restSpeed. Empty when it rests on none.
std::optional<std::size_t> restingPlane(const Eigen::Vector3d& position,
                                        const Eigen::Vector3d& velocity, double radius,
                                        const std::vector<Plane>& planes,
                                        const Eigen::Vector3d& gravity, double contact_tolerance);

/// The acceleration of a body resting on a plane: gravity's part along the plane (it slides;
/// the plane takes the rest).
inline Eigen::Vector3d restingAcceleration(const Eigen::Vector3d& gravity,
                                           const Eigen::Vector3d& normal) {
  return gravity - gravity.dot(normal) * normal;
}

}  // namespace collision_response::core
