// The seed's head-on request, the one fixture of every test (and benchmark) that needs a good
// ComputeCollision request: 2 kg at 3 m/s against 1 kg at -1 m/s along x, e = 0.5. Its answer,
// from the seed's combined formulas: v_a' = (6 - 1 + 0.5 * 1 * (-4)) / 3 = 1 and
// v_b' = (5 + 0.5 * 2 * 4) / 3 = 3; impulse m_a (v_a - v_a') = 4 N s; energy lost
// (1/2) mu (1 - e^2) d^2 = 0.5 * 2/3 * 0.75 * 16 = 4 J.
#pragma once

#include "collision_response/ComputeCollision.h"

namespace collision_response::testing {

inline ComputeCollision::Request seedHeadOnRequest() {
  ComputeCollision::Request request;
  request.a.id = "a";
  request.a.mass = 2.0;
  request.a.velocity.x = 3.0;
  request.b.id = "b";
  request.b.mass = 1.0;
  request.b.position.x = 1.0;
  request.b.velocity.x = -1.0;
  request.restitution = 0.5;
  return request;
}

/// The exact answer to seedHeadOnRequest().
inline constexpr double kSeedVelocityA = 1.0;
inline constexpr double kSeedVelocityB = 3.0;
inline constexpr double kSeedImpulse = 4.0;
inline constexpr double kSeedEnergyLost = 4.0;

}  // namespace collision_response::testing
