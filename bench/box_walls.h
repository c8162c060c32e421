// The six walls of the closed box [0, size]^3 that the benchmarks' gases bounce in.
#pragma once

#include <string>

#include "collision_response/core/scene.h"

namespace collision_response::bench {

/// Planes facing inwards, ids wall_0 .. wall_5, of `material`.
inline void addBoxWalls(core::Scene& scene, double size, const std::string& material) {
  using V = Eigen::Vector3d;
  const V normals[] = {V(1, 0, 0), V(-1, 0, 0), V(0, 1, 0), V(0, -1, 0), V(0, 0, 1), V(0, 0, -1)};
  for (int i = 0; i < 6; ++i) {
    core::ObstacleSpec wall;
    wall.id = "wall_" + std::to_string(i);
    wall.material = material;
    wall.normal = normals[i];
    wall.offset = i % 2 == 0 ? 0.0 : -size;
    scene.obstacles.push_back(wall);
  }
}

}  // namespace collision_response::bench
