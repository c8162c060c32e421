// The scene parts the core tests build again and again: a ball, a plane, a fixed sphere. Each
// sets only what it is given; the rest keeps BodySpec's and ObstacleSpec's defaults.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

#include "collision_response/core/scene.h"

namespace collision_response::core::scene_builders {

inline BodySpec ball(const std::string& id, double mass, double radius, const std::string& material,
                     const Eigen::Vector3d& position = Eigen::Vector3d::Zero(),
                     const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero()) {
  BodySpec body;
  body.id = id;
  body.mass = mass;
  body.radius = radius;
  body.material = material;
  body.position = position;
  body.velocity = velocity;
  return body;
}

/// The plane normal.x = offset (the normal as given: Scene loading normalises it).
inline ObstacleSpec plane(const std::string& id, const Eigen::Vector3d& normal, double offset,
                          const std::string& material) {
  ObstacleSpec obstacle;
  obstacle.id = id;
  obstacle.normal = normal;
  obstacle.offset = offset;
  obstacle.material = material;
  return obstacle;
}

inline ObstacleSpec sphere(const std::string& id, const Eigen::Vector3d& centre, double radius,
                           const std::string& material) {
  ObstacleSpec obstacle;
  obstacle.id = id;
  obstacle.shape = ObstacleShape::kSphere;
  obstacle.position = centre;
  obstacle.radius = radius;
  obstacle.material = material;
  return obstacle;
}

/// A box of edge lengths `size` centred at `centre`, turned by `orientation`.
inline ObstacleSpec box(const std::string& id, const Eigen::Vector3d& centre,
                        const Eigen::Vector3d& size, const std::string& material,
                        const Eigen::Quaterniond& orientation = Eigen::Quaterniond::Identity()) {
  ObstacleSpec obstacle;
  obstacle.id = id;
  obstacle.shape = ObstacleShape::kBox;
  obstacle.position = centre;
  obstacle.size = size;
  obstacle.orientation = orientation;
  obstacle.material = material;
  return obstacle;
}

}  // namespace collision_response::core::scene_builders
