// A shaped body's scenes and closed forms that the prediction's tests and the monitor's share: a
// box over a concrete floor, and the closed form of a box landing on an edge (edge_landing.h).
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

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

}  // namespace collision_response::core::shaped_scenes
