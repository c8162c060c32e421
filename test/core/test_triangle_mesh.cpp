// Triangle meshes: what is refused or left out at build, the hierarchy's answers against brute
// force over every triangle, and a tessellated flat floor answering as the plane it tessellates
// (no internal edge is ever met: the same instants to the ulp, a flat normal across the edges).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/prediction.h"
#include "collision_response/core/scene.h"
#include "collision_response/core/triangle_mesh.h"
#include "geometry/finite_shapes.h"
#include "geometry/narrow_phase.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using LD = long double;
constexpr double kG = 9.81;

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

// Open meshes (issue 39): a mesh none of whose edges is open and whose winding agrees across
// every edge is closed and bounds the solid it encloses; any other is a surface, which nothing
// beside, below or above it is inside (its distance is the plain distance to its triangles, and a
// ball meets either side of it). Before, the sign of the nearest boundary edge's pseudo-normal
// put everything below an open floor's plane inside it, metres beside its triangles.

/// The open square [x0, x1] x [y0, y1] at height z as two triangles facing up, in the frame of
/// the obstacle (placed at the origin: the mesh's bounding sphere about it reaches the balls).
std::shared_ptr<const TriangleMesh> openSquare(double x0, double x1, double y0, double y1,
                                               double z) {
  const std::vector<V> corners{V(x0, y0, z), V(x1, y0, z), V(x1, y1, z), V(x0, y1, z)};
  return *TriangleMesh::build(corners, {{0, 1, 2}, {0, 2, 3}}, "open floor");
}

Scene droppedBeside(const std::shared_ptr<const TriangleMesh>& open_floor,
                    const std::vector<V>& drops, double r) {
  Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -kG);
  for (std::size_t i = 0; i < drops.size(); ++i) {
    scene.bodies.push_back(
        scene_builders::ball("ball_" + std::to_string(i), 0.057, r, "tennis_ball", drops[i]));
  }
  scene.obstacles = {scene_builders::plane("floor", V::UnitZ(), 0.0, "concrete"),
                     scene_builders::mesh("open", open_floor, V::Zero(), "concrete")};
  return scene;
}

/// Runs `monitor` on its own motion from `start` at 100 Hz to `end`: every impact.
std::vector<ImpactRecord> playAlone(ImpactMonitor& monitor, const std::vector<V>& start,
                                    double end) {
  std::vector<BodyStateSample> states;
  for (std::size_t i = 0; i < start.size(); ++i) {
    BodyStateSample sample;
    sample.body = i;
    sample.position = start[i];
    states.push_back(sample);
  }
  std::vector<ImpactRecord> impacts;
  monitor.step(0.0, states);
  const int steps = static_cast<int>(std::lround(end * 100));
  for (int k = 1; k <= steps; ++k) {
    const StepReport report = monitor.step(k / 100.0, {});
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
  }
  return impacts;
}

MonitorSettings ownMotion() {
  MonitorSettings settings;
  settings.body_timeout = 1e9;  // no states after the first: the monitor's own motion
  return settings;
}

TEST(TriangleMesh, OnlyAMeshClosedAtEveryEdgeIsClosed) {
  EXPECT_TRUE(scene_builders::cubeMesh(V(0.5, 0.5, 0.5))->closed());
  EXPECT_FALSE(scene_builders::floorMesh(8, 2.0)->closed());
  EXPECT_FALSE(openSquare(14, 16, -1, 1, 0.26)->closed());
  // The cube without its top (10 triangles): open.
  const auto cube = scene_builders::cubeMesh(V(0.5, 0.5, 0.5));
  std::vector<TriangleMesh::Triangle> no_top;
  for (std::uint32_t t = 0; t < cube->triangles().size(); ++t) {
    if (!(cube->normal(t).z() > 0.5)) no_top.push_back(cube->triangles()[t]);
  }
  ASSERT_EQ(no_top.size(), 10u);
  EXPECT_FALSE((*TriangleMesh::build(cube->vertices(), no_top, "box without a top"))->closed());
  // The cube with one triangle turned inside out: its winding disagrees across three edges.
  std::vector<TriangleMesh::Triangle> flipped = cube->triangles();
  std::swap(flipped[0][1], flipped[0][2]);
  EXPECT_FALSE((*TriangleMesh::build(cube->vertices(), flipped, "cube turned"))->closed());
}

// The open square's distance beside, below and above it: the plain distance to its triangles,
// the normal from the ball to their nearest point. A ball thrown up under it meets its back.
TEST(TriangleMesh, AnOpenMeshIsASurfaceWithNoInside) {
  PlacedShape placed;
  placed.shape = Mesh{openSquare(14, 16, -1, 1, 0.26)};
  const double r = 0.05;
  // Beside and below its plane, 1 m from its edge x = 14 across and 0.21 m down.
  const ContactGeometry beside = contactGeometry(V(13, 0.1, 0.05), r, placed, 1e-9, kNoApproach);
  const double d = std::sqrt(1.0 + 0.21 * 0.21);
  EXPECT_NEAR(beside.gap, d - r, 1e-15);
  EXPECT_NEAR((beside.normal - V(1, 0, 0.21) / d).norm(), 0, 1e-15);
  // Under its face, 0.16 m below it: 0.16 m away, the normal up into it.
  const ContactGeometry under = contactGeometry(V(15, 0.1, 0.1), r, placed, 1e-9, kNoApproach);
  EXPECT_NEAR(under.gap, 0.16 - r, 1e-15);
  EXPECT_EQ(under.normal, V(0, 0, 1));
  // Above it, as before.
  const ContactGeometry over = contactGeometry(V(15, 0.1, 0.36), r, placed, 1e-9, kNoApproach);
  EXPECT_NEAR(over.gap, 0.1 - r, 1e-15);
  EXPECT_EQ(over.normal, V(0, 0, -1));
  // Thrown up at 2 m/s from 0.1 m under it: it meets the face's back at (0.26 - r - 0.1) / 2.
  const auto up = thrown(placed.shape, V(15, 0.1, 0.1), V(0, 0, 2), r);
  ASSERT_TRUE(up);
  EXPECT_LE(ulps(*up, (LD(0.26) - LD(r) - LD(0.1)) / 2), 4);
  // Thrown sideways under it: it passes (0.16 m below the plane, r = 0.05).
  EXPECT_FALSE(thrown(placed.shape, V(13, 0.1, 0.1), V(2, 0, 0), r));
  // Beside it, falling from 1 m: nothing (before, it was 1 m inside once below z = 0.26).
  EXPECT_FALSE(thrown(placed.shape, V(13, 0.1, 1.0), V::Zero(), r, V(0, 0, -kG), 1.0));
}

// Issue 39: a 2 x 2 m open floor mesh (x in [14, 16], at z = 0.26 or 0.5) beside a floor plane;
// balls dropped from z0 = 1 at x = -5, 0.05, 3, 7 and 13 meet the plane under themselves at the
// ballistic instant sqrt(2 (z0 - r) / g) (0.44009 s; before, at 0.44257 s at (14.05, 0.1, 0): they
// were moved onto the mesh's boundary edge).
TEST(TriangleMesh, BallsDroppedBesideAnOpenFloorMeshMeetTheFloorUnderThem) {
  const double r = 0.05, z0 = 1.0;
  const double meets = static_cast<double>(std::sqrt(2 * (LD(z0) - LD(r)) / LD(kG)));
  for (const double height : {0.26, 0.5}) {
    std::vector<V> drops;
    for (const double x : {-5.0, 0.05, 3.0, 7.0, 13.0}) drops.emplace_back(x, 0.1, z0);
    const Scene scene = droppedBeside(openSquare(14, 16, -1, 1, height), drops, r);
    ImpactMonitor monitor(scene, ownMotion());
    const auto impacts = playAlone(monitor, drops, 0.5);
    for (std::size_t i = 0; i < drops.size(); ++i) {
      const auto first =
          std::find_if(impacts.begin(), impacts.end(),
                       [&](const ImpactRecord& impact) { return impact.body_a == i; });
      ASSERT_NE(first, impacts.end()) << "no impact at x = " << drops[i].x();
      ASSERT_TRUE(first->other_is_obstacle) << drops[i].x();
      EXPECT_EQ(monitor.obstacle(first->other).id, "floor") << drops[i].x();
      EXPECT_NEAR(first->time, meets, 1e-12) << drops[i].x() << " at z " << height;
      EXPECT_LE((first->contact_point - V(drops[i].x(), 0.1, 0)).norm(), 1e-12)
          << drops[i].x() << ": " << first->contact_point.transpose();
      EXPECT_NEAR(first->velocity_a_before.z(), -kG * meets, 1e-12) << drops[i].x();
      // And it stays over its own x.
      const auto end = monitor.predictedState(i, 0.5);
      EXPECT_EQ(end->first.x(), drops[i].x());
      EXPECT_EQ(end->first.y(), 0.1);
    }
  }
}

// A ball dropped onto a box 14 m from such a mesh (its top at 0.2 m, under the mesh's plane, and
// at 0.4 m, over it) meets the box's top at sqrt(2 (z0 - r - top) / g) (before: it passed through
// the box, or bounced off a phantom of the mesh at (14.05, 0.1, 0.26)).
TEST(TriangleMesh, ABallDroppedOnABoxBesideAnOpenMeshBouncesOffTheBox) {
  const double r = 0.05, z0 = 1.0;
  for (const double top : {0.2, 0.4}) {
    Scene scene = droppedBeside(openSquare(14, 16, -1, 1, 0.26), {V(0, 0.1, z0)}, r);
    scene.obstacles.push_back(
        scene_builders::box("box", V(0, 0.1, top - 0.1), V(0.4, 0.4, 0.2), "concrete"));
    ImpactMonitor monitor(scene, ownMotion());
    const auto impacts = playAlone(monitor, {V(0, 0.1, z0)}, 0.5);
    ASSERT_FALSE(impacts.empty()) << "top " << top;
    const double meets = static_cast<double>(std::sqrt(2 * (LD(z0) - LD(r) - LD(top)) / LD(kG)));
    ASSERT_TRUE(impacts[0].other_is_obstacle) << top;
    EXPECT_EQ(monitor.obstacle(impacts[0].other).id, "box") << top;
    EXPECT_NEAR(impacts[0].time, meets, 1e-12) << top;
    EXPECT_LE((impacts[0].contact_point - V(0, 0.1, top)).norm(), 1e-12)
        << impacts[0].contact_point.transpose();
    EXPECT_EQ(impacts[0].normal, V(0, 0, -1));
  }
}

// No start-up warning for balls resting on the floor beside an open mesh, under its plane
// (before: "starts 9.55 m inside" it); a ball inside a closed mesh is still warned of.
TEST(TriangleMesh, NoBallBesideAnOpenMeshStartsInsideIt) {
  const double r = 0.05;
  Scene scene = droppedBeside(openSquare(14, 16, -1, 1, 0.5),
                              {V(4.45, 0, r), V(10, 0, 0.3), V(13, 0.1, r), V(15, 0, 0.3)}, r);
  EXPECT_TRUE(bodiesStartingInside(scene).empty());
  scene.obstacles.push_back(scene_builders::mesh(
      "crate", scene_builders::cubeMesh(V(0.5, 0.5, 0.5)), V(-3, 0, 0.5), "concrete"));
  scene.bodies.push_back(scene_builders::ball("crated", 0.057, r, "tennis_ball", V(-3, 0, 0.6)));
  const auto warnings = bodiesStartingInside(scene);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("'crated'"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("starts 0.45 m inside obstacle 'crate'"), std::string::npos)
      << warnings[0];
}

// A ball rolling at v0 = 5 m/s (r = 0.05, friction and spin) off the edge x = 10 of an open
// 10 x 10 m floor mesh at z = 0 (its origin at its centre, (5, 0, 0)): as v0^2 > g r, the edge
// cannot hold it, and it flies from the edge on the parabola x = 8 + v0 t,
// z = r - g (t - 0.4)^2 / 2, as off the same floor as a box (before, the mesh pulled it back
// under itself: x 11 -> 8.8, z -58 m at 4 s, no impact), in the monitor and in predictImpacts.
TEST(TriangleMesh, ABallRollsOffAnOpenFloorMeshsEdgeAsOffABox) {
  const double r = 0.05, v0 = 5.0, horizon = 4.0;
  const V start(8, 0, r), velocity(v0, 0, 0), spin = V(0, 0, 1).cross(velocity) / r;
  const V lands(8 + v0 * horizon, 0, r - 0.5 * kG * (horizon - 0.4) * (horizon - 0.4));
  for (const bool as_box : {false, true}) {
    Scene scene;
    scene.effects.gravity = scene.effects.friction = scene.effects.spin = true;
    scene.gravity = V(0, 0, -kG);
    scene.bodies = {scene_builders::ball("ball", 0.057, r, "tennis_ball")};
    scene.obstacles = {
        as_box
            ? scene_builders::box("floor", V(5, 0, -0.5), V(10, 10, 1), "concrete")
            : scene_builders::mesh("floor", openSquare(-5, 5, -5, 5, 0), V(5, 0, 0), "concrete")};
    ImpactMonitor monitor(scene, ownMotion());
    BodyStateSample state;
    state.position = start;
    state.velocity = velocity;
    state.angular_velocity = spin;
    monitor.step(0.0, {state});
    std::size_t impacts = 0;
    for (int k = 1; k <= 400; ++k) impacts += monitor.step(k / 100.0, {}).impacts.size();
    EXPECT_EQ(impacts, 0u) << (as_box ? "box" : "mesh");
    const auto end = monitor.predictedState(0, horizon);
    EXPECT_LE((end->first - lands).norm(), 1e-9)
        << (as_box ? "box: " : "mesh: ") << end->first.transpose();

    PredictionRequest request;
    request.body = scene.bodies[0];
    request.state = state;
    request.horizon = horizon;
    request.max_impacts = 10;
    request.effects = scene.effects;
    request.sample_period = 0.1;  // the path at 10 Hz (without, it was right before too)
    const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
    ASSERT_TRUE(prediction.ok()) << prediction.error().message();
    EXPECT_TRUE(prediction->impacts.empty()) << (as_box ? "box" : "mesh");
    EXPECT_LE((prediction->final_state.position - lands).norm(), 1e-9)
        << (as_box ? "box: " : "mesh: ") << prediction->final_state.position.transpose();
    ASSERT_EQ(prediction->samples.size(), 41u);
    for (const BodyStateSample& sample : prediction->samples) {
      const double t = sample.time, fallen = std::max(0.0, t - 0.4);
      const V there(8 + v0 * t, 0, r - 0.5 * kG * fallen * fallen);
      EXPECT_LE((sample.position - there).norm(), 1e-9)
          << (as_box ? "box" : "mesh") << " at " << t << ": " << sample.position.transpose();
    }
  }
}

}  // namespace
}  // namespace collision_response::core
