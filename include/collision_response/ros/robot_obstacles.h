// A robot's own links as obstacles (scene key `robot:`): every <collision> of the chosen links of
// the URDF on the parameter server becomes an obstacle attached to its link's tf frame, moving
// with it (README, "A robot's links").
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/scene.h"
#include "collision_response/ros/mesh_resource.h"

namespace collision_response {

/// The scene's `robot:` entry.
struct RobotLinks {
  std::string description = "robot_description";  ///< the parameter holding the URDF
  bool all_links = true;                          ///< `links: all`
  std::vector<std::string> links;                 ///< otherwise these
  std::string material;                           ///< required: every link's
  double padding = 0.0;  ///< m, >= 0: every shape grown by it (a box by it on each side)
  /// Not a `robot:` key: the scene's `max_mesh_bytes`, the largest mesh file read.
  std::size_t max_mesh_bytes = kDefaultMaxMeshBytes;
};

/// The obstacles of `urdf` (the URDF's XML) for `robot`: one per `<collision>` of each chosen link,
/// in link-name order, named `<link>/<index>` (`<link>` alone when it has one), in the link's
/// frame at the collision's `<origin>`: a URDF box (`size` full lengths), cylinder (along z,
/// `length` full) and sphere as the scene's box, cylinder and sphere, grown by `padding`; a
/// `<mesh>` as a mesh obstacle, loaded from its filename at its scale (mesh_resource.h), not grown.
/// `warnings` says what is left out: a `<collision>` without geometry, a mesh's zero-area
/// triangles, a padding a mesh does not take. Errors name `field`'s keys: a URDF that does not
/// parse (field/description), a mesh that does not load (field/description, with the link, the
/// filename and the reason), a chosen link the URDF does not have or without a `<collision>`
/// (field/links[i]).
core::Expected<std::vector<core::ObstacleSpec>> robotObstacles(const std::string& urdf,
                                                               const RobotLinks& robot,
                                                               const std::string& field,
                                                               std::vector<std::string>& warnings);

}  // namespace collision_response
