// A mesh obstacle's triangles from its resource (scene type `mesh`, a URDF <mesh>): a package://
// or file:// address of a regular file on this machine, read within a size limit (the scene's
// `max_mesh_bytes`), parsed as ROS parses meshes, by geometric_shapes (assimp: STL, COLLADA,
// OBJ, ...), and scaled along the mesh's own axes (README, "Obstacles").
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/triangle_mesh.h"

namespace collision_response {

/// The largest mesh file read, by default (the scene's `max_mesh_bytes`): 128 MiB, a binary STL
/// of 2.7 million triangles, about 1.8 GB at its peak as it is parsed and built (measured: 660 MB
/// for a binary STL of a million, 50 MB).
inline constexpr std::size_t kDefaultMaxMeshBytes = std::size_t{128} << 20;

/// The file a package:// or file:// address names: `package://<package>/<path>` is `<path>` in
/// the package's directory (as resource_retriever resolves it), `file://<path>` an absolute
/// path. Any other address (http://, a bare path, ...) is an error naming the scheme.
core::Expected<std::string> meshResourcePath(const std::string& resource);

/// The bytes of `path`: a regular file (not a device, a FIFO, a directory) of at most `max_bytes`,
/// before and while it is read (a file that grows past it is refused too). The reason on error
/// names the limit as the scene's max_mesh_bytes.
core::Expected<std::string> readMeshFile(const std::string& path, std::size_t max_bytes);

/// The triangles of `resource`, each vertex scaled by `scale` (> 0 along every axis). Errors name
/// `field`'s keys with the address and the reason: a scale that is not positive and finite, or
/// one under which the mesh's coordinates overflow or triangles of nonzero area lose their area
/// in doubles (field/scale[i], field/scale); an address of another scheme, a file that is not a
/// regular one or is larger than `max_bytes`, one that does not parse as a mesh, a non-finite
/// vertex, no triangle of nonzero area, a mesh that does not fit in memory once parsed
/// (field/resource). Triangles of zero area in the file are
/// left out, and `warnings` says which (the resource and their indices).
core::Expected<std::shared_ptr<const core::TriangleMesh>> loadMeshResource(
    const std::string& resource, const Eigen::Vector3d& scale, const std::string& field,
    std::vector<std::string>& warnings, std::size_t max_bytes = kDefaultMaxMeshBytes);

}  // namespace collision_response
