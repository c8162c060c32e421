// Boxes, cylinders and capsules: the certified polynomial roots, each feature of each shape hit
// head-on, obliquely and under gravity against closed forms evaluated in long double (to a few
// ulps of the instant), the contact geometry of each feature, and random throws against an
// independent reference (the distance to the shape by its own formula, advanced conservatively).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <vector>

#include "collision_response/core/monitor.h"
#include "geometry/finite_shapes.h"
#include "geometry/narrow_phase.h"
#include "geometry/polynomial_roots.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using LD = long double;

const auto kNoApproach = [] { return V(V::Zero()); };

/// |value - reference| in ulps of the reference (a double).
double ulps(double value, LD reference) {
  const double r = static_cast<double>(reference);
  const double ulp = std::nextafter(std::abs(r), INFINITY) - std::abs(r);
  return static_cast<double>(std::abs(static_cast<LD>(value) - reference) / ulp);
}

std::vector<PolynomialRoot> allRoots(const std::vector<LD>& p, double horizon) {
  std::vector<PolynomialRoot> roots;
  visitRoots(p, horizon, [&](const PolynomialRoot& root) {
    roots.push_back(root);
    return false;
  });
  return roots;
}

TEST(PolynomialRoots, SimpleRootsInOrderWithTheirDirection) {
  // (t - 0.3)(t - 0.7) = t^2 - t + 0.21: positive, falls through 0.3, rises through 0.7.
  const auto roots = allRoots({0.21L, -1.0L, 1.0L}, 1.0);
  ASSERT_EQ(roots.size(), 2u);
  EXPECT_TRUE(roots[0].simple);
  EXPECT_TRUE(roots[0].falling);
  EXPECT_NEAR(roots[0].time, 0.3, 1e-15);
  EXPECT_FALSE(roots[1].falling);
  EXPECT_NEAR(roots[1].time, 0.7, 1e-15);
  // On a horizon of 0.5 only the first.
  EXPECT_EQ(allRoots({0.21L, -1.0L, 1.0L}, 0.5).size(), 1u);
}

TEST(PolynomialRoots, EightRootsOfADegreeEightPolynomial) {
  // prod_k (t - k / 9), k = 1..8, expanded in long double: every root, in order.
  std::vector<LD> p = {1.0L};
  for (int k = 1; k <= 8; ++k) {
    std::vector<LD> next(p.size() + 1, 0.0L);
    for (std::size_t i = 0; i < p.size(); ++i) {
      next[i] -= p[i] * (k / 9.0L);
      next[i + 1] += p[i];
    }
    p = next;
  }
  const auto roots = allRoots(p, 1.0);
  ASSERT_EQ(roots.size(), 8u);
  for (int k = 1; k <= 8; ++k) {
    EXPECT_NEAR(roots[k - 1].time, k / 9.0, 1e-12) << k;
    EXPECT_EQ(roots[k - 1].falling, k % 2 == 1) << k;  // p(0) = prod(-k/9) > 0
  }
}

TEST(PolynomialRoots, ADoubleRootIsAGrazeAndAPositiveOneHasNone) {
  // (t - 0.5)^2: touches 0 without crossing.
  const auto touch = allRoots({0.25L, -1.0L, 1.0L}, 1.0);
  ASSERT_FALSE(touch.empty());
  EXPECT_FALSE(touch[0].simple);
  EXPECT_NEAR(touch[0].time, 0.5, 1e-7);  // a double root is known to the rounding's root
  // (t - 0.5)^2 + 1e-6: no root.
  EXPECT_TRUE(allRoots({0.25L + 1e-6L, -1.0L, 1.0L}, 1.0).empty());
  EXPECT_TRUE(allRoots({3.0L}, 1.0).empty());
}

/// The first contact of a ball thrown at `shape` placed at `pose` (moving at `shape_velocity`).
std::optional<double> thrown(const Shape& shape, const V& centre, const V& velocity, double radius,
                             const V& acceleration = V::Zero(), double horizon = 10.0,
                             const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity(),
                             const V& shape_velocity = V::Zero()) {
  BallMotion ball;
  ball.centre = centre;
  ball.radius = radius;
  ball.velocity = velocity;
  ball.acceleration = acceleration;
  PlacedShape placed;
  placed.shape = shape;
  placed.pose.transform = pose;
  placed.pose.velocity = shape_velocity;
  return firstContact(ball, placed, shape_velocity, V::Zero(), !acceleration.isZero(), horizon);
}

const Cuboid kBox{V(0.5, 0.25, 0.75)};
constexpr double kRadius = 0.1;
constexpr double kG = 9.81;
constexpr double kUlps = 4;

// The box's features, hit as a box and as a mesh of its 12 triangles (scene_builders::cubeMesh):
// the same closed forms, to the same few ulps (a mesh's axis-aligned faces have exact normals).
class BoxOrMeshCube : public ::testing::TestWithParam<bool> {
 protected:
  Shape box() const {
    if (!GetParam()) return kBox;
    static const Shape mesh = Mesh{scene_builders::cubeMesh(kBox.half_size)};
    return mesh;
  }
};
INSTANTIATE_TEST_SUITE_P(FiniteShapes, BoxOrMeshCube, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& param) {
                           return param.param ? "MeshCube" : "Box";
                         });

TEST_P(BoxOrMeshCube, BoxFaceHeadOnAndOblique) {
  // Towards the face z = 0.75 at 3 m/s from z = 2: (2 - 0.75 - 0.1) / 3.
  const LD head_on = (2.0L - 0.75L - LD(kRadius)) / 3.0L;
  const auto t = thrown(box(), V(0, 0, 2), V(0, 0, -3), kRadius);
  ASSERT_TRUE(t);
  EXPECT_LE(ulps(*t, head_on), kUlps);
  // Obliquely: the same instant, the point still on the face.
  const auto oblique = thrown(box(), V(-0.2, 0.1, 2), V(0.3, -0.1, -3), kRadius);
  ASSERT_TRUE(oblique);
  EXPECT_LE(ulps(*oblique, head_on), kUlps);
  // Towards the face x = -0.5 from x = -1.3 at 0.7 m/s.
  const auto side = thrown(box(), V(-1.3, 0.2, -0.6), V(0.7, 0, 0), kRadius);
  ASSERT_TRUE(side);
  EXPECT_LE(ulps(*side, (1.3L - 0.5L - LD(kRadius)) / 0.7L), kUlps);
}

TEST_P(BoxOrMeshCube, BoxEdgeAndCornerHeadOn) {
  // Along the diagonal towards the edge x = 0.5, z = 0.75: the centre's distance from the edge's
  // line is sqrt(2) (d - u t), in contact at r: t = (d - r / sqrt(2)) / u.
  const double d = 0.7, u = 1.3;
  const auto edge = thrown(box(), V(0.5 + d, 0.1, 0.75 + d), V(-u, 0, -u), kRadius);
  ASSERT_TRUE(edge);
  const LD dx = LD(0.5 + d) - 0.5L;  // the double's own offset
  EXPECT_LE(ulps(*edge, (dx - LD(kRadius) / std::sqrt(2.0L)) / LD(u)), kUlps);
  // Towards the corner (0.5, 0.25, 0.75) along (-1, -1, -1): sqrt(3) (d - u t) = r.
  const V corner(0.5, 0.25, 0.75);
  const auto hit = thrown(box(), corner + V(d, d, d), V(-u, -u, -u), kRadius);
  ASSERT_TRUE(hit);
  const LD offset = LD(0.25 + d) - 0.25L;  // the same in every axis? not quite: take each
  const LD ox = LD(0.5 + d) - 0.5L, oz = LD(0.75 + d) - 0.75L;
  ASSERT_EQ(ox, offset);
  ASSERT_EQ(oz, offset);
  EXPECT_LE(ulps(*hit, (offset - LD(kRadius) / std::sqrt(3.0L)) / LD(u)), kUlps);
}

TEST_P(BoxOrMeshCube, BoxFeaturesUnderGravity) {
  const V gravity(0, 0, -kG);
  const double top = 0.75, z0 = 1.9;
  // Dropped from rest onto the face: z0 - g t^2 / 2 = top + r.
  const auto face = thrown(box(), V(0.1, -0.05, z0), V::Zero(), kRadius, gravity);
  ASSERT_TRUE(face);
  EXPECT_LE(ulps(*face, std::sqrt(2 * (LD(z0) - LD(top) - LD(kRadius)) / LD(kG))), kUlps);
  // Dropped beside the edge x = 0.5 (delta < r outside): it meets the edge's cylinder where
  // (z - top)^2 + delta^2 = r^2.
  const double delta = 0.06;
  const auto edge = thrown(box(), V(0.5 + delta, 0.0, z0), V::Zero(), kRadius, gravity);
  ASSERT_TRUE(edge);
  const LD dx = LD(0.5 + delta) - 0.5L;
  const LD edge_height = LD(top) + std::sqrt(LD(kRadius) * LD(kRadius) - dx * dx);
  EXPECT_LE(ulps(*edge, std::sqrt(2 * (LD(z0) - edge_height) / LD(kG))), kUlps);
  // Beside the corner (0.5, 0.25): (z - top)^2 + dx^2 + dy^2 = r^2.
  const double dy_off = 0.05;
  const auto corner = thrown(box(), V(0.5 + delta, 0.25 + dy_off, z0), V::Zero(), kRadius, gravity);
  ASSERT_TRUE(corner);
  const LD dy = LD(0.25 + dy_off) - 0.25L;
  const LD corner_height = LD(top) + std::sqrt(LD(kRadius) * LD(kRadius) - dx * dx - dy * dy);
  EXPECT_LE(ulps(*corner, std::sqrt(2 * (LD(z0) - corner_height) / LD(kG))), kUlps);
  // Thrown up and over: it rises past the box's top and comes down on it (the second crossing
  // of the face's height is the entry).
  const auto lob = thrown(box(), V(-1.0, 0.0, 1.0), V(1.0, 0, 4.0), kRadius, gravity);
  ASSERT_TRUE(lob);
  // x reaches -0.5 - r at t = 0.4 with z = 1 + 1.6 - 0.7848 = 1.8152 > 0.85: over the edge; the
  // face z = 0.85: 1 + 4 t - 4.905 t^2 = 0.85, the later root.
  const LD a = LD(kG) / 2, b = -4.0L, c = LD(top) + LD(kRadius) - 1.0L;
  const LD later = (-b + std::sqrt(b * b - 4 * a * c)) / (2 * a);
  EXPECT_LE(ulps(*lob, later), kUlps);
}

TEST_P(BoxOrMeshCube, TurnedAndMovingBox) {
  // The box turned 90 degrees about x (its y half-size 0.25 now along z), moving up at 2 m/s
  // towards a ball at rest above it: 3 - 0.25 - r = 2 t.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI / 2, V::UnitX()).toRotationMatrix();
  const auto t = thrown(box(), V(0, 0, 3), V::Zero(), kRadius, V::Zero(), 10.0, pose, V(0, 0, 2));
  ASSERT_TRUE(t);
  // The turned half-size along z is 0.25 to within the rotation's rounding (cos 90 deg = 6e-17).
  EXPECT_NEAR(*t, (3 - 0.25 - kRadius) / 2, 1e-15);
}

TEST_P(BoxOrMeshCube, NoImpactWhereNoneBegins) {
  // Sliding past the face just clear of it: no entry.
  EXPECT_FALSE(thrown(box(), V(-2, 0, 0.75 + kRadius + 1e-9), V(1, 0, 0), kRadius));
  // At the very contact distance it grazes the edge x = -0.5 as it arrives over it (at 1.5 s):
  // a touch without approach, as two spheres that graze (timeOfImpactSpheres).
  const auto graze = thrown(box(), V(-2, 0, 0.75 + kRadius), V(1, 0, 0), kRadius);
  ASSERT_TRUE(graze);
  EXPECT_NEAR(*graze, 1.5, 1e-6);  // a double root: known to the square root of its rounding
  // Passing beside the box, clear of its edges.
  EXPECT_FALSE(thrown(box(), V(-2, 0.25 + kRadius + 1e-9, 2), V(1, 0, -1), kRadius));
  // Overlapping already: its impact was when it began.
  EXPECT_FALSE(thrown(box(), V(0, 0, 0.8), V(0, 0, -1), kRadius));
  // Touching and leaving.
  EXPECT_FALSE(thrown(box(), V(0, 0, 0.75 + kRadius), V(0, 0, 1), kRadius));
  // Touching and approaching: now.
  EXPECT_EQ(thrown(box(), V(0, 0, 0.75 + kRadius), V(0, 0, -1), kRadius), 0.0);
  // Too far for the horizon.
  EXPECT_FALSE(thrown(box(), V(0, 0, 2), V(0, 0, -1), kRadius, V::Zero(), 1.0));
}

TEST_P(BoxOrMeshCube, ExactlyOnAnEdgeTheFaceAndTheEdgeAgree) {
  // Falling straight down exactly over the edge x = 0.5: the face's and the edge's instants are
  // one, and the normal turns continuously from the face to the edge.
  const auto t = thrown(box(), V(0.5, 0, 2), V(0, 0, -3), kRadius);
  ASSERT_TRUE(t);
  EXPECT_LE(ulps(*t, (2.0L - 0.75L - LD(kRadius)) / 3.0L), kUlps);
  PlacedShape placed;
  placed.shape = box();
  for (const double dx : {-1e-9, 0.0, 1e-9}) {
    const ContactGeometry g =
        contactGeometry(V(0.5 + dx, 0, 0.75 + kRadius), kRadius, placed, 1e-9, kNoApproach);
    EXPECT_NEAR(g.normal.z(), -1.0, 1e-15) << dx;
    EXPECT_NEAR(g.normal.x(), dx > 0 ? -dx / kRadius : 0.0, 1e-15) << dx;
  }
}

const Cylinder kCylinder{0.3, 0.5};

TEST(FiniteShapes, CylinderSideCapAndRim) {
  // The side, head-on along x: 2 - 0.3 - r = 1.5 t.
  const auto side = thrown(kCylinder, V(2, 0, 0.2), V(-1.5, 0, 0), kRadius);
  ASSERT_TRUE(side);
  EXPECT_LE(ulps(*side, (2.0L - 0.3L - LD(kRadius)) / 1.5L), kUlps);
  // Obliquely at the side: |(x, y)| = R + r with x = 2 - 1.5 t, y = 0.1.
  const auto oblique = thrown(kCylinder, V(2, 0.1, 0.2), V(-1.5, 0, 0.1), kRadius);
  ASSERT_TRUE(oblique);
  const LD reach = 0.4L, y = LD(0.1);
  EXPECT_LE(ulps(*oblique, (2.0L - std::sqrt(reach * reach - y * y)) / 1.5L), kUlps);
  // A cap from above.
  const auto cap = thrown(kCylinder, V(0.1, 0.1, 1.7), V(0, 0, -2), kRadius);
  ASSERT_TRUE(cap);
  EXPECT_LE(ulps(*cap, (1.7L - 0.5L - LD(kRadius)) / 2.0L), kUlps);
  // The rim, along the diagonal of the xz-plane towards (R, 0, h): (ox - u t)^2 + (oz - u t)^2
  // = r^2 with the doubles' own offsets ox, oz from the rim, the smaller root.
  const double d = 0.45, u = 0.9;
  const auto rim = thrown(kCylinder, V(0.3 + d, 0, 0.5 + d), V(-u, 0, -u), kRadius);
  ASSERT_TRUE(rim);
  const LD ox = LD(0.3 + d) - 0.3L, oz = LD(0.5 + d) - 0.5L, uu = LD(u);
  const LD qa = 2 * uu * uu, qb = -2 * uu * (ox + oz),
           qc = ox * ox + oz * oz - LD(kRadius) * LD(kRadius);
  EXPECT_LE(ulps(*rim, (-qb - std::sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)), kUlps);
  // The rim under gravity (degree 8): dropped at R + delta, (z - h)^2 + delta^2 = r^2.
  const double delta = 0.07, z0 = 1.4;
  const auto dropped = thrown(kCylinder, V(0.3 + delta, 0, z0), V::Zero(), kRadius, V(0, 0, -kG));
  ASSERT_TRUE(dropped);
  const LD dx = LD(0.3 + delta) - 0.3L;
  const LD height = 0.5L + std::sqrt(LD(kRadius) * LD(kRadius) - dx * dx);
  EXPECT_LE(ulps(*dropped, std::sqrt(2 * (LD(z0) - height) / LD(kG))), kUlps);
  // And the same turned about z by 30 degrees (the rim is a circle: the same instant).
  const double turn = M_PI / 6;
  const auto turned =
      thrown(kCylinder, V((0.3 + delta) * std::cos(turn), (0.3 + delta) * std::sin(turn), z0),
             V::Zero(), kRadius, V(0, 0, -kG));
  ASSERT_TRUE(turned);
  EXPECT_NEAR(*turned, static_cast<double>(std::sqrt(2 * (LD(z0) - height) / LD(kG))), 1e-14);
}

const Capsule kCapsule{0.2, 0.4};

TEST(FiniteShapes, CapsuleSideAndEnd) {
  const auto side = thrown(kCapsule, V(-1.5, 0, 0.3), V(2, 0, 0), kRadius);
  ASSERT_TRUE(side);
  EXPECT_LE(ulps(*side, (1.5L - 0.2L - LD(kRadius)) / 2.0L), kUlps);
  // The end ball about (0, 0, 0.4), head-on from above and under gravity.
  const auto end = thrown(kCapsule, V(0, 0, 1.6), V(0, 0, -1), kRadius);
  ASSERT_TRUE(end);
  EXPECT_LE(ulps(*end, 1.6L - 0.4L - 0.2L - LD(kRadius)), kUlps);
  const double dx = 0.15, z0 = 1.2;
  const auto dropped = thrown(kCapsule, V(dx, 0, z0), V::Zero(), kRadius, V(0, 0, -kG));
  ASSERT_TRUE(dropped);
  const LD grown = 0.2L + LD(kRadius);
  const LD height = 0.4L + std::sqrt(grown * grown - LD(dx) * LD(dx));
  EXPECT_LE(ulps(*dropped, std::sqrt(2 * (LD(z0) - height) / LD(kG))), kUlps);
}

TEST(FiniteShapes, ContactGeometryOfEachFeature) {
  PlacedShape box;
  box.shape = kBox;
  box.pose.transform.translation() = V(1, 0, 0);
  // Over the face z = 0.75: flat, bounded.
  ContactGeometry g = contactGeometry(V(1.1, 0, 1.0), kRadius, box, 1e-9, kNoApproach);
  EXPECT_EQ(g.normal, V(0, 0, -1));
  EXPECT_NEAR(g.gap, 0.25 - kRadius, 1e-15);
  EXPECT_TRUE(g.flat());
  EXPECT_TRUE(g.bounded);
  // Beside the edge x = 1.5, z = 0.75: the normal to the edge, turning about its axis y.
  g = contactGeometry(V(1.5 + 0.3, 0.1, 0.75 + 0.4), kRadius, box, 1e-9, kNoApproach);
  EXPECT_NEAR((g.normal - V(-0.6, 0, -0.8)).norm(), 0, 1e-15);
  EXPECT_NEAR(g.gap, 0.5 - kRadius, 1e-15);
  EXPECT_NEAR(g.curvature, 2.0, 1e-15);
  EXPECT_EQ(g.turning_axis, V::UnitY());
  EXPECT_EQ(g.axial_share, 0.0);
  // Moving along the edge the normal does not turn; across it, |v|^2 / d.
  EXPECT_EQ(g.centripetal(V(0, 3, 0)), 0.0);
  EXPECT_NEAR(g.centripetal(V(0.8, 0, -0.6)), 2.0, 1e-15);
  // A corner: turning alike every way.
  g = contactGeometry(V(1.5 + 0.2, 0.25 + 0.2, 0.75 + 0.1), kRadius, box, 1e-9, kNoApproach);
  EXPECT_NEAR(g.gap, 0.3 - kRadius, 1e-15);
  EXPECT_NEAR(g.curvature, 1 / 0.3, 1e-14);
  EXPECT_TRUE(g.turning_axis.isZero());
  // Inside, nearest the face x = 1.5: pushed out through it.
  g = contactGeometry(V(1.45, 0, 0), kRadius, box, 1e-9, kNoApproach);
  EXPECT_EQ(g.normal, V(-1, 0, 0));  // the shape pushes the ball out along +x
  EXPECT_NEAR(g.gap, -0.05 - kRadius, 1e-15);
  // A cylinder's rim: along the rim the normal turns at (1 - R / rho) of the rate across it.
  PlacedShape cylinder;
  cylinder.shape = kCylinder;
  g = contactGeometry(V(0.3 + 0.3, 0, 0.5 + 0.4), kRadius, cylinder, 1e-9, kNoApproach);
  EXPECT_NEAR(g.gap, 0.5 - kRadius, 1e-15);
  EXPECT_NEAR((g.turning_axis - V::UnitY()).norm(), 0, 1e-15);
  EXPECT_NEAR(g.axial_share, 0.5, 1e-15);  // 1 - 0.3 / 0.6
}

// A paddle (a thin box, its faces at x = +-0.01 in its own axes) turning about z at w = 10 rad/s
// on its frame, and a ball (r = 0.05, e = 0.5 against it, no friction) moving at v = 0.5 m/s
// along x at y0 = 0.1 towards its -x face, x0 = -0.065. The paddle's axis x is (cos wt, sin wt,
// 0): the ball's centre is at q_x = (x0 + v t) cos wt + y0 sin wt along it, and meets the face
// grown by r where q_x = -0.01 - r: f(t) = (x0 + v t) cos wt + y0 sin wt + 0.06 = 0, solved below
// by Newton's method in long double (the paddle turns towards the ball: about 3.3 ms, where a
// paddle that did not turn would be met at 10 ms). There the face's point under the ball moves
// at w x r, and the ball leaves along the face's normal n at u_s + e (u_s - u_a).
TEST(FiniteShapes, ATurningPaddleIsMetWhereItHasTurnedAndHitsWithItsSurfacesVelocity) {
  Scene scene;
  ASSERT_TRUE(scene.materials.addMaterial("wood", Material{0.5, 0.0}, "m").ok());
  BodySpec ball;
  ball.id = "ball";
  ball.mass = 0.1;
  ball.radius = 0.05;
  ball.material = "wood";
  scene.bodies = {ball};
  ObstacleSpec paddle;
  paddle.id = "paddle";
  paddle.shape = ObstacleShape::kBox;
  paddle.size = V(0.02, 0.3, 0.3);
  paddle.frame = "paddle_link";
  paddle.material = "wood";
  scene.obstacles = {paddle};
  ImpactMonitor monitor(scene, MonitorSettings{});
  RigidPose frame;
  const double w = 10, x0 = -0.065, y0 = 0.1, v = 0.5, e = 0.5;
  frame.angular_velocity = V(0, 0, w);
  monitor.setObstaclePose(0, frame);
  BodyStateSample start;
  start.body = 0;
  start.position = V(x0, y0, 0);
  start.velocity = V(v, 0, 0);
  monitor.step(0.0, {start});
  const StepReport report = monitor.step(0.02, {});
  ASSERT_EQ(report.impacts.size(), 1u);
  const ImpactRecord& impact = report.impacts[0];
  EXPECT_TRUE(impact.other_is_obstacle);
  LD t = 0.0033L;
  for (int i = 0; i < 50; ++i) {
    const LD f = (x0 + v * t) * std::cos(w * t) + y0 * std::sin(w * t) + 0.06L;
    const LD slope =
        v * std::cos(w * t) - w * (x0 + v * t) * std::sin(w * t) + w * y0 * std::cos(w * t);
    t -= f / slope;
  }
  EXPECT_NEAR(impact.time, static_cast<double>(t), 1e-12);
  const LD angle = w * t;
  const Eigen::Matrix<LD, 3, 1> n(std::cos(angle), std::sin(angle), 0);
  const Eigen::Matrix<LD, 3, 1> across(-std::sin(angle), std::cos(angle), 0);
  const LD along_face = -(x0 + v * t) * std::sin(angle) + y0 * std::cos(angle);
  const Eigen::Matrix<LD, 3, 1> point = -0.01L * n + along_face * across;
  const Eigen::Matrix<LD, 3, 1> surface(-w * point.y(), w * point.x(), 0);
  EXPECT_NEAR((impact.normal - n.cast<double>()).norm(), 0, 1e-12);
  EXPECT_NEAR((impact.velocity_b_before - surface.cast<double>()).norm(), 0, 1e-12);
  const LD u_a = v * n.x(), u_s = surface.dot(n);
  const Eigen::Matrix<LD, 3, 1> after =
      Eigen::Matrix<LD, 3, 1>(v, 0, 0) + (u_s + e * (u_s - u_a) - u_a) * n;
  EXPECT_NEAR((impact.velocity_a_after - after.cast<double>()).norm(), 0, 1e-12);
}

// The turning paddle above with friction and spin (mu large enough that the contact point
// stops slipping within the impact: sticking) spins the ball. At the contact the ball's point
// slips across the face at s = (v - v_s).t (t = (-n_y, n_x, 0), the face's direction in the
// plane of turning; the ball has no spin yet). A solid ball (I = 2/5 m r^2) stops slipping after
// the tangential impulse -(2/7) m s t: its velocity along t changes by -(2/7) s, and it turns at
// r n x J / I = -(5/7) (s / r) z. Along n, u_s + e (u_s - u_a) as before.
TEST(FiniteShapes, ATurningPaddleSpinsTheBallWithFriction) {
  Scene scene;
  scene.effects.friction = true;
  scene.effects.spin = true;
  ASSERT_TRUE(scene.materials.addMaterial("rubber", Material{0.5, 1e6}, "m").ok());
  BodySpec ball;
  ball.id = "ball";
  ball.mass = 0.1;
  ball.radius = 0.05;
  ball.material = "rubber";
  scene.bodies = {ball};
  ObstacleSpec paddle;
  paddle.id = "paddle";
  paddle.shape = ObstacleShape::kBox;
  paddle.size = V(0.02, 0.3, 0.3);
  paddle.frame = "paddle_link";
  paddle.material = "rubber";
  scene.obstacles = {paddle};
  ImpactMonitor monitor(scene, MonitorSettings{});
  RigidPose frame;
  const double w = 10, x0 = -0.065, y0 = 0.1, v = 0.5, e = 0.5, r = 0.05;
  frame.angular_velocity = V(0, 0, w);
  monitor.setObstaclePose(0, frame);
  BodyStateSample start;
  start.body = 0;
  start.position = V(x0, y0, 0);
  start.velocity = V(v, 0, 0);
  monitor.step(0.0, {start});
  const StepReport report = monitor.step(0.02, {});
  ASSERT_EQ(report.impacts.size(), 1u);
  const ImpactRecord& impact = report.impacts[0];
  LD t = 0.0033L;  // the instant, as in the test above
  for (int i = 0; i < 50; ++i) {
    const LD f = (x0 + v * t) * std::cos(w * t) + y0 * std::sin(w * t) + 0.06L;
    const LD slope =
        v * std::cos(w * t) - w * (x0 + v * t) * std::sin(w * t) + w * y0 * std::cos(w * t);
    t -= f / slope;
  }
  const LD angle = w * t;
  const Eigen::Matrix<LD, 3, 1> n(std::cos(angle), std::sin(angle), 0);
  const Eigen::Matrix<LD, 3, 1> across(-std::sin(angle), std::cos(angle), 0);
  const LD along_face = -(x0 + v * t) * std::sin(angle) + y0 * std::cos(angle);
  const Eigen::Matrix<LD, 3, 1> point = -0.01L * n + along_face * across;
  const Eigen::Matrix<LD, 3, 1> surface(-w * point.y(), w * point.x(), 0);
  const Eigen::Matrix<LD, 3, 1> before(v, 0, 0);
  const LD u_a = before.dot(n), u_s = surface.dot(n), slip = (before - surface).dot(across);
  const Eigen::Matrix<LD, 3, 1> after =
      before + (u_s + e * (u_s - u_a) - u_a) * n - (2.0L / 7) * slip * across;
  EXPECT_NEAR((impact.velocity_a_after - after.cast<double>()).norm(), 0, 1e-12);
  EXPECT_NEAR((impact.angular_velocity_a_after - V(0, 0, double(-(5.0L / 7) * slip / r))).norm(), 0,
              1e-11);
  // Most of the slip is the face's: w x r along it is -0.1 m/s at 0.01 m from the axis, the
  // ball's own velocity along it 0.5 sin(angle) = 0.017 m/s.
  EXPECT_GT(std::abs(double(slip)), 0.08);
}

// A paddle swung about a hinge: the box (faces at x = +-0.01) centred at (0, 0.25, 0) on a frame
// that turns about z through its origin at w = 2 rad/s from theta0 = -0.5 rad; a ball (r = 0.033)
// at rest at p = (-0.06, 0.25, 0). The paddle's centre moves on the circle about the hinge (the
// frame's constant twist), and its -x face grown by r reaches the ball where cos(theta - beta) =
// -(0.01 + r) / |p| (beta = p's angle): at t = (theta - theta0) / w. There the line of impact is
// the paddle's x axis, the face's point x_c = -0.01 n + q_y (-n_y, n_x, 0) moves at w z x x_c, and
// the ball at rest leaves at (1 + e) u_s n, u_s = -w q_y (e = 0.5, no friction).
TEST(FiniteShapes, APaddleSwungAboutAHingeIsMetOnItsCircleAtTheClosedForm) {
  Scene scene;
  ASSERT_TRUE(scene.materials.addMaterial("wood", Material{0.5, 0.0}, "m").ok());
  BodySpec ball;
  ball.id = "ball";
  ball.mass = 0.057;
  ball.radius = 0.033;
  ball.material = "wood";
  scene.bodies = {ball};
  ObstacleSpec paddle;
  paddle.id = "paddle";
  paddle.shape = ObstacleShape::kBox;
  paddle.size = V(0.02, 0.3, 0.3);
  paddle.position = V(0, 0.25, 0);
  paddle.frame = "paddle_link";
  paddle.material = "wood";
  scene.obstacles = {paddle};
  ImpactMonitor monitor(scene, MonitorSettings{});
  const double w = 2, theta0 = -0.5, px = -0.06, py = 0.25, r = 0.033;
  RigidPose frame;
  frame.transform.linear() = Eigen::AngleAxisd(theta0, V::UnitZ()).toRotationMatrix();
  frame.angular_velocity = V(0, 0, w);
  monitor.setObstaclePose(0, frame);
  BodyStateSample start;
  start.body = 0;
  start.position = V(px, py, 0);
  monitor.step(0.0, {start});
  const StepReport report = monitor.step(0.4, {});
  ASSERT_FALSE(report.impacts.empty());
  const ImpactRecord& impact = report.impacts[0];
  const LD theta =
      std::atan2(LD(py), LD(px)) - std::acos(-(0.01L + r) / std::hypot(LD(px), LD(py)));
  EXPECT_NEAR(impact.time, static_cast<double>((theta - theta0) / w), 1e-12);
  const LD nx = std::cos(theta), ny = std::sin(theta);
  const LD along = -px * std::sin(theta) + py * std::cos(theta);
  const LD xc = -0.01L * nx - along * ny, yc = -0.01L * ny + along * nx;
  EXPECT_NEAR((impact.normal - V(double(nx), double(ny), 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((impact.velocity_b_before - V(double(-w * yc), double(w * xc), 0)).norm(), 0, 1e-12);
  const LD leaves = (1 + 0.5L) * -w * along;
  EXPECT_NEAR((impact.velocity_a_after - V(double(leaves * nx), double(leaves * ny), 0)).norm(), 0,
              1e-12);
}

/// Independent references: the distance from a point to each shape by its own formula.
LD distanceTo(const Cuboid& box, const Eigen::Matrix<LD, 3, 1>& p) {
  LD sum = 0;
  for (int i = 0; i < 3; ++i) {
    const LD out = std::max(std::abs(p[i]) - LD(box.half_size[i]), 0.0L);
    sum += out * out;
  }
  return std::sqrt(sum);
}
LD distanceTo(const Cylinder& c, const Eigen::Matrix<LD, 3, 1>& p) {
  const LD radial = std::max(std::hypot(p.x(), p.y()) - LD(c.radius), 0.0L);
  const LD axial = std::max(std::abs(p.z()) - LD(c.half_length), 0.0L);
  return std::hypot(radial, axial);
}
LD distanceTo(const Capsule& c, const Eigen::Matrix<LD, 3, 1>& p) {
  const LD z = std::clamp(p.z(), -LD(c.half_length), LD(c.half_length));
  return std::max(
      std::sqrt(p.x() * p.x() + p.y() * p.y() + (p.z() - z) * (p.z() - z)) - LD(c.radius), 0.0L);
}

/// A mesh's: the least distance to its triangles, each by projection onto its plane (inside the
/// triangle by the signs of three cross products) or else to the nearest of its three sides
/// (another route than TriangleMesh::nearest's Voronoi regions), in long double.
LD distanceTo(const Mesh& mesh, const Eigen::Matrix<LD, 3, 1>& p) {
  using LV = Eigen::Matrix<LD, 3, 1>;
  const auto to_segment = [&](const LV& a, const LV& b) {
    const LV ab = b - a;
    const LD s = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0L, 1.0L);
    return (p - (a + s * ab)).norm();
  };
  LD least = INFINITY;
  for (const TriangleMesh::Triangle& t : mesh.triangles->triangles()) {
    const LV a = mesh.triangles->vertices()[t[0]].cast<LD>();
    const LV b = mesh.triangles->vertices()[t[1]].cast<LD>();
    const LV c = mesh.triangles->vertices()[t[2]].cast<LD>();
    const LV n = (b - a).cross(c - a).normalized();
    const LV q = p - n.dot(p - a) * n;
    const bool over = n.dot((b - a).cross(q - a)) >= 0 && n.dot((c - b).cross(q - b)) >= 0 &&
                      n.dot((a - c).cross(q - c)) >= 0;
    const LD d = over ? std::abs(n.dot(p - a))
                      : std::min({to_segment(a, b), to_segment(b, c), to_segment(c, a)});
    least = std::min(least, d);
  }
  return least;
}

/// The convex hull of a few points as a mesh: every triangle of them with all the others on one
/// side (by brute force), facing out.
std::shared_ptr<const TriangleMesh> convexHull(const std::vector<V>& points) {
  std::vector<TriangleMesh::Triangle> triangles;
  V centre = V::Zero();
  for (const V& p : points) centre += p / points.size();
  const auto n = static_cast<std::uint32_t>(points.size());
  for (std::uint32_t i = 0; i < n; ++i) {
    for (std::uint32_t j = i + 1; j < n; ++j) {
      for (std::uint32_t k = j + 1; k < n; ++k) {
        const V normal = (points[j] - points[i]).cross(points[k] - points[i]);
        int above = 0, below = 0;
        for (std::uint32_t m = 0; m < n; ++m) {
          const double side = normal.dot(points[m] - points[i]);
          above += side > 1e-12;
          below += side < -1e-12;
        }
        if (above == 0 || below == 0) triangles.push_back({i, j, k});
      }
    }
  }
  return scene_builders::facingOut(points, triangles, centre);
}

/// An icosahedron stretched to 1.0 x 0.6 x 0.8 and turned: faces, edges and vertices in no
/// axis' direction.
std::shared_ptr<const TriangleMesh> stretchedIcosahedron() {
  const double phi = (1 + std::sqrt(5.0)) / 2;
  std::vector<V> points;
  for (const double a : {-1.0, 1.0}) {
    for (const double b : {-phi, phi}) {
      points.emplace_back(0, a, b);
      points.emplace_back(a, b, 0);
      points.emplace_back(b, 0, a);
    }
  }
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, V(1, 2, 3).normalized()).toRotationMatrix();
  for (V& p : points) p = turn * V(0.5, 0.3, 0.4).cwiseProduct(p) / phi;
  return convexHull(points);
}

struct Reference {
  bool hit = false;
  LD time = 0;
  bool clear = true;  ///< far enough from a graze that hit or miss is certain
};

/// The first contact by conservative advancement on the distance (no step can skip a contact:
/// the distance changes no faster than the speed), in long double. With `w`, the shape turns at
/// w about its origin: the ball's centre in the shape's axes is R(-w t) p(t), whose speed is at
/// most |p'| + |w| |p|.
template <class Finite>
Reference reference(const Finite& shape, const V& c, const V& v, const V& a, double r,
                    double horizon, const V& w = V::Zero()) {
  using LV = Eigen::Matrix<LD, 3, 1>;
  const LV c0 = c.cast<LD>(), v0 = v.cast<LD>(), a0 = a.cast<LD>(), w0 = w.cast<LD>();
  const auto at = [&](LD t) -> LV {
    const LV p = c0 + t * (v0 + (t / 2) * a0);
    if (w0.norm() == 0) return p;
    return Eigen::AngleAxis<LD>(-w0.norm() * t, w0.normalized()).toRotationMatrix() * p;
  };
  const LD travel = v0.norm() + a0.norm() * horizon;
  const LD speed = travel + w0.norm() * (c0.norm() + travel * horizon);
  const LD margin = 1e-9L;
  Reference ref;
  LD t = 0, least = INFINITY;
  for (int i = 0; i < 200000 && t <= horizon; ++i) {
    const LD gap = distanceTo(shape, at(t)) - LD(r);
    least = std::min(least, gap);
    if (gap <= 1e-15L) {
      ref.hit = true;
      ref.time = t;
      // Certain only if the path goes well inside afterwards.
      LD deepest = 0;
      for (int k = 1; k <= 64; ++k) {
        const LD s = t + (LD(horizon) - t) * k / 64;
        deepest = std::min(deepest, distanceTo(shape, at(s)) - LD(r));
      }
      // (and soon after: a corner clipped, or swept by a turning shape, is left within a step)
      for (LD after = 1e-7L; after < LD(horizon) - t; after *= 2) {
        deepest = std::min(deepest, distanceTo(shape, at(t + after)) - LD(r));
      }
      ref.clear = deepest < -margin;
      return ref;
    }
    t += std::max(gap / speed, 1e-13L);
  }
  ref.clear = least > margin;
  return ref;
}

template <class Finite>
void throwAtRandom(const char* name, const Finite& shape, int throws, std::uint32_t seed,
                   double turning = 0.0) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double bound = boundingRadius(shape);
  int hits = 0, misses = 0, ambiguous = 0, wrong = 0;
  for (int n = 0; n < throws; ++n) {
    const double r = 0.01 + 0.1 * (unit(random) + 1);
    V start(unit(random), unit(random), unit(random));
    start = start.normalized() * (bound + r + 0.5 + 0.5 * (unit(random) + 1));
    const V aim = 1.2 * bound * V(unit(random), unit(random), unit(random));
    const double speed = 0.5 + 2.0 * (unit(random) + 1);
    const V velocity = (aim - start).normalized() * speed;
    const V acceleration = n % 2 ? V(0, 0, -kG) : V::Zero();
    const double horizon = 1.5;
    BallMotion ball{start, r, velocity, acceleration};
    PlacedShape placed;
    placed.shape = shape;
    // Turning: up to `turning` rad/s about a random axis through the shape's origin.
    const V w = turning * 0.5 * (unit(random) + 1) *
                V(unit(random), unit(random), unit(random) + 2).normalized();
    if (turning > 0) placed.pose.angular_velocity = w;
    const auto t = firstContact(ball, placed, V::Zero(), V::Zero(), n % 2 == 1, horizon);
    const Reference ref = turning > 0
                              ? reference(shape, start, velocity, acceleration, r, horizon, w)
                              : reference(shape, start, velocity, acceleration, r, horizon);
    if (!ref.clear) {
      ++ambiguous;
      continue;
    }
    if (ref.hit) {
      ++hits;
    } else {
      ++misses;
    }
    const bool agree = ref.hit == t.has_value() &&
                       (!ref.hit || std::abs(LD(*t) - ref.time) <= 1e-9L * (1 + ref.time));
    if (!agree && ++wrong <= 5) {
      ADD_FAILURE() << "throw " << n << ": from (" << start.transpose() << ") at ("
                    << velocity.transpose() << "), r " << r << ", reference "
                    << (ref.hit ? "hit at " + std::to_string(double(ref.time)) : "miss")
                    << ", ours " << (t ? "hit at " + std::to_string(*t) : "miss");
    }
  }
  std::printf(
      "%s: %d throws, %d hits, %d misses, %d within 1e-9 m of a graze (not counted), %d wrong\n",
      name, throws, hits, misses, ambiguous, wrong);
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(hits, throws / 10);  // the throws test something either way
  EXPECT_GT(misses, throws / 10);
  EXPECT_LT(ambiguous, throws / 100);
}

// Shapes that turn (up to 20 rad/s about random axes through their origins), where the contact
// is no polynomial's root: 2,000 throws a shape (FINITE_SHAPE_THROWS for more), against the
// reference advanced along the ball's path in the shape's turning axes.
TEST(FiniteShapes, RandomThrowsAtTurningShapesMissNothingAndInventNothing) {
  const char* asked = std::getenv("FINITE_SHAPE_THROWS");
  const int throws = asked ? std::max(1000, std::atoi(asked) / 10) : 2000;
  throwAtRandom("turning box", kBox, throws, 11, 20.0);
  throwAtRandom("turning cylinder", kCylinder, throws, 12, 20.0);
  throwAtRandom("turning capsule", kCapsule, throws, 13, 20.0);
  throwAtRandom("turning mesh icosahedron", Mesh{stretchedIcosahedron()}, throws, 14, 20.0);
}

// 20,000 throws a shape in the suite; FINITE_SHAPE_THROWS=1000000 for the long run (about 33
// minutes for the five, and 100,000 at each turning shape above; doc/model.md, "Finite
// obstacles", gives its last result).
TEST(FiniteShapes, RandomThrowsMissNothingAndInventNothing) {
  const char* asked = std::getenv("FINITE_SHAPE_THROWS");
  const int throws = asked ? std::max(1000, std::atoi(asked)) : 20000;
  throwAtRandom("box", kBox, throws, 1);
  throwAtRandom("mesh cube", Mesh{scene_builders::cubeMesh(kBox.half_size)}, throws, 4);
  throwAtRandom("mesh icosahedron", Mesh{stretchedIcosahedron()}, throws, 5);
  throwAtRandom("cylinder", kCylinder, throws, 2);
  throwAtRandom("capsule", kCapsule, throws, 3);
}

/// The stretched icosahedron without the five triangles about one vertex: a bowl (an open mesh)
/// whose inside is met through its pentagonal opening, on its faces' backs.
std::shared_ptr<const TriangleMesh> openIcosahedron() {
  const auto whole = stretchedIcosahedron();
  const std::uint32_t top = whole->triangles()[0][0];
  std::vector<TriangleMesh::Triangle> kept;
  for (const TriangleMesh::Triangle& t : whole->triangles()) {
    if (t[0] != top && t[1] != top && t[2] != top) kept.push_back(t);
  }
  return *TriangleMesh::build(whole->vertices(), kept, "open icosahedron");
}

/// A sheet folded five times (a zigzag 1.2 m along x, 0.8 m along y, 0.3 m deep), turned: its
/// folds are convex on one side and grooves on the other, every one met from its convex side.
std::shared_ptr<const TriangleMesh> foldedSheet() {
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.4, V(3, 1, 2).normalized()).toRotationMatrix();
  std::vector<V> vertices;
  for (int i = 0; i <= 6; ++i) {
    for (const double y : {-0.4, 0.4}) {
      vertices.push_back(turn * V(-0.6 + 0.2 * i, y, i % 2 ? 0.15 : -0.15));
    }
  }
  std::vector<TriangleMesh::Triangle> triangles;
  for (std::uint32_t i = 0; i < 6; ++i) {
    triangles.push_back({2 * i, 2 * i + 2, 2 * i + 3});
    triangles.push_back({2 * i, 2 * i + 3, 2 * i + 1});
  }
  return *TriangleMesh::build(vertices, triangles, "folded sheet");
}

// Open meshes are surfaces, met from either side: a bowl (the icosahedron without a cap) and a
// folded sheet, 3,000 throws each against the plain distance to their triangles (the reference
// of every mesh here).
TEST(FiniteShapes, RandomThrowsAtOpenMeshesMeetEitherSide) {
  const char* asked = std::getenv("FINITE_SHAPE_THROWS");
  const int throws = asked ? std::max(1000, std::atoi(asked) / 4) : 3000;
  EXPECT_FALSE(openIcosahedron()->closed());
  EXPECT_FALSE(foldedSheet()->closed());
  throwAtRandom("open icosahedron", Mesh{openIcosahedron()}, throws, 6);
  throwAtRandom("folded sheet", Mesh{foldedSheet()}, throws, 7);
}

}  // namespace
}  // namespace collision_response::core
