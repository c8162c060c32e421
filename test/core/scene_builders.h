// The scene parts the core tests build again and again: a ball, a plane, a fixed sphere. Each
// sets only what it is given; the rest keeps BodySpec's and ObstacleSpec's defaults.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "collision_response/core/scene.h"
#include "collision_response/core/triangle_mesh.h"

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

/// Triangles listed as they come, each turned to face away from `inside` (a point of the solid).
inline std::shared_ptr<const TriangleMesh> facingOut(const std::vector<Eigen::Vector3d>& vertices,
                                                     std::vector<TriangleMesh::Triangle> triangles,
                                                     const Eigen::Vector3d& inside) {
  for (TriangleMesh::Triangle& t : triangles) {
    const Eigen::Vector3d& a = vertices[t[0]];
    const Eigen::Vector3d normal = (vertices[t[1]] - a).cross(vertices[t[2]] - a);
    const Eigen::Vector3d centroid = (a + vertices[t[1]] + vertices[t[2]]) / 3;
    if (normal.dot(centroid - inside) < 0) std::swap(t[1], t[2]);
  }
  return *TriangleMesh::build(vertices, triangles, "mesh");
}

/// A box of half sizes `half` about the origin as 12 triangles (two a face, split along a
/// diagonal).
inline std::shared_ptr<const TriangleMesh> cubeMesh(const Eigen::Vector3d& half) {
  std::vector<Eigen::Vector3d> vertices;
  for (int i = 0; i < 8; ++i) {
    vertices.emplace_back((i & 1 ? 1 : -1) * half.x(), (i & 2 ? 1 : -1) * half.y(),
                          (i & 4 ? 1 : -1) * half.z());
  }
  // Each face's four corners in order around it: the vertices with bit `axis` = side.
  std::vector<TriangleMesh::Triangle> triangles;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = 1 << ((axis + 1) % 3), w = 1 << ((axis + 2) % 3);
    for (const int side : {0, 1 << axis}) {
      const std::uint32_t a = side, b = side | u, c = side | u | w, d = side | w;
      triangles.push_back({a, b, c});
      triangles.push_back({a, c, d});
    }
  }
  return facingOut(vertices, triangles, Eigen::Vector3d::Zero());
}

/// A flat floor z = 0 over [-side/2, side/2]^2 of n x n squares, each two triangles (2 n^2 in
/// all), facing up.
inline std::shared_ptr<const TriangleMesh> floorMesh(int n, double side) {
  std::vector<Eigen::Vector3d> vertices;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      vertices.emplace_back(side * (double(i) / n - 0.5), side * (double(j) / n - 0.5), 0.0);
    }
  }
  std::vector<TriangleMesh::Triangle> triangles;
  const auto at = [n](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return *TriangleMesh::build(vertices, triangles, "floor");
}

/// A mesh obstacle whose origin is at `centre`.
inline ObstacleSpec mesh(const std::string& id, std::shared_ptr<const TriangleMesh> triangles,
                         const Eigen::Vector3d& centre, const std::string& material) {
  ObstacleSpec obstacle;
  obstacle.id = id;
  obstacle.shape = ObstacleShape::kMesh;
  obstacle.mesh = std::move(triangles);
  obstacle.position = centre;
  obstacle.material = material;
  return obstacle;
}

}  // namespace collision_response::core::scene_builders
