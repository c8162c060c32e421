// The second bounce of a throw (bouncing_ball.h) as the monitor's own prediction
// (core::predictImpacts) finds it from the state before the first, with the coefficients a
// calibration gave, the seed's, or the truth's: what a calibration buys (issue 44, item 5), for
// bench/calibration_accuracy.cpp and test/core/test_calibration.cpp.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "bouncing_ball.h"
#include "collision_response/core/prediction.h"

namespace collision_response::core::second_bounce {

using V = Eigen::Vector3d;
using bouncing_ball::kG;
using bouncing_ball::Throw;

/// The material a user without a calibration would take for a table-tennis ball: the seed's
/// hollow hard plastic ball, on concrete e = 0.688 and the default mu (materials.h, 0.5).
inline constexpr const char* kSeedMaterial = "hollow_hard_plastic_ball";
/// The material of the coefficients given to floorScene.
inline constexpr const char* kGivenMaterial = "given";
inline constexpr double kMass = 0.0027;  ///< kg, a table-tennis ball's (cancels from its motion)
/// s before the first bounce: the state the prediction starts from, as a tracker hands it over.
inline constexpr double kLead = 0.05;

/// The throw's state kLead before its first bounce and its centre at the second, in closed form
/// (bouncing_ball.h's parabolas, without noise).
struct Truth {
  V start_position = V::Zero();
  V start_velocity = V::Zero();
  V second_bounce = V::Zero();  ///< the centre at the second bounce
};

inline Truth truthOf(Throw t) {
  t.bounces = std::max(t.bounces, 2);
  t.noise = 0.0;
  t.drop = 0.0;
  const auto track = bouncing_ball::throwBall(t);
  const auto& first = track.bounces[0];
  const auto& second = track.bounces[1];
  Truth truth;
  V at_first = t.position + first.time * t.velocity;  // the first bounce's centre, z = r
  at_first.z() = t.radius;
  // Flown back from it by kLead along its parabola.
  truth.start_position = at_first - kLead * first.before;
  truth.start_position.z() -= 0.5 * kG * kLead * kLead;
  truth.start_velocity = first.before + V(0, 0, kG * kLead);
  truth.second_bounce = at_first + (second.time - first.time) * first.after;
  truth.second_bounce.z() = t.radius;
  return truth;
}

/// The floor (concrete, z = 0) and the throw's ball (solid) with gravity, friction and spin, as
/// bouncing_ball.h flies them; the material kGivenMaterial of e and mu against concrete (a
/// material's own coefficients are its pair's with concrete, materials.h). An e or mu the scene
/// refuses: its error.
inline Expected<Scene> floorScene(const Throw& t, double e, double mu) {
  Scene scene;
  scene.effects.gravity = scene.effects.friction = scene.effects.spin = true;
  scene.gravity = V(0, 0, -kG);
  BodySpec ball;
  ball.id = "ball";
  ball.mass = kMass;
  ball.radius = t.radius;
  ball.material = kSeedMaterial;
  ball.inertia = Inertia::kSolid;
  scene.bodies = {ball};
  ObstacleSpec floor;
  floor.id = "floor";
  floor.normal = V::UnitZ();
  floor.offset = 0.0;
  floor.material = kReferenceSurface;
  scene.obstacles = {floor};
  if (auto added = scene.materials.addMaterial(kGivenMaterial, Material{e, mu}, kGivenMaterial);
      !added) {
    return added.error();
  }
  return scene;
}

/// m: how far from the truth's the monitor's prediction puts the centre at the second bounce,
/// from the truth's state kLead before the first, the ball of `material` (its pair with the
/// floor); none when it finds fewer than two bounces; the prediction's error when refused.
inline Expected<std::optional<double>> secondBounceError(const Throw& t, const Truth& truth,
                                                         Scene scene, const std::string& material) {
  scene.bodies[0].material = material;
  PredictionRequest request;
  request.body = scene.bodies[0];
  request.state.position = truth.start_position;
  request.state.velocity = truth.start_velocity;
  request.state.angular_velocity = t.spin;
  request.horizon = 5.0;
  request.max_impacts = 2;
  request.effects = scene.effects;
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  if (!prediction.ok()) return prediction.error();
  if (prediction->impacts.size() < 2) return std::optional<double>();
  const auto& second = prediction->impacts[1];
  const V centre = second.contact_point - t.radius * second.normal;  // normal: ball to floor
  return std::optional<double>((centre - truth.second_bounce).norm());
}

}  // namespace collision_response::core::second_bounce
