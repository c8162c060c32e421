// The closed form of a box landing on an edge, shared by the core's tests of a shaped body
// (shaped_scenes.h) and the tests over ROS (test/ros/test_predict_serve.cpp). Eigen only.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "quadrature.h"

namespace collision_response::core::shaped_scenes {

/// A box of half edges (a, b, c) and mass m, turned by theta about y, dropped from rest with its
/// centre at `height`, lands on the edge of its two lowest corners, (a cos theta - c sin theta,
/// +-b, -(a sin theta + c cos theta)) from its centre. Frictionless, the two take equal impulses
/// whose moments about x cancel: as one contact at (x, 0, z), whose effective mass along z is
/// 1 / (1/m + x^2 / I_yy), I_yy = m (a^2 + c^2) / 3. So J = (1 + e) v / (1/m + x^2 / I_yy),
/// v_z' = -v + J / m, w_y' = -x J / I_yy (the floor's impulse +J z at r = (x, ., z)).
struct EdgeLanding {
  static constexpr double kGravity = 9.81;  ///< m/s^2, along -z
  double a = 0.1, b = 0.05, c = 0.025, m = 2.0, e = 0.5, theta = 0.3, height = 0.5;

  Eigen::Quaterniond turn() const {
    return Eigen::Quaterniond(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitY()));
  }
  double low() const { return a * std::sin(theta) + c * std::cos(theta); }
  double fall() const { return std::sqrt(2 * (height - low()) / kGravity); }
  double speed() const { return kGravity * fall(); }  ///< v, down
  double x() const { return a * std::cos(theta) - c * std::sin(theta); }
  double inertia() const { return m * (a * a + c * c) / 3; }  ///< I_yy
  double impulse() const { return (1 + e) * speed() / (1 / m + x() * x() / inertia()); }
  double velocityAfter() const { return -speed() + impulse() / m; }  ///< v_z'
  double spinAfter() const { return -x() * impulse() / inertia(); }  ///< w_y'

  /// The centre's height at tilt phi about y, on the edge of (a, +-b, -c): a sin phi + c cos phi.
  double heightAt(double phi) const { return a * std::sin(phi) + c * std::cos(phi); }
  /// Released at rest on that edge (tilt theta, the centre at low()) on a frictionless floor: the
  /// floor's force is vertical, so the centre's x and y stay, and the energy gives
  /// phi'^2 = 2 g (h(theta) - h(phi)) / (h'(phi)^2 + I_yy / m), h' = a cos phi - c sin phi, down
  /// to phi = 0 where the face lands. Its instant is the integral of dphi / |phi'| over (0, theta):
  /// with phi = theta - u^2 the integrand 2 u / |phi'| is smooth, by 5-point Gauss-Legendre over
  /// 200 panels of u in (0, sqrt theta).
  double tipInstant() const {
    const auto rate = [&](double phi) {
      const double slope = a * std::cos(phi) - c * std::sin(phi);
      return std::sqrt(2 * kGravity * (heightAt(theta) - heightAt(phi)) /
                       (slope * slope + inertia() / m));
    };
    return quadrature::fromRest(rate, theta, 0.0, 200);
  }
};

}  // namespace collision_response::core::shaped_scenes
