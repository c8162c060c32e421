#include "collision_response/core/triangle_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "collision_response/core/validation.h"

namespace collision_response::core {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
/// Triangles a leaf of the hierarchy holds at most.
constexpr std::uint32_t kLeafSize = 4;

/// The squared distance from `p` to the box [low, high] (0 inside).
double boxDistance2(const Eigen::Vector3d& p, const Eigen::Vector3d& low,
                    const Eigen::Vector3d& high) {
  return (low - p).cwiseMax(p - high).cwiseMax(0.0).squaredNorm();
}

/// The point of triangle abc nearest p, and the part it is on: Ericson, "Real-Time Collision
/// Detection" (2005), section 5.1.5, its Voronoi regions tested in turn.
TriangleMesh::NearestPoint nearestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                             const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                             const Eigen::Vector3d& normal) {
  using Part = TriangleMesh::Part;
  TriangleMesh::NearestPoint result;
  const auto at = [&](const Eigen::Vector3d& point, Part part, int index) {
    result.point = point;
    result.part = part;
    result.index = index;
    return result;
  };
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return at(a, Part::kVertex, 0);
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return at(b, Part::kVertex, 1);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return at(a + (d1 / (d1 - d3)) * ab, Part::kEdge, 0);
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return at(c, Part::kVertex, 2);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return at(a + (d2 / (d2 - d6)) * ac, Part::kEdge, 2);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    return at(b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b), Part::kEdge, 1);
  }
  // Inside the face: along the normal from p (to the bit on an axis-aligned face).
  return at(p - normal.dot(ap) * normal, Part::kFace, 0);
}

}  // namespace

std::size_t& TriangleMesh::visitedCount() {
  thread_local std::size_t count = 0;
  return count;
}

namespace {

/// For each vertex, the first vertex at its position (an STL file repeats each vertex in every
/// triangle): joined, neighbouring triangles share their edges.
std::vector<std::uint32_t> firstAtSamePosition(const std::vector<Eigen::Vector3d>& vertices) {
  std::vector<std::uint32_t> order(vertices.size()), same(vertices.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) {
    const Eigen::Vector3d &p = vertices[i], &q = vertices[j];
    if (p.x() != q.x()) return p.x() < q.x();
    if (p.y() != q.y()) return p.y() < q.y();
    if (p.z() != q.z()) return p.z() < q.z();
    return i < j;
  });
  for (std::size_t i = 0; i < order.size(); ++i) {
    same[order[i]] =
        i > 0 && vertices[order[i]] == vertices[order[i - 1]] ? same[order[i - 1]] : order[i];
  }
  return same;
}

}  // namespace

Expected<std::shared_ptr<const TriangleMesh>> TriangleMesh::build(
    const std::vector<Eigen::Vector3d>& vertices, const std::vector<Triangle>& triangles,
    const std::string& field, std::vector<std::size_t>* zero_area) {
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    if (auto status = checkFinite(vertices[i], field + " vertex " + std::to_string(i)); !status) {
      return status.error();
    }
  }
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->vertices_ = vertices;
  if (auto status = mesh->keepFacedTriangles(triangles, field, zero_area); !status) {
    return status.error();
  }
  mesh->buildHierarchy();
  mesh->buildEdges();
  mesh->buildVertices();
  return std::shared_ptr<const TriangleMesh>(std::move(mesh));
}

Status TriangleMesh::keepFacedTriangles(const std::vector<Triangle>& triangles,
                                        const std::string& field,
                                        std::vector<std::size_t>* zero_area) {
  const std::vector<std::uint32_t> same = firstAtSamePosition(vertices_);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    Triangle triangle = triangles[t];
    for (std::uint32_t& v : triangle) {
      if (v >= vertices_.size()) {
        return Error{
            field + " triangle " + std::to_string(t),
            "names vertex " + std::to_string(v) + " of " + std::to_string(vertices_.size())};
      }
      v = same[v];
    }
    const Eigen::Vector3d& a = vertices_[triangle[0]];
    const Eigen::Vector3d ab = vertices_[triangle[1]] - a, ac = vertices_[triangle[2]] - a;
    const Eigen::Vector3d cross = ab.cross(ac);
    const double longest = std::max(ab.squaredNorm(), ac.squaredNorm());
    // Zero area up to the rounding of the cross product: collinear or repeated vertices.
    if (!(cross.norm() > 16 * kEps * longest)) {
      if (zero_area) zero_area->push_back(t);
      continue;
    }
    triangles_.push_back(triangle);
    normals_.push_back(cross.stableNormalized());
  }
  if (triangles_.empty()) {
    return Error{field, "has no triangle of nonzero area (" + std::to_string(triangles.size()) +
                            " triangles, " + std::to_string(vertices_.size()) + " vertices)"};
  }
  return Ok{};
}

void TriangleMesh::buildHierarchy() {
  // Median splits along the widest spread of the triangles' centroids.
  std::vector<Eigen::Vector3d> centroids;
  centroids.reserve(triangles_.size());
  for (const Triangle& t : triangles_) {
    centroids.push_back((vertices_[t[0]] + vertices_[t[1]] + vertices_[t[2]]) / 3.0);
  }
  nodes_.reserve(2 * triangles_.size() / kLeafSize + 1);
  buildNode(0, static_cast<std::uint32_t>(triangles_.size()), centroids);
}

void TriangleMesh::buildEdges() {
  // Each pair of vertices once, with the faces that share it.
  struct HalfEdge {
    std::uint32_t low, high, triangle;
    int k;
  };
  std::vector<HalfEdge> half_edges;
  half_edges.reserve(3 * triangles_.size());
  for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = triangles_[t][k], v = triangles_[t][(k + 1) % 3];
      half_edges.push_back({std::min(u, v), std::max(u, v), t, k});
    }
  }
  std::sort(half_edges.begin(), half_edges.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.low != y.low ? x.low < y.low : x.high < y.high;
  });
  triangle_edges_.resize(triangles_.size());
  // Per edge: between two faces in one plane (flat), or in a groove seen from the faces' outer
  // side; whether it is reachable depends on whether the whole mesh is closed, known at the end.
  std::vector<char> flat, groove;
  closed_ = true;
  for (std::size_t i = 0; i < half_edges.size();) {
    std::size_t j = i;
    while (j < half_edges.size() && half_edges[j].low == half_edges[i].low &&
           half_edges[j].high == half_edges[i].high) {
      ++j;
    }
    Edge edge;
    edge.from = half_edges[i].low;
    edge.to = half_edges[i].high;
    const auto index = static_cast<std::uint32_t>(edges_.size());
    for (std::size_t h = i; h < j; ++h) {
      edge.pseudo_normal += normals_[half_edges[h].triangle];
      triangle_edges_[half_edges[h].triangle][half_edges[h].k] = index;
    }
    bool is_flat = false, is_groove = false, opposite = false;
    if (j - i == 2) {
      // Two faces. Their winding agrees when they run the edge in opposite directions; then they
      // lie in one plane when their normals are one, and form a groove when the second face's
      // far vertex rises above the first face's plane. Where the winding disagrees they lie in
      // one plane when their normals are opposite. (Faces back to back, a knife's edge, rise 0
      // with opposite normals and agreeing winding: neither.)
      const HalfEdge& first = half_edges[i];
      const HalfEdge& second = half_edges[i + 1];
      const Triangle& t1 = triangles_[first.triangle];
      const Triangle& t2 = triangles_[second.triangle];
      opposite = t1[first.k] != t2[second.k];
      const Eigen::Vector3d& n1 = normals_[first.triangle];
      const Eigen::Vector3d& n2 = normals_[second.triangle];
      const Eigen::Vector3d& far = vertices_[t2[(second.k + 2) % 3]];
      const Eigen::Vector3d& on_edge = vertices_[edge.from];
      const double rise = n1.dot(far - on_edge);
      is_flat = opposite ? (n1 - n2).norm() <= 1e-12 : (n1 + n2).norm() <= 1e-12;
      is_groove = opposite && !is_flat && rise > 1e-12 * (far - on_edge).norm();
    }
    if (!(j - i == 2 && opposite)) closed_ = false;
    flat.push_back(is_flat);
    groove.push_back(is_groove);
    edges_.push_back(edge);
    i = j;
  }
  // A groove's edge lies inside the grown solid of a closed mesh; on an open one (a surface) the
  // groove's other side is a convex fold, whose edge a ball can touch first.
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    edges_[e].reachable = !(flat[e] || (closed_ && groove[e]));
  }
}

void TriangleMesh::buildVertices() {
  // Pseudo-normals weighted by each face's angle there; reachable when one of their edges is.
  vertex_normals_.assign(vertices_.size(), Eigen::Vector3d::Zero());
  vertex_reachable_.assign(vertices_.size(), 0);
  for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& v = vertices_[triangles_[t][k]];
      const Eigen::Vector3d to_next = vertices_[triangles_[t][(k + 1) % 3]] - v;
      const Eigen::Vector3d to_previous = vertices_[triangles_[t][(k + 2) % 3]] - v;
      const double angle = std::atan2(to_next.cross(to_previous).norm(), to_next.dot(to_previous));
      vertex_normals_[triangles_[t][k]] += angle * normals_[t];
    }
  }
  for (const Edge& edge : edges_) {
    if (edge.reachable) vertex_reachable_[edge.from] = vertex_reachable_[edge.to] = 1;
  }
  for (const Triangle& t : triangles_) {
    for (const std::uint32_t v : t) {
      bounding_radius_ = std::max(bounding_radius_, vertices_[v].stableNorm());
    }
  }
}

std::uint32_t TriangleMesh::buildNode(std::uint32_t first, std::uint32_t count,
                                      std::vector<Eigen::Vector3d>& centroids) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d low = Eigen::Vector3d::Constant(INFINITY);
  Eigen::Vector3d high = -low;
  Eigen::Vector3d centre_low = low, centre_high = high;
  for (std::uint32_t t = first; t < first + count; ++t) {
    for (const std::uint32_t v : triangles_[t]) {
      low = low.cwiseMin(vertices_[v]);
      high = high.cwiseMax(vertices_[v]);
    }
    centre_low = centre_low.cwiseMin(centroids[t]);
    centre_high = centre_high.cwiseMax(centroids[t]);
  }
  nodes_[index].low = low;
  nodes_[index].high = high;
  if (count <= kLeafSize) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  int axis = 0;
  (centre_high - centre_low).maxCoeff(&axis);
  // Sort this node's triangles (with their normals and centroids) by the centroid's median.
  std::vector<std::uint32_t> order(count);
  std::iota(order.begin(), order.end(), first);
  const std::uint32_t half = count / 2;
  std::nth_element(
      order.begin(), order.begin() + half, order.end(),
      [&](std::uint32_t x, std::uint32_t y) { return centroids[x][axis] < centroids[y][axis]; });
  std::vector<Triangle> triangles(count);
  std::vector<Eigen::Vector3d> normals(count), centres(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    triangles[i] = triangles_[order[i]];
    normals[i] = normals_[order[i]];
    centres[i] = centroids[order[i]];
  }
  std::copy(triangles.begin(), triangles.end(), triangles_.begin() + first);
  std::copy(normals.begin(), normals.end(), normals_.begin() + first);
  std::copy(centres.begin(), centres.end(), centroids.begin() + first);
  buildNode(first, half, centroids);
  const std::uint32_t right = buildNode(first + half, count - half, centroids);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

TriangleMesh::NearestPoint TriangleMesh::nearest(const Eigen::Vector3d& p) const {
  NearestPoint best;
  double best2 = INFINITY;
  std::size_t& visited = visitedCount();
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    ++visited;
    if (!(boxDistance2(p, node.low, node.high) < best2)) continue;
    if (node.count > 0) {
      for (std::uint32_t t = node.first; t < node.first + node.count; ++t) {
        const Triangle& tri = triangles_[t];
        NearestPoint candidate = nearestOnTriangle(p, vertices_[tri[0]], vertices_[tri[1]],
                                                   vertices_[tri[2]], normals_[t]);
        const double d2 = (p - candidate.point).squaredNorm();
        if (d2 < best2) {
          best2 = d2;
          best = candidate;
          best.triangle = t;
        }
      }
      continue;
    }
    // The nearer child last on the stack: looked at first.
    const std::uint32_t left = static_cast<std::uint32_t>(&node - nodes_.data()) + 1;
    const std::uint32_t right = node.first;
    const double to_left = boxDistance2(p, nodes_[left].low, nodes_[left].high);
    const double to_right = boxDistance2(p, nodes_[right].low, nodes_[right].high);
    // (Never full: median splits of at most 2^32 triangles nest at most 32 deep.)
    if (to_left < to_right) {
      stack[top++] = right;
      stack[top++] = left;
    } else {
      stack[top++] = left;
      stack[top++] = right;
    }
  }
  // The distance itself, scaled by the largest component (no overflow at 1e200 m).
  const Eigen::Vector3d offset = p - best.point;
  const double largest = offset.lpNorm<Eigen::Infinity>();
  best.distance = largest == 0 ? 0.0 : largest * (offset / largest).norm();
  return best;
}

void TriangleMesh::overlapping(const Eigen::Vector3d& low, const Eigen::Vector3d& high,
                               std::vector<std::uint32_t>& out) const {
  std::size_t& visited = visitedCount();
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::uint32_t index = stack[--top];
    const Node& node = nodes_[index];
    ++visited;
    if ((node.low.array() > high.array()).any() || (node.high.array() < low.array()).any()) {
      continue;
    }
    if (node.count > 0) {
      for (std::uint32_t t = node.first; t < node.first + node.count; ++t) out.push_back(t);
      continue;
    }
    stack[top++] = node.first;
    stack[top++] = index + 1;
  }
}

}  // namespace collision_response::core
