#include "collision_response/ros/mesh_resource.h"

#include <geometric_shapes/mesh_operations.h>
#include <geometric_shapes/shapes.h>
#include <resource_retriever/retriever.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "collision_response/ros/parameters.h"

namespace collision_response {

core::Expected<std::shared_ptr<const core::TriangleMesh>> loadMeshResource(
    const std::string& resource, const Eigen::Vector3d& scale, const std::string& field,
    std::vector<std::string>& warnings) {
  for (int i = 0; i < 3; ++i) {
    if (!(std::isfinite(scale[i]) && scale[i] > 0)) {
      std::ostringstream got;
      got << scale[i];
      return core::Error{
          indexKey(joinKey(field, "scale"), static_cast<std::size_t>(i)),
          "must be finite and > 0 (the mesh's size along its own axis), got " + got.str()};
    }
  }
  const std::string resource_field = joinKey(field, "resource");
  if (resource.empty())
    return core::Error{resource_field, "is required (a package:// or file:// address)"};
  resource_retriever::MemoryResource memory;
  try {
    memory = resource_retriever::Retriever().get(resource);
  } catch (const resource_retriever::Exception& error) {
    return core::Error{resource_field, "'" + resource + "' does not load: " + error.what()};
  }
  if (memory.size == 0) return core::Error{resource_field, "'" + resource + "' is empty"};
  // geometric_shapes hands the bytes to assimp, which takes the format from the name's extension.
  const std::unique_ptr<shapes::Mesh> loaded(shapes::createMeshFromBinary(
      reinterpret_cast<const char*>(memory.data.get()), memory.size, scale, resource));
  if (!loaded || loaded->triangle_count == 0) {
    return core::Error{resource_field, "'" + resource +
                                           "' is not a mesh assimp reads (STL, COLLADA, OBJ, ...)"
                                           " or has no triangle; assimp's reason is in the log"};
  }
  std::vector<Eigen::Vector3d> vertices(loaded->vertex_count);
  for (unsigned int v = 0; v < loaded->vertex_count; ++v) {
    vertices[v] = Eigen::Vector3d(loaded->vertices[3 * v], loaded->vertices[3 * v + 1],
                                  loaded->vertices[3 * v + 2]);
  }
  std::vector<core::TriangleMesh::Triangle> triangles(loaded->triangle_count);
  for (unsigned int t = 0; t < loaded->triangle_count; ++t) {
    triangles[t] = {loaded->triangles[3 * t], loaded->triangles[3 * t + 1],
                    loaded->triangles[3 * t + 2]};
  }
  std::vector<std::size_t> zero_area;
  auto mesh = core::TriangleMesh::build(vertices, triangles, resource_field + " '" + resource + "'",
                                        &zero_area);
  if (!mesh) return mesh.error();
  if (!zero_area.empty()) {
    std::ostringstream list;
    const std::size_t shown = std::min<std::size_t>(zero_area.size(), 10);
    for (std::size_t i = 0; i < shown; ++i) list << (i ? ", " : "") << zero_area[i];
    if (shown < zero_area.size()) list << ", ... (" << zero_area.size() << " in all)";
    warnings.push_back(resource_field + " '" + resource + "': " + std::to_string(zero_area.size()) +
                       " triangle(s) of zero area left out (no face, no outside): " + list.str());
  }
  return mesh;
}

}  // namespace collision_response
