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
#include "scene_builders.h"

namespace collision_response::core::shaped_scenes {

inline constexpr double kG = 9.81;

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
