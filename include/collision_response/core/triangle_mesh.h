// A triangle mesh obstacle (scene type `mesh`): its triangles in the mesh's own frame under a
// bounding-volume hierarchy of axis-aligned boxes, so that a query near a few of 1,000,000
// triangles looks at O(log n) of them.
//
// A closed mesh (every edge shared by exactly two triangles whose winding agrees across it, run
// in opposite directions) bounds the solid it encloses, on the side its triangles' normals point
// away from (counter-clockwise seen from outside, the convention of STL and COLLADA). Any other
// mesh (a floor, a box without a lid, one with a crack or a triangle wound the other way) is
// open: a surface of no thickness with no inside, which a ball meets from either side; nothing
// beside, below or above it is inside it (the sign of a pseudo-normal tells inside from outside
// only on a closed, consistently wound surface: Baerentzen and Aanaes 2005). A ball against a
// mesh is a ball against its features grown by the ball's radius: faces are planes, edges
// cylinders, vertices spheres. Only the features a ball can touch first are kept: an edge
// between two faces in one plane lies inside the grown solid, and so, on a closed mesh, does an
// edge in a groove (concave: on an open mesh the groove's other side is convex and its edge is
// kept), and a vertex all of whose edges do; that is why a ball rolling across a tessellated
// flat floor never meets an internal edge (the "ghost collisions" of engines that test each
// triangle alone).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"

namespace collision_response::core {

class TriangleMesh {
 public:
  using Triangle = std::array<std::uint32_t, 3>;

  /// The part of a triangle a point is nearest: its face, its edge k (from vertex k to vertex
  /// k + 1 mod 3) or its vertex k.
  enum class Part { kFace, kEdge, kVertex };
  struct NearestPoint {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< on the triangle
    double distance = 0.0;                            ///< m, unsigned
    std::uint32_t triangle = 0;
    Part part = Part::kFace;
    int index = 0;  ///< the edge's or the vertex's, 0..2
  };
  struct Edge {
    std::uint32_t from = 0, to = 0;  ///< vertex indices
    /// The sum of the unit normals of the faces that share it (the angle-weighted pseudo-normal
    /// of Baerentzen and Aanaes, "Signed distance computation using the angle weighted
    /// pseudonormal", IEEE TVCG 11(3), 2005): which side of it is outside.
    Eigen::Vector3d pseudo_normal = Eigen::Vector3d::Zero();
    /// Not between faces in one plane, nor (on a closed mesh) in a groove.
    bool reachable = true;
  };

  /// Builds the mesh from its vertices (m, the mesh's frame) and triangles (vertex indices,
  /// counter-clockwise seen from outside). Refused by name (`field`): a non-finite vertex, an
  /// index out of range, no triangle left. Vertices at the same position are joined (an STL file
  /// repeats them in every triangle), so that neighbouring triangles share their edge. Triangles of
  /// zero area (collinear or repeated vertices) have no face and no outside: they are left out, and
  /// their indices are appended to `zero_area` for the caller to name.
  static Expected<std::shared_ptr<const TriangleMesh>> build(
      const std::vector<Eigen::Vector3d>& vertices, const std::vector<Triangle>& triangles,
      const std::string& field, std::vector<std::size_t>* zero_area = nullptr);

  const std::vector<Eigen::Vector3d>& vertices() const { return vertices_; }
  /// The triangles kept (those of nonzero area), in the hierarchy's order.
  const std::vector<Triangle>& triangles() const { return triangles_; }
  const Eigen::Vector3d& normal(std::uint32_t triangle) const { return normals_[triangle]; }
  const Edge& edgeOf(std::uint32_t triangle, int k) const {
    return edges_[triangle_edges_[triangle][k]];
  }
  std::uint32_t edgeIndex(std::uint32_t triangle, int k) const {
    return triangle_edges_[triangle][k];
  }
  const Edge& edge(std::uint32_t index) const { return edges_[index]; }
  /// The angle-weighted sum of the unit normals of the faces around a vertex (Baerentzen and
  /// Aanaes), and whether a ball can touch it first.
  const Eigen::Vector3d& vertexPseudoNormal(std::uint32_t vertex) const {
    return vertex_normals_[vertex];
  }
  bool vertexReachable(std::uint32_t vertex) const { return vertex_reachable_[vertex] != 0; }

  /// Whether every edge is shared by exactly two triangles run along it in opposite directions
  /// (their winding agrees): the mesh then encloses a solid. Otherwise it is a surface.
  bool closed() const { return closed_; }

  /// m: the radius of the smallest sphere about the mesh's origin that holds it.
  double boundingRadius() const { return bounding_radius_; }

  /// The point of the triangles nearest `p`; branch and bound down the hierarchy.
  NearestPoint nearest(const Eigen::Vector3d& p) const;
  /// Appends every triangle whose bounding box overlaps [low, high].
  void overlapping(const Eigen::Vector3d& low, const Eigen::Vector3d& high,
                   std::vector<std::uint32_t>& out) const;
  /// How many of the hierarchy's boxes and triangles the last queries of this thread looked at
  /// (for the benchmark of the query's growth with the triangle count).
  static std::size_t& visitedCount();

 private:
  struct Node {
    Eigen::Vector3d low, high;
    std::uint32_t first = 0;  ///< leaf: first triangle; inner: the right child (left is next)
    std::uint32_t count = 0;  ///< leaf: triangle count; inner: 0
  };
  /// build's stages: the triangles of nonzero area, their vertices joined (an error names the
  /// triangle whose index is out of range); the hierarchy; the edges, whether the mesh is closed
  /// and whether each edge is reachable; the vertices' pseudo-normals, reachability and the
  /// bounding radius.
  Status keepFacedTriangles(const std::vector<Triangle>& triangles, const std::string& field,
                            std::vector<std::size_t>* zero_area);
  void buildHierarchy();
  void buildEdges();
  void buildVertices();
  std::uint32_t buildNode(std::uint32_t first, std::uint32_t count,
                          std::vector<Eigen::Vector3d>& centroids);

  std::vector<Eigen::Vector3d> vertices_;
  std::vector<Triangle> triangles_;
  std::vector<Eigen::Vector3d> normals_;
  std::vector<std::array<std::uint32_t, 3>> triangle_edges_;
  std::vector<Edge> edges_;
  std::vector<Eigen::Vector3d> vertex_normals_;
  std::vector<char> vertex_reachable_;
  std::vector<Node> nodes_;
  double bounding_radius_ = 0.0;
  bool closed_ = true;
};

}  // namespace collision_response::core
