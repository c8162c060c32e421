// A shaped body's scenes and closed forms that the prediction's tests and the monitor's share: a
// box over a concrete floor, and the closed form of a box landing on an edge (edge_landing.h).
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"
#include "edge_landing.h"
#include "quadrature.h"
#include "scene_builders.h"

namespace collision_response::core::shaped_scenes {

inline constexpr double kG = 9.81;

/// Every impact the monitor's steps reported, in order.
inline std::vector<ImpactRecord> impactsOf(const std::vector<StepReport>& reports) {
  std::vector<ImpactRecord> impacts;
  for (const StepReport& report : reports) {
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
  }
  return impacts;
}

/// A box of edges 2 half over a concrete floor at z = 0, its material `e` against concrete.
inline Scene floorScene(double e, const Eigen::Vector3d& half, double mass = 2.0) {
  Scene scene;
  scene.effects.gravity = true;
  scene.gravity = Eigen::Vector3d(0, 0, -kG);
  EXPECT_TRUE(scene.materials.addMaterial("block", Material{e, 0.0}, "m").ok());
  BodySpec body;
  body.id = "block";
  body.mass = mass;
  body.material = "block";
  body.shape = BodyShape::kBox;
  body.size = 2 * half;
  scene.bodies = {body};
  scene.obstacles = {scene_builders::plane("floor", Eigen::Vector3d::UnitZ(), 0.0, "concrete")};
  return scene;
}

/// A solid cylinder (r = 0.05 m, 0.2 m long, 1 kg) over the frictionless floor of floorScene,
/// given at rest leaning on its rim: its axis turned by `tilt` about x, its rim's lowest point
/// on the floor. Its centre falls straight down (no force along the floor), at the height
/// z = r sin theta + h cos theta, and m z'^2 theta'^2 / 2 + I_x theta'^2 / 2 + m g z is kept
/// (I_x = m (3 r^2 + L^2) / 12): below atan(r / h) it falls back onto its cap at theta = 0,
/// the integral of dtheta / theta' later (landing()).
struct RimFall {
  double r = 0.05, h = 0.1, m = 1.0, tilt = 0.3;

  Scene scene() const {
    Scene made = floorScene(0.5, Eigen::Vector3d(0.05, 0.05, 0.05), m);
    made.bodies[0].shape = BodyShape::kCylinder;
    made.bodies[0].size = Eigen::Vector3d::Zero();
    made.bodies[0].radius = r;
    made.bodies[0].length = 2 * h;
    return made;
  }
  Eigen::Vector3d centre() const {
    return Eigen::Vector3d(0, 0, r * std::sin(tilt) + h * std::cos(tilt));
  }
  Eigen::Quaterniond orientation() const {
    return Eigen::Quaterniond(Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()));
  }
  /// From rest at tilt to 0: with theta = tilt - s^2 the integrand 2 s / theta' is smooth at
  /// s = 0; 5-point Gauss-Legendre over 400 panels of s in [0, sqrt(tilt)].
  double landing() const {
    const double ix = m * (3 * r * r + 4 * h * h) / 12;
    const auto z = [&](double q) { return r * std::sin(q) + h * std::cos(q); };
    const auto dz = [&](double q) { return r * std::cos(q) - h * std::sin(q); };
    const auto rate = [&](double q) {
      return std::sqrt(2 * m * kG * (z(tilt) - z(q)) / (m * dz(q) * dz(q) + ix));
    };
    return quadrature::fromRest(rate, tilt, 0.0, 400);
  }
};

/// A cube (0.1 m, 1 kg) at rest on an incline of tan theta = 3/4 (its normal (0, -3/5, 4/5),
/// through the origin; no other obstacle), mu 0.9 >= 3/4, given sliding across the slope at
/// 1 m/s: its slide's direction turns towards the slope's (no closed form), which the model does
/// not carry yet (`not yet: sliding across the slope`): the example of a lasting contact held
/// and reported.
struct AcrossSlope {
  Scene scene() const {
    Scene made = floorScene(0.5, Eigen::Vector3d(0.05, 0.05, 0.05), 1.0);
    EXPECT_TRUE(made.materials.addMaterial("rough", Material{0.5, 0.9}, "m").ok());
    made.bodies[0].material = "rough";
    made.effects.friction = true;
    made.obstacles = {scene_builders::plane("incline", normal(), 0.0, "concrete")};
    return made;
  }
  static Eigen::Vector3d normal() { return Eigen::Vector3d(0, -0.6, 0.8); }
  BodyStateSample state(std::size_t body, double time) const {
    BodyStateSample made;
    made.body = body;
    made.time = time;
    made.position = 0.05 * normal();
    made.orientation = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), normal());
    made.velocity = Eigen::Vector3d(1, 0, 0);
    return made;
  }
};

/// The edge landing's impacts at one instant against its closed form: at edge.fall() (1e-11 s,
/// the first contact's certification), each leaving with v_z' and w_y' and no other spin (1e-9),
/// their impulses adding up to J (1e-9).
inline void expectTheEdgeLanding(const EdgeLanding& edge,
                                 const std::vector<ImpactRecord>& impacts) {
  double total = 0.0;
  for (const ImpactRecord& impact : impacts) {
    EXPECT_NEAR(impact.time, edge.fall(), 1e-11);
    total += impact.impulse;
    EXPECT_NEAR(impact.velocity_a_after.z(), edge.velocityAfter(), 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.y(), edge.spinAfter(), 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.x(), 0.0, 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.z(), 0.0, 1e-9);
  }
  EXPECT_NEAR(total, edge.impulse(), 1e-9);
}

}  // namespace collision_response::core::shaped_scenes
