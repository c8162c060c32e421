// Triangle meshes: what is refused or left out at build, the hierarchy's answers against brute
// force over every triangle, and a tessellated flat floor answering as the plane it tessellates
// (no internal edge is ever met: the same instants to the ulp, a flat normal across the edges).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "collision_response/core/triangle_mesh.h"
#include "geometry/finite_shapes.h"
#include "geometry/narrow_phase.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using LD = long double;

const auto kNoApproach = [] { return V(V::Zero()); };

double ulps(double value, LD reference) {
  const double r = static_cast<double>(reference);
  const double ulp = std::nextafter(std::abs(r), INFINITY) - std::abs(r);
  return static_cast<double>(std::abs(static_cast<LD>(value) - reference) / ulp);
}

std::optional<double> thrown(const Shape& shape, const V& centre, const V& velocity, double radius,
                             const V& acceleration = V::Zero(), double horizon = 10.0) {
  BallMotion ball{centre, radius, velocity, acceleration};
  PlacedShape placed;
  placed.shape = shape;
  return firstContact(ball, placed, V::Zero(), V::Zero(), !acceleration.isZero(), horizon);
}

TEST(TriangleMesh, BadInputIsNamedAndZeroAreaTrianglesAreLeftOut) {
  const std::vector<V> square{V(0, 0, 0), V(1, 0, 0), V(1, 1, 0), V(0, 1, 0)};
  auto out_of_range = TriangleMesh::build(square, {{0, 1, 2}, {0, 2, 7}}, "obstacles[3]");
  ASSERT_FALSE(out_of_range);
  EXPECT_EQ(out_of_range.error().message(), "obstacles[3] triangle 1: names vertex 7 of 4");
  std::vector<V> with_nan = square;
  with_nan[2].y() = NAN;
  auto not_finite = TriangleMesh::build(with_nan, {{0, 1, 2}}, "obstacles[3]");
  ASSERT_FALSE(not_finite);
  EXPECT_EQ(not_finite.error().field, "obstacles[3] vertex 2.y");
  // A repeated vertex and three on a line: no area, left out and named; the rest kept.
  std::vector<std::size_t> zero_area;
  const std::vector<V> line{V(0, 0, 0), V(1, 0, 0), V(2, 0, 0), V(0, 1, 0)};
  auto kept = TriangleMesh::build(line, {{0, 1, 1}, {0, 1, 2}, {0, 1, 3}}, "m", &zero_area);
  ASSERT_TRUE(kept);
  EXPECT_EQ((*kept)->triangles().size(), 1u);
  EXPECT_EQ(zero_area, (std::vector<std::size_t>{0, 1}));
  auto nothing = TriangleMesh::build(line, {{0, 1, 2}}, "obstacles[0]");
  ASSERT_FALSE(nothing);
  EXPECT_EQ(nothing.error().message(),
            "obstacles[0]: has no triangle of nonzero area (1 triangles, 4 vertices)");
}

// The hierarchy's nearest point and overlapping triangles against every triangle looked at: a
// bumpy floor of 20,000 triangles, 200 random points and boxes.
TEST(TriangleMesh, HierarchyAnswersAsBruteForce) {
  const int n = 100;
  std::vector<V> vertices;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      vertices.emplace_back(0.01 * i, 0.01 * j, 0.003 * std::sin(0.7 * i) * std::cos(0.3 * j));
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
  const auto mesh = *TriangleMesh::build(vertices, triangles, "bumpy");
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(-0.2, 1.2);
  int looked_at = 0;
  for (int k = 0; k <= 200; ++k) {
    const V p(unit(random), unit(random), 0.3 * unit(random));
    double least = INFINITY;
    // The brute force for the first 20 points (each looks at all 20,000 triangles).
    for (const TriangleMesh::Triangle& t : mesh->triangles()) {
      if (k >= 20) break;
      const V& a = vertices[t[0]];
      const V& b = vertices[t[1]];
      const V& c = vertices[t[2]];
      const V normal = (b - a).cross(c - a).normalized();
      const V q = p - normal.dot(p - a) * normal;
      const bool over = normal.dot((b - a).cross(q - a)) >= 0 &&
                        normal.dot((c - b).cross(q - b)) >= 0 &&
                        normal.dot((a - c).cross(q - c)) >= 0;
      const auto to_segment = [&](const V& u, const V& w) {
        const double s = std::clamp((p - u).dot(w - u) / (w - u).squaredNorm(), 0.0, 1.0);
        return (p - (u + s * (w - u))).norm();
      };
      const double d = over ? std::abs(normal.dot(p - a))
                            : std::min({to_segment(a, b), to_segment(b, c), to_segment(c, a)});
      least = std::min(least, d);
    }
    TriangleMesh::visitedCount() = 0;
    const TriangleMesh::NearestPoint near = mesh->nearest(p);
    looked_at += static_cast<int>(TriangleMesh::visitedCount());
    if (k < 20) {
      EXPECT_NEAR(near.distance, least, 1e-15) << k;
    }
    // Overlapping boxes: every triangle whose bounds meet the box, and no other.
    const V low = p - V(0.02, 0.02, 0.5), high = p + V(0.03, 0.01, 0.5);
    std::vector<std::uint32_t> found;
    mesh->overlapping(low, high, found);
    std::size_t expected = 0;
    for (std::uint32_t t = 0; t < mesh->triangles().size(); ++t) {
      V tl = V::Constant(INFINITY), th = -tl;
      for (const std::uint32_t v : mesh->triangles()[t]) {
        tl = tl.cwiseMin(vertices[v]);
        th = th.cwiseMax(vertices[v]);
      }
      const bool meets = (tl.array() <= high.array()).all() && (th.array() >= low.array()).all();
      expected += meets;
      if (meets) {
        EXPECT_NE(std::find(found.begin(), found.end(), t), found.end()) << k << " " << t;
      }
    }
    // Leaves of up to four triangles come whole: at most a few more than overlap.
    EXPECT_LE(found.size(), 4 * expected + 8) << k;
  }
  // O(log n) boxes a nearest-point query, not n: 20,000 triangles, a few dozen boxes.
  EXPECT_LT(looked_at / 201, 400);
}

// A floor of 8 x 8 squares (128 triangles) answers as the plane z = 0: dropped over a face, an
// internal edge (the squares' sides and the diagonals) and an internal vertex, straight or under
// gravity, at the plane's instant to a few ulps, with the plane's normal and no curvature.
TEST(TriangleMesh, ATessellatedFloorAnswersAsItsPlane) {
  const Mesh floor{scene_builders::floorMesh(8, 2.0)};
  const double r = 0.1, z0 = 1.3, u = 2.0, g = 9.81;
  const double step = 2.0 / 8;
  for (const V& over : {V(0.1, 0.05, 0), V(step, 0.1, 0), V(0.1, step, 0), V(0.1, 0.1, 0),
                        V(step, step, 0), V(0, 0, 0)}) {
    const auto straight = thrown(floor, over + V(0, 0, z0), V(0.3, -0.2, -u), r);
    ASSERT_TRUE(straight);
    EXPECT_LE(ulps(*straight, (LD(z0) - LD(r)) / LD(u)), 2) << over.transpose();
    const auto falling = thrown(floor, over + V(0, 0, z0), V::Zero(), r, V(0, 0, -g));
    ASSERT_TRUE(falling);
    EXPECT_LE(ulps(*falling, std::sqrt(2 * (LD(z0) - LD(r)) / LD(g))), 4) << over.transpose();
    PlacedShape placed;
    placed.shape = floor;
    const ContactGeometry touch = contactGeometry(over + V(0, 0, r), r, placed, 1e-9, kNoApproach);
    EXPECT_EQ(touch.normal, V(0, 0, -1)) << over.transpose();
    EXPECT_EQ(touch.gap, 0.0) << over.transpose();
    EXPECT_TRUE(touch.flat()) << over.transpose();
  }
  // Rolling along it at the contact distance, across every internal edge: no contact begins (a
  // plane's answer: touching, not approaching), where an edge tested alone would be hit.
  EXPECT_FALSE(thrown(floor, V(-0.9, -0.37, r), V(1.0, 0.35, 0), r, V::Zero(), 1.5));
  // Its outer edge is a real edge: a ball sliding towards it from beside the floor, its centre
  // dz above the floor's plane, meets the edge's cylinder at x = 1 + sqrt(r^2 - dz^2).
  const double dz = 0.06;
  const auto rim = thrown(floor, V(1.5, 0.2, dz), V(-2.0, 0, 0), r);
  ASSERT_TRUE(rim);
  EXPECT_LE(ulps(*rim, (0.5L - std::sqrt(LD(r) * LD(r) - LD(dz) * LD(dz))) / 2), 4);
}

// An STL file repeats each vertex in every triangle that has it: the mesh joins vertices at the
// same position, so that the floor's internal edges are still shared, and still not there.
TEST(TriangleMesh, ATriangleSoupFloorIsJoinedAtItsVertices) {
  const auto joined = scene_builders::floorMesh(6, 2.0);
  std::vector<V> soup_vertices;
  std::vector<TriangleMesh::Triangle> soup;
  for (const TriangleMesh::Triangle& t : joined->triangles()) {
    const auto next = static_cast<std::uint32_t>(soup_vertices.size());
    for (const std::uint32_t v : t) soup_vertices.push_back(joined->vertices()[v]);
    soup.push_back({next, next + 1, next + 2});
  }
  const auto built = TriangleMesh::build(soup_vertices, soup, "soup");
  ASSERT_TRUE(built);
  const Mesh floor{*built};
  // 6 x 6 squares of two triangles: of the edges, only the 4 x 6 on the outline are there.
  std::set<std::uint32_t> reachable;
  for (std::uint32_t t = 0; t < (*built)->triangles().size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if ((*built)->edgeOf(t, k).reachable) reachable.insert((*built)->edgeIndex(t, k));
    }
  }
  EXPECT_EQ(reachable.size(), 24u);
  const double r = 0.1;
  EXPECT_FALSE(thrown(floor, V(-0.9, -0.37, r), V(1.0, 0.35, 0), r, V::Zero(), 1.5));
}

// The cube's edge and corner as features: the normal from the nearest point to the centre,
// continuous from the face across the edge, turning at the centre's distance from the edge.
TEST(TriangleMesh, ACubesEdgeAndCornerTurnTheNormal) {
  PlacedShape cube;
  cube.shape = Mesh{scene_builders::cubeMesh(V(0.5, 0.5, 0.5))};
  const double r = 0.1;
  const ContactGeometry edge =
      contactGeometry(V(0.5 + 0.06, 0.1, 0.5 + 0.08), r, cube, 1e-9, kNoApproach);
  EXPECT_NEAR((edge.normal - V(-0.6, 0, -0.8)).norm(), 0, 1e-15);
  EXPECT_NEAR(edge.curvature, 10.0, 1e-12);
  EXPECT_NEAR(std::abs(edge.turning_axis.y()), 1.0, 1e-15);
  const ContactGeometry corner =
      contactGeometry(V(0.5, 0.5, 0.5) + V(1, 2, 2) * (0.1 / 3), r, cube, 1e-9, kNoApproach);
  EXPECT_NEAR((corner.normal + V(1, 2, 2) / 3).norm(), 0, 1e-15);
  EXPECT_NEAR(corner.gap, 0.0, 1e-16);
  EXPECT_NEAR(corner.curvature, 10.0, 1e-12);
  // Inside the cube: a depth, the normal the nearest face's.
  const ContactGeometry inside = contactGeometry(V(0.1, 0.0, 0.45), r, cube, 1e-9, kNoApproach);
  EXPECT_EQ(inside.normal, V(0, 0, -1));
  EXPECT_NEAR(inside.gap, -0.05 - r, 1e-15);
}

}  // namespace
}  // namespace collision_response::core
