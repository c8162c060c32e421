// A mesh obstacle's triangles from its resource (scene type `mesh`, a URDF <mesh>): loaded the
// way ROS loads meshes, through resource_retriever (package:// and file:// addresses) and
// geometric_shapes (assimp: STL, COLLADA, OBJ, ...), scaled along the mesh's own axes (README,
// "Obstacles").
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/triangle_mesh.h"

namespace collision_response {

/// The triangles of `resource`, each vertex scaled by `scale` (> 0 along every axis). Errors name
/// `field`'s keys with the address and the reason: a scale that is not positive and finite
/// (field/scale), a resource that does not load or does not parse as a mesh, a non-finite vertex,
/// no triangle of nonzero area (field/resource). Triangles of zero area are left out, and
/// `warnings` says which (the resource and their indices).
core::Expected<std::shared_ptr<const core::TriangleMesh>> loadMeshResource(
    const std::string& resource, const Eigen::Vector3d& scale, const std::string& field,
    std::vector<std::string>& warnings);

}  // namespace collision_response
