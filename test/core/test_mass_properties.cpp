// A body's mass properties (mass_properties.h): each uniform solid's closed form against an
// independent computation (the polyhedron's divergence-theorem sums on a box's triangles, a
// tetrahedron's tensor in rationals and a cylinder's and a capsule's by quadrature along the
// axis, both from test/exact/mass_properties.py), hulls from points, and every refusal of a
// shape, a hull and a tensor, named.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "collision_response/core/mass_properties.h"
#include "collision_response/core/triangle_mesh.h"
#include "collision_response/core/validation.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using M = Eigen::Matrix3d;

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kPi = 3.14159265358979323846;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Each entry of `actual` within `ulps` units of the largest entry of `expected` (the tensor's
// scale: a zero product of inertia is compared at the moments' scale).
void expectTensorNear(const M& actual, const M& expected, double ulps) {
  const double scale = expected.cwiseAbs().maxCoeff();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(actual(i, j), expected(i, j), ulps * kEps * scale)
          << "entry (" << i << ", " << j << ")\n"
          << actual << "\nexpected\n"
          << expected;
    }
  }
}

// A box's 8 corners (x, y, z in {-h, +h}, corner k's bit i the sign of axis i) and its 12
// triangles, counter-clockwise seen from outside.
Polyhedron boxPolyhedron(const V& half, const V& centre) {
  Polyhedron box;
  for (int k = 0; k < 8; ++k) {
    box.vertices.push_back(centre + V((k & 1) ? half.x() : -half.x(),
                                      (k & 2) ? half.y() : -half.y(),
                                      (k & 4) ? half.z() : -half.z()));
  }
  box.triangles = {{0, 2, 1}, {1, 2, 3},   // z = -h
                   {4, 5, 6}, {5, 7, 6},   // z = +h
                   {0, 1, 4}, {1, 5, 4},   // y = -h
                   {2, 6, 3}, {3, 6, 7},   // y = +h
                   {0, 4, 2}, {2, 4, 6},   // x = -h
                   {1, 3, 5}, {3, 7, 5}};  // x = +h
  return box;
}

void expectRefused(const Status& status, const std::string& field, const std::string& words) {
  ASSERT_FALSE(status.ok()) << "expected a refusal naming " << field;
  EXPECT_EQ(status.error().field, field) << status.error().message();
  EXPECT_NE(status.error().reason.find(words), std::string::npos) << status.error().message();
}
template <class T>
void expectRefused(const Expected<T>& result, const std::string& field, const std::string& words) {
  ASSERT_FALSE(result.ok()) << "expected a refusal naming " << field;
  EXPECT_EQ(result.error().field, field) << result.error().message();
  EXPECT_NE(result.error().reason.find(words), std::string::npos) << result.error().message();
}

// Solid: I = 2/5 m r^2 = 2/5 5 4 = 8; hollow: I = 2/3 m r^2 = 2/3 3 4 = 8, both exact in doubles.
TEST(MassProperties, SpheresAreTheSolidAndHollowFactors) {
  const MassProperties solid = sphereMassProperties(5.0, 2.0, Inertia::kSolid);
  EXPECT_EQ(solid.inertia, M(V::Constant(8.0).asDiagonal()));
  EXPECT_EQ(solid.mass, 5.0);
  EXPECT_NEAR(solid.volume, 32.0 / 3.0 * kPi, 2 * kEps * solid.volume);
  const MassProperties hollow = sphereMassProperties(3.0, 2.0, Inertia::kHollow);
  EXPECT_EQ(hollow.inertia, M(V::Constant(8.0).asDiagonal()));
}

// 3 kg, edges 0.5 x 0.25 x 1: m/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2) = diag(17/64, 5/16,
// 5/64) (exact in doubles); volume 1/8.
TEST(MassProperties, BoxIsItsClosedForm) {
  Cuboid box;
  box.half_size = V(0.25, 0.125, 0.5);
  const MassProperties properties = solidMassProperties(box, 3.0);
  EXPECT_EQ(properties.inertia, M(V(17.0 / 64, 5.0 / 16, 5.0 / 64).asDiagonal()));
  EXPECT_EQ(properties.volume, 0.125);
  EXPECT_EQ(properties.centre_of_mass, V::Zero());
}

// The divergence-theorem sums over the box's 12 triangles give the closed form to a few ulps,
// centred anywhere: at the origin, and at (1000, -250, 30), where the vertices' mean (their
// reference) keeps the position's digits out of the moments.
TEST(MassProperties, BoxFromItsTwelveTrianglesIsTheClosedForm) {
  const V half(0.25, 0.125, 0.5);
  const M closed_form = V(17.0 / 64, 5.0 / 16, 5.0 / 64).asDiagonal();
  for (const V& centre : {V(0, 0, 0), V(1000, -250, 30), V(0.3, 0.1, -0.7)}) {
    SCOPED_TRACE("centre " + formatVector(centre));
    const auto properties = polyhedronMassProperties(boxPolyhedron(half, centre), 3.0, "box");
    ASSERT_TRUE(properties.ok()) << properties.error().message();
    expectTensorNear(properties->inertia, closed_form, 2);
    EXPECT_NEAR(properties->volume, 0.125, 2 * kEps * 0.125);
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_NEAR(properties->centre_of_mass[axis], centre[axis],
                  2 * kEps * (std::abs(centre[axis]) + 1.0));
    }
    EXPECT_EQ(properties->mass, 3.0);
  }
}

// The tetrahedron (0.5, 0.25, -1), (2, 0.5, 0), (0.25, 1.5, 0.5), (1, 1, 2) of 3 kg, whose
// volume, centroid and tensor test/exact/mass_properties.py gives in rationals (from the
// simplex's Dirichlet integrals, not the divergence theorem): volume 7/12, centroid (15/16,
// 13/16, 3/8), ixx 1077/1280, iyy 249/256, izz 261/640, ixy 21/256, ixz -21/640, iyz -123/640.
TEST(MassProperties, TetrahedronIsItsTensorInRationals) {
  Polyhedron tetrahedron;
  tetrahedron.vertices = {V(0.5, 0.25, -1), V(2, 0.5, 0), V(0.25, 1.5, 0.5), V(1, 1, 2)};
  // Wound outwards: (v1 - v0) x (v2 - v0) . (v3 - v0) > 0 makes 0, 2, 1 the face away from v3.
  tetrahedron.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  const auto properties = polyhedronMassProperties(tetrahedron, 3.0, "tetrahedron");
  ASSERT_TRUE(properties.ok()) << properties.error().message();
  EXPECT_NEAR(properties->volume, 7.0 / 12, 2 * kEps);
  EXPECT_NEAR((properties->centre_of_mass - V(15.0 / 16, 13.0 / 16, 3.0 / 8)).norm(), 0.0,
              4 * kEps);
  InertiaTensor expected;
  expected.ixx = 1077.0 / 1280;
  expected.iyy = 249.0 / 256;
  expected.izz = 261.0 / 640;
  expected.ixy = 21.0 / 256;
  expected.ixz = -21.0 / 640;
  expected.iyz = -123.0 / 640;
  expectTensorNear(properties->inertia, expected.matrix(), 2);
  EXPECT_TRUE(checkInertiaTensor(InertiaTensor::fromMatrix(properties->inertia), "t").ok());
}

// Quadrature along the axis (test/exact/mass_properties.py): a cylinder of r = 0.375, h = 0.5,
// 3 kg; capsules of r = 0.25, h = 1.5, 2 kg and of r = 0.0525, h = 0.1, 0.37 kg.
TEST(MassProperties, CylinderAndCapsuleAgreeWithQuadrature) {
  Cylinder cylinder;
  cylinder.radius = 0.375;
  cylinder.half_length = 0.25;
  const MassProperties c = solidMassProperties(cylinder, 3.0);
  EXPECT_NEAR(c.volume, 0.22089323345553233, 4 * kEps * c.volume);
  expectTensorNear(c.inertia, V(0.16796875, 0.16796875, 0.2109375).asDiagonal(), 2);

  struct Case {
    double radius, length, mass, volume, ixx, izz;
  };
  for (const Case& k :
       {Case{0.25, 1.5, 2.0, 0.3599741582238305, 0.5971590909090909, 0.060227272727272727},
        Case{0.0525, 0.1, 0.37, 0.0014720325077476673, 0.001180141299019608,
             0.00046791397058823525}}) {
    SCOPED_TRACE("capsule r = " + formatNumber(k.radius));
    Capsule capsule;
    capsule.radius = k.radius;
    capsule.half_length = k.length / 2;
    const MassProperties p = solidMassProperties(capsule, k.mass);
    EXPECT_NEAR(p.volume, k.volume, 2 * kEps * k.volume);
    EXPECT_NEAR(p.inertia(0, 0), k.ixx, 2 * kEps * k.ixx);
    EXPECT_NEAR(p.inertia(1, 1), k.ixx, 2 * kEps * k.ixx);
    EXPECT_NEAR(p.inertia(2, 2), k.izz, 2 * kEps * k.izz);
    EXPECT_EQ(p.inertia(0, 1), 0.0);
  }
}

// A capsule of no segment is a solid sphere (2/5 m r^2); one of no radius a thin rod (m h^2 / 12,
// none about its axis).
TEST(MassProperties, CapsuleLimitsAreASphereAndARod) {
  Capsule ball;
  ball.radius = 2.0;
  const MassProperties sphere = solidMassProperties(ball, 5.0);
  expectTensorNear(sphere.inertia, V::Constant(8.0).asDiagonal(), 2);
  Capsule rod;
  rod.half_length = 1.5;
  const MassProperties thin = solidMassProperties(rod, 4.0);
  EXPECT_EQ(thin.inertia, M(V(3.0, 3.0, 0.0).asDiagonal()));
}

// A cube's hull from its 8 corners among 200 points inside it and on its faces: 8 vertices, 12
// triangles, and the solid's closed form m s^2 / 6 (s = 2, m = 1.5: 1).
TEST(MassProperties, CubesHullFromItsCornersAndPointsInside) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> inside(-1.0, 1.0);
  std::vector<V> points;
  for (int k = 0; k < 200; ++k) {
    V point(inside(random), inside(random), inside(random));
    if (k % 4 == 0) point[k % 3] = (k % 8 == 0) ? 1.0 : -1.0;  // on a face
    points.push_back(point);
    if (k % 25 == 0) {
      const int corner = k / 25;
      points.push_back(V((corner & 1) ? 1 : -1, (corner & 2) ? 1 : -1, (corner & 4) ? 1 : -1));
    }
  }
  const auto hull = convexHull(points, "points");
  ASSERT_TRUE(hull.ok()) << hull.error().message();
  EXPECT_EQ(hull->vertices.size(), 8u);
  EXPECT_EQ(hull->triangles.size(), 12u);
  for (const V& vertex : hull->vertices) EXPECT_EQ(vertex.cwiseAbs(), V::Ones());
  const auto properties = polyhedronMassProperties(*hull, 1.5, "hull");
  ASSERT_TRUE(properties.ok()) << properties.error().message();
  expectTensorNear(properties->inertia, M::Identity(), 2);
  EXPECT_NEAR(properties->volume, 8.0, 2 * kEps * 8.0);
  EXPECT_NEAR(properties->centre_of_mass.norm(), 0.0, 2 * kEps);
}

// The octahedron |x| + |y| + |z| <= a is 8 tetrahedra (0, a e_x, a e_y, a e_z) mirrored, each
// with integral of x^2 dV = a^5 / 60 (the Dirichlet integrals): V = 4/3 a^3, I = m a^2 / 5 1.
// Its hull from its 6 corners and points inside it, turned by a rotation R: R I R^T = I.
TEST(MassProperties, OctahedronsHullTurnedAnyWay) {
  const double a = 0.5, mass = 2.0;
  std::vector<V> corners = {V(a, 0, 0),  V(-a, 0, 0), V(0, a, 0),
                            V(0, -a, 0), V(0, 0, a),  V(0, 0, -a)};
  std::mt19937 random(3);
  std::uniform_real_distribution<double> inside(-a / 3, a / 3);
  for (int k = 0; k < 50; ++k) corners.push_back(V(inside(random), inside(random), inside(random)));
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, V(1, 2, 3).normalized()).toRotationMatrix();
  for (V& point : corners) point = turn * point;
  const auto hull = convexHull(corners, "points");
  ASSERT_TRUE(hull.ok()) << hull.error().message();
  EXPECT_EQ(hull->vertices.size(), 6u);
  EXPECT_EQ(hull->triangles.size(), 8u);
  const auto properties = polyhedronMassProperties(*hull, mass, "hull");
  ASSERT_TRUE(properties.ok()) << properties.error().message();
  EXPECT_NEAR(properties->volume, 4.0 / 3 * a * a * a, 2 * kEps);
  expectTensorNear(properties->inertia, M::Identity() * mass * a * a / 5, 2);
}

// A mesh body is its convex hull: a closed cube of edge 2 whose top face is dented (its centre
// pushed down to z = 0.5, four triangles) has the cube's mass properties (m s^2 / 6 = 1 for
// m = 1.5).
TEST(MassProperties, AMeshBodyIsItsConvexHull) {
  std::vector<V> vertices;
  for (int k = 0; k < 8; ++k)
    vertices.push_back(V((k & 1) ? 1 : -1, (k & 2) ? 1 : -1, (k & 4) ? 1 : -1));
  vertices.push_back(V(0, 0, 0.5));  // 8: the dent
  const std::vector<TriangleMesh::Triangle> triangles = {
      {0, 2, 1}, {1, 2, 3},                        // bottom
      {4, 5, 8}, {5, 7, 8}, {7, 6, 8}, {6, 4, 8},  // the dented top
      {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  const auto mesh = TriangleMesh::build(vertices, triangles, "bodies[0]/resource");
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  ASSERT_TRUE(mesh.value()->closed());
  const auto properties =
      uniformMassProperties(Mesh{mesh.value()}, 1.5, Inertia::kSolid, "bodies[0]");
  ASSERT_TRUE(properties.ok()) << properties.error().message();
  expectTensorNear(properties->inertia, M::Identity(), 2);
  EXPECT_NEAR(properties->volume, 8.0, 8 * kEps * 8.0);
}

// Each shape through the one entry point is its own closed form; a sphere's centre is its centre
// of mass.
TEST(MassProperties, EachShapeThroughTheOneEntry) {
  Sphere sphere;
  sphere.centre = V(1, 2, 3);
  sphere.radius = 2.0;
  const auto hollow = uniformMassProperties(sphere, 3.0, Inertia::kHollow, "s");
  ASSERT_TRUE(hollow.ok());
  EXPECT_EQ(hollow->inertia, M(V::Constant(8.0).asDiagonal()));
  EXPECT_EQ(hollow->centre_of_mass, V(1, 2, 3));
  Cuboid box;
  box.half_size = V(0.25, 0.125, 0.5);
  EXPECT_EQ(uniformMassProperties(box, 3.0, Inertia::kSolid, "b")->inertia,
            solidMassProperties(box, 3.0).inertia);
  Cylinder cylinder;
  cylinder.radius = 0.375;
  cylinder.half_length = 0.25;
  EXPECT_EQ(uniformMassProperties(cylinder, 3.0, Inertia::kSolid, "c")->inertia,
            solidMassProperties(cylinder, 3.0).inertia);
  Capsule capsule;
  capsule.radius = 0.25;
  capsule.half_length = 0.75;
  EXPECT_EQ(uniformMassProperties(capsule, 2.0, Inertia::kSolid, "c")->inertia,
            solidMassProperties(capsule, 2.0).inertia);
}

TEST(MassProperties, ShapesOfNoVolumeAndBadMassesAreNamed) {
  Cuboid box;
  box.half_size = V(0.25, 0.0, 0.5);
  expectRefused(uniformMassProperties(box, 1.0, Inertia::kSolid, "bodies[1]"), "bodies[1]",
                "no volume");
  Cylinder disc;
  disc.radius = 1.0;
  expectRefused(uniformMassProperties(disc, 1.0, Inertia::kSolid, "bodies[1]"), "bodies[1]",
                "no volume");
  expectRefused(uniformMassProperties(Sphere{}, 1.0, Inertia::kSolid, "bodies[1]"), "bodies[1]",
                "no volume");
  expectRefused(uniformMassProperties(Plane{}, 1.0, Inertia::kSolid, "bodies[1]"), "bodies[1]",
                "plane");
  box.half_size = V(1, 1, 1);
  for (const double mass : {kInf, 0.0, -1.0, kNan}) {
    expectRefused(uniformMassProperties(box, mass, Inertia::kSolid, "bodies[1]"), "bodies[1]",
                  "finite mass > 0");
  }
  box.half_size = V(1e200, 1e200, 1e200);
  expectRefused(uniformMassProperties(box, 1.0, Inertia::kSolid, "bodies[1]"), "bodies[1]",
                "too large");  // its volume overflows
}

TEST(MassProperties, HullsOfNoVolumeAreNamed) {
  // Four corners of a square and its centre: one plane.
  expectRefused(convexHull({V(0, 0, 0), V(1, 0, 0), V(0, 1, 0), V(1, 1, 0), V(0.5, 0.5, 0)},
                           "bodies[2]/resource"),
                "bodies[2]/resource", "spans no volume");
  // On one line, and one point five times.
  expectRefused(convexHull({V(0, 0, 0), V(1, 1, 1), V(2, 2, 2), V(3, 3, 3)}, "m"), "m",
                "spans no volume");
  expectRefused(convexHull(std::vector<V>(5, V(1, 2, 3)), "m"), "m", "spans no volume");
  expectRefused(convexHull({V(0, 0, 0), V(1, 0, 0), V(0, 1, 0)}, "m"), "m", "at least four");
  expectRefused(convexHull({V(0, 0, 0), V(1, 0, 0), V(0, 1, 0), V(0, 0, kNan)}, "m"), "m[3].z",
                "finite");
  // A mesh body that is flat (a floor of two triangles): its hull has no volume.
  const auto floor = TriangleMesh::build({V(0, 0, 0), V(1, 0, 0), V(1, 1, 0), V(0, 1, 0)},
                                         {{0, 1, 2}, {0, 2, 3}}, "mesh");
  ASSERT_TRUE(floor.ok());
  expectRefused(uniformMassProperties(Mesh{floor.value()}, 1.0, Inertia::kSolid, "bodies[4]"),
                "bodies[4]", "spans no volume");
}

TEST(MassProperties, PolyhedraOpenOrWoundInwardsAreNamed) {
  Polyhedron inwards = boxPolyhedron(V(1, 1, 1), V::Zero());
  for (auto& triangle : inwards.triangles) std::swap(triangle[1], triangle[2]);
  expectRefused(polyhedronMassProperties(inwards, 1.0, "p"), "p", "wound inwards");
  Polyhedron open = boxPolyhedron(V(1, 1, 1), V(5, 0, 0));
  open.triangles.resize(2);  // only the bottom: about the vertices' mean, it sums to nothing
  expectRefused(polyhedronMassProperties(open, 1.0, "p"), "p", "no volume");
  Polyhedron out_of_range = boxPolyhedron(V(1, 1, 1), V::Zero());
  out_of_range.triangles[3][1] = 8;
  expectRefused(polyhedronMassProperties(out_of_range, 1.0, "p"), "p.triangles[3]", "out of range");
  Polyhedron not_finite = boxPolyhedron(V(1, 1, 1), V::Zero());
  not_finite.vertices[5].y() = kInf;
  expectRefused(polyhedronMassProperties(not_finite, 1.0, "p"), "p.vertices[5].y", "finite");
  expectRefused(polyhedronMassProperties(Polyhedron{}, 1.0, "p"), "p", "no triangles");
}

// A rigid motion moves the mass, not its distribution: the hull of points on an ellipsoid (an
// irregular polyhedron of about 300 faces) turned by R keeps its volume, its centre of mass goes
// to R c and its tensor becomes R I R^T; moved by t, its centre goes to c + t and the rest stays.
// The points are on a grid of 2^-20 m, so that the shift (1000.5, -250.25, 30) moves them
// exactly (a rounded shift of 1e-14 m would change a 5 cm body's volume by about 1e-12 of
// itself); each to 64 ulps of its scale (qhull triangulates the turned points' faces its own
// way, and the sums run in another order).
TEST(MassProperties, AHullTurnedOrMovedTurnsOrMovesItsTensor) {
  std::mt19937 random(5);
  std::normal_distribution<double> normal;
  std::vector<V> points;
  for (int k = 0; k < 300; ++k) {
    const V direction = V(normal(random), normal(random), normal(random)).normalized();
    const V point = direction.cwiseProduct(V(0.3, 0.1, 0.05)) + V(0.02, -0.01, 0.03);
    points.push_back((point * 0x1p20).array().round() * 0x1p-20);
  }
  const auto hull = convexHull(points, "points");
  ASSERT_TRUE(hull.ok()) << hull.error().message();
  const auto properties = polyhedronMassProperties(*hull, 0.8, "hull");
  ASSERT_TRUE(properties.ok()) << properties.error().message();

  const M turn = Eigen::AngleAxisd(2.1, V(-1, 3, 0.5).normalized()).toRotationMatrix();
  const V shift(1000.5, -250.25, 30.0);
  for (const bool turned : {true, false}) {
    SCOPED_TRACE(turned ? "turned" : "moved");
    std::vector<V> moved;
    for (const V& point : points) moved.push_back(turned ? V(turn * point) : V(point + shift));
    const auto moved_hull = convexHull(moved, "moved");
    ASSERT_TRUE(moved_hull.ok()) << moved_hull.error().message();
    EXPECT_EQ(moved_hull->vertices.size(), hull->vertices.size());
    const auto moved_properties = polyhedronMassProperties(*moved_hull, 0.8, "hull");
    ASSERT_TRUE(moved_properties.ok());
    EXPECT_NEAR(moved_properties->volume, properties->volume, 64 * kEps * properties->volume);
    const V centre =
        turned ? V(turn * properties->centre_of_mass) : V(properties->centre_of_mass + shift);
    EXPECT_NEAR((moved_properties->centre_of_mass - centre).lpNorm<Eigen::Infinity>(), 0.0,
                64 * kEps * centre.lpNorm<Eigen::Infinity>());
    expectTensorNear(
        moved_properties->inertia,
        turned ? M(turn * properties->inertia * turn.transpose()) : properties->inertia, 64);
  }
}

// URDF's convention: the off-diagonal entries are the tensor's, symmetric.
TEST(InertiaTensorCheck, EntriesAreTheTensorsOwn) {
  InertiaTensor tensor;
  tensor.ixx = 1;
  tensor.iyy = 2;
  tensor.izz = 3;
  tensor.ixy = 0.1;
  tensor.ixz = 0.2;
  tensor.iyz = 0.3;
  M expected;
  expected << 1, 0.1, 0.2, 0.1, 2, 0.3, 0.2, 0.3, 3;
  EXPECT_EQ(tensor.matrix(), expected);
  const InertiaTensor back = InertiaTensor::fromMatrix(expected);
  EXPECT_EQ(back.matrix(), expected);
}

TEST(InertiaTensorCheck, RealBodiesAreAccepted) {
  // The box's, the 1e300 and 1e-300 scaled box's, a flat plate's (1, 1, 2: the triangle
  // inequality with equality) and the plate turned any way (its rounding within the allowance).
  const InertiaTensor box =
      InertiaTensor::fromMatrix(V(17.0 / 64, 5.0 / 16, 5.0 / 64).asDiagonal());
  EXPECT_TRUE(checkInertiaTensor(box, "inertia").ok());
  EXPECT_TRUE(checkInertiaTensor(InertiaTensor::fromMatrix(box.matrix() * 1e300), "i").ok());
  EXPECT_TRUE(checkInertiaTensor(InertiaTensor::fromMatrix(box.matrix() * 1e-300), "i").ok());
  const M plate = V(1, 1, 2).asDiagonal();
  EXPECT_TRUE(checkInertiaTensor(InertiaTensor::fromMatrix(plate), "i").ok());
  std::mt19937 random(11);
  std::normal_distribution<double> normal;
  for (int k = 0; k < 1000; ++k) {
    const M turn =
        Eigen::Quaterniond(normal(random), normal(random), normal(random), normal(random))
            .normalized()
            .toRotationMatrix();
    const M turned = turn * plate * turn.transpose();
    const auto status = checkInertiaTensor(InertiaTensor::fromMatrix(turned), "i");
    ASSERT_TRUE(status.ok()) << status.error().message() << "\n" << turned;
  }
}

TEST(InertiaTensorCheck, EachBadValueIsNamed) {
  InertiaTensor good;
  good.ixx = 1;
  good.iyy = 1;
  good.izz = 1;
  InertiaTensor bad = good;
  bad.ixy = kNan;
  expectRefused(checkInertiaTensor(bad, "bodies[0]/inertia"), "bodies[0]/inertia.ixy", "finite");
  bad = good;
  bad.izz = kInf;
  expectRefused(checkInertiaTensor(bad, "b.inertia"), "b.inertia.izz", "finite");
  for (const double moment : {0.0, -1.0}) {
    bad = good;
    bad.iyy = moment;
    expectRefused(checkInertiaTensor(bad, "b.inertia"), "b.inertia.iyy", "> 0");
  }
  // |ixz| = 1 = sqrt(ixx izz): semi-definite in the x-z plane.
  bad = good;
  bad.ixz = -1.0;
  expectRefused(checkInertiaTensor(bad, "b.inertia"), "b.inertia.ixz", "not positive definite");
  bad = good;
  bad.iyz = 2.0;
  expectRefused(checkInertiaTensor(bad, "b.inertia"), "b.inertia.iyz", "not positive definite");
  // Every 2 x 2 minor 1 - 0.36 > 0, but the whole has the principal moment 1 - 2 (0.6) = -0.2.
  bad = good;
  bad.ixy = bad.ixz = bad.iyz = -0.6;
  expectRefused(checkInertiaTensor(bad, "b.inertia"), "b.inertia", "not positive definite");
  // A rod: 1, 1 and 1e-17 about its axis, below the rounding of 1.
  bad = good;
  bad.izz = 1e-17;
  expectRefused(checkInertiaTensor(bad, "b.inertia"), "b.inertia", "not positive definite");
  // 1 + 1 < 2.5: no body has it.
  bad = good;
  bad.izz = 2.5;
  expectRefused(checkInertiaTensor(bad, "b.inertia"), "b.inertia", "triangle inequality");
  // Turned: principal moments (1, 1, 2.5) as a full tensor.
  const M turn = Eigen::AngleAxisd(0.4, V(1, -1, 2).normalized()).toRotationMatrix();
  expectRefused(checkInertiaTensor(
                    InertiaTensor::fromMatrix(turn * V(1, 1, 2.5).asDiagonal() * turn.transpose()),
                    "b.inertia"),
                "b.inertia", "triangle inequality");
  // Positive definite but its inverse overflows.
  bad = good;
  bad.ixx = bad.iyy = bad.izz = 1e-310;
  expectRefused(checkInertiaTensor(bad, "b.inertia"), "b.inertia", "too small");
}

TEST(OrientationCheck, EachBadQuaternionIsNamed) {
  EXPECT_TRUE(checkOrientation(Eigen::Quaterniond::Identity(), "q").ok());
  EXPECT_TRUE(checkOrientation(Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5), "q").ok());
  // Within tf2's tolerance of unit length (x^2 + ... within 0.01 of 1).
  EXPECT_TRUE(checkOrientation(Eigen::Quaterniond(1.004, 0, 0, 0), "q").ok());
  expectRefused(checkOrientation(Eigen::Quaterniond(0, 0, 0, 0), "bodies[0]/orientation"),
                "bodies[0]/orientation", "is zero");
  expectRefused(checkOrientation(Eigen::Quaterniond(2, 0, 0, 0), "state.orientation"),
                "state.orientation", "length 1");
  expectRefused(checkOrientation(Eigen::Quaterniond(0, 1e-200, 0, 0), "q"), "q", "length 1");
  // Eigen's (w, x, y, z) constructor; the field names the component.
  expectRefused(checkOrientation(Eigen::Quaterniond(1, 0, kNan, 0), "state.orientation"),
                "state.orientation.y", "finite");
  expectRefused(checkOrientation(Eigen::Quaterniond(kInf, 0, 0, 0), "q"), "q.w", "finite");
}

}  // namespace
}  // namespace collision_response::core
