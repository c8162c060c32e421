// The narrow phase's dispatch: for each shape, the contact geometry of a ball at an instant, the
// first contact along its motion (the closed forms of time_of_impact.h, called), and the
// placement of a shape on a moving frame.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "collision_response/core/time_of_impact.h"
#include "geometry/narrow_phase.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;

const auto kNoApproach = [] { return V(V::Zero()); };

PlacedShape atRest(const Shape& shape, const V& origin) {
  PlacedShape placed;
  placed.shape = shape;
  placed.pose.transform.translation() = origin;
  return placed;
}

TEST(NarrowPhase, BallAbovePlane) {
  PlacedShape floor = atRest(Plane{V::UnitZ(), 0.5}, V(0, 0, 0.5));
  floor.pose.velocity = V(1, 0, 0);
  floor.pose.angular_velocity = V(0, 0, 2);
  const ContactGeometry g = contactGeometry(V(1, 2, 3), 0.25, floor, 1e-9, kNoApproach);
  ASSERT_TRUE(g.valid);
  EXPECT_EQ(g.normal, V(0, 0, -1));
  EXPECT_EQ(g.gap, 3 - 0.5 - 0.25);
  EXPECT_TRUE(g.flat());
  // The middle of the gap: between the ball's surface (z = 2.75) and the plane's (z = 0.5).
  EXPECT_EQ(g.point, V(1, 2, 1.625));
  // v + w x r, r from the pose's origin (0, 0, 0.5) to the point.
  EXPECT_EQ(g.surface_velocity, V(1, 0, 0) + V(0, 0, 2).cross(V(1, 2, 1.125)));
}

TEST(NarrowPhase, BallBesideSphere) {
  const PlacedShape post = atRest(Sphere{V(3, 0, 0), 1.0}, V(3, 0, 0));
  const ContactGeometry g = contactGeometry(V(0, 0, 0), 0.5, post, 1e-9, kNoApproach);
  ASSERT_TRUE(g.valid);
  EXPECT_EQ(g.normal, V(1, 0, 0));
  EXPECT_EQ(g.gap, 1.5);
  EXPECT_EQ(g.curvature, 1.0 / 3.0);
  EXPECT_FALSE(g.flat());
  EXPECT_EQ(g.point, V(1.25, 0, 0));  // between the surfaces at x = 0.5 and x = 2
  EXPECT_EQ(g.surface_velocity, V::Zero());
}

// Impacts, lasting contacts and stepped clusters record this one point; between two spheres it
// is the same bits whichever is the ball (renaming bodies swaps pairs' sides), and for touching
// surfaces it is where they touch.
TEST(NarrowPhase, OneContactPointWhicheverSphereIsTheBall) {
  const V a(0.1, -0.3, 0.7), b(0.4, 0.2, 1.3);
  const double ra = 0.3, rb = 0.5;
  const ContactGeometry ab = contactGeometry(a, ra, atRest(Sphere{b, rb}, b), 1e-9, kNoApproach);
  const ContactGeometry ba = contactGeometry(b, rb, atRest(Sphere{a, ra}, a), 1e-9, kNoApproach);
  EXPECT_EQ(ab.point, ba.point);
  EXPECT_NEAR((ab.point - (a + (ra + 0.5 * ab.gap) * ab.normal)).norm(), 0, 1e-15);
  const V touching(0, 0, 0.3);
  const ContactGeometry on_floor =
      contactGeometry(touching, 0.3, atRest(Plane{V::UnitZ(), 0.0}, V::Zero()), 1e-9, kNoApproach);
  EXPECT_EQ(on_floor.gap, 0.0);
  EXPECT_EQ(on_floor.point, V::Zero());
}

TEST(NarrowPhase, CoincidentCentresTakeTheApproachOrNone) {
  const PlacedShape post = atRest(Sphere{V(1, 1, 1), 1.0}, V(1, 1, 1));
  const ContactGeometry along =
      contactGeometry(V(1, 1, 1), 0.5, post, 1e-9, [] { return V(0, 2, 0); });
  ASSERT_TRUE(along.valid);
  EXPECT_EQ(along.normal, V(0, 1, 0));
  EXPECT_EQ(along.gap, -1.5);
  const ContactGeometry none = contactGeometry(V(1, 1, 1), 0.5, post, 1e-9, kNoApproach);
  EXPECT_FALSE(none.valid);
  EXPECT_FALSE(none.flat());  // the line of centres turns at any motion
}

TEST(NarrowPhase, FirstContactIsTheClosedForms) {
  BallMotion ball;
  ball.centre = V(0, 0, 2);
  ball.radius = 0.5;
  ball.velocity = V(1, 0, -3);
  ball.acceleration = V(0, 0, -9.81);
  const PlacedShape floor = atRest(Plane{V::UnitZ(), 0.0}, V::Zero());
  EXPECT_EQ(firstContact(ball, floor, V::Zero(), V::Zero(), false, 10.0),
            timeOfImpactPlane(1.5, -3.0, 10.0));
  EXPECT_EQ(firstContact(ball, floor, V::Zero(), V::Zero(), true, 10.0),
            timeOfImpactPlaneBallistic(1.5, -3.0, -9.81, 10.0));
  const PlacedShape post = atRest(Sphere{V(2, 0, 0), 0.5}, V(2, 0, 0));
  EXPECT_EQ(firstContact(ball, post, V::Zero(), V::Zero(), false, 10.0),
            timeOfImpactSpheres<double>(V(2, 0, -2), V(-1, 0, 3), 1.0, 10.0));
  EXPECT_EQ(firstContact(ball, post, V::Zero(), V::Zero(), true, 10.0),
            timeOfImpactSpheresAccelerated(V(2, 0, -2), V(-1, 0, 3), V(0, 0, 9.81), 1.0, 10.0));
}

TEST(NarrowPhase, ShapesPlacedOnATurnedMovingFrame) {
  RigidPose frame;
  frame.time = 2.0;
  frame.transform = Eigen::Translation3d(1, 0, 0) * Eigen::AngleAxisd(M_PI / 2, V::UnitZ());
  frame.velocity = V(0, 1, 0);
  frame.angular_velocity = V(0, 0, 1);
  ObstacleSpec spec;
  spec.shape = ObstacleShape::kPlane;
  spec.normal = V(2, 0, 0);  // x = 0.5 in the frame
  spec.offset = 0.5;
  const PlacedShape wall = place(spec, frame);
  const Plane& plane = std::get<Plane>(wall.shape);
  EXPECT_NEAR((plane.normal - V(0, 1, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR(plane.offset, 0.5, 1e-15);
  EXPECT_EQ(wall.pose.time, 2.0);
  EXPECT_NEAR((wall.pose.velocity - V(-0.5, 1, 0)).norm(), 0, 1e-15);
  spec.shape = ObstacleShape::kSphere;
  spec.position = V(1, 0, 0);
  spec.radius = 0.25;
  const PlacedShape ball = place(spec, frame);
  const Sphere& sphere = std::get<Sphere>(ball.shape);
  EXPECT_NEAR((sphere.centre - V(1, 1, 0)).norm(), 0, 1e-15);
  EXPECT_EQ(sphere.radius, 0.25);
  // Moved on: straight along the centre's velocity.
  const PlacedShape later = shapeAt(ball, 3.0);
  EXPECT_NEAR((std::get<Sphere>(later.shape).centre - V(0, 2, 0)).norm(), 0, 1e-15);
}

TEST(NarrowPhase, ShapeNumbersCheckedByTheirKeys) {
  const auto field = [](const char* key) { return std::string("~scene/obstacles[0]/") + key; };
  const Status zero = checkShape(Plane{V::Zero(), 0.0}, field);
  ASSERT_FALSE(zero);
  EXPECT_EQ(zero.error().field, "~scene/obstacles[0]/normal");
  const Status radius = checkShape(Sphere{V::Zero(), -1.0}, field);
  ASSERT_FALSE(radius);
  EXPECT_EQ(radius.error().field, "~scene/obstacles[0]/radius");
  EXPECT_TRUE(checkShape(Sphere{V::Zero(), 1.0}, field));
  EXPECT_EQ(std::get<Plane>(normalized(Plane{V(0, 0, 1e-200), 1.0})).normal, V::UnitZ());
}

// The tables over the kinds of both sides: the sphere's row (a ball against every kind) is
// filled, its column by reversal of that row; every other pair is not yet, and says so naming
// both kinds.
TEST(NarrowPhaseTable, EverySphereEntryIsFilledAndTheRestNotYet) {
  const ShapeKind sphere = ShapeKind::kSphere;
  for (std::size_t i = 0; i < kShapeKinds; ++i) {
    const ShapeKind kind = static_cast<ShapeKind>(i);
    const NarrowPhaseEntry& row = narrowPhaseEntry(sphere, kind);
    EXPECT_NE(row.contact, nullptr) << kindName(kind);
    EXPECT_NE(row.first_contact, nullptr) << kindName(kind);
    EXPECT_FALSE(row.reversed) << kindName(kind);
    const NarrowPhaseEntry& column = narrowPhaseEntry(kind, sphere);
    EXPECT_NE(column.contact, nullptr) << kindName(kind);
    EXPECT_NE(column.first_contact, nullptr) << kindName(kind);
    EXPECT_EQ(column.reversed, kind != sphere) << kindName(kind);
    EXPECT_TRUE(narrowPhaseCovers(sphere, kind, "bodies[0]"));
    EXPECT_TRUE(narrowPhaseCovers(kind, sphere, "bodies[0]"));
    for (std::size_t j = 0; j < kShapeKinds; ++j) {
      const ShapeKind other = static_cast<ShapeKind>(j);
      if (kind == sphere || other == sphere) continue;
      EXPECT_EQ(narrowPhaseEntry(kind, other).contact, nullptr);
      EXPECT_EQ(narrowPhaseEntry(kind, other).first_contact, nullptr);
      const Status covered = narrowPhaseCovers(kind, other, "bodies[2]");
      ASSERT_FALSE(covered);
      EXPECT_EQ(covered.error().field, "bodies[2]");
      EXPECT_EQ(covered.error().reason, std::string("not yet: the contact of a ") + kindName(kind) +
                                            " with a " + kindName(other) +
                                            " (only a ball's contacts are answered yet)");
    }
  }
  EXPECT_STREQ(kindName(ShapeKind::kBox), "box");
  // Not yet: no contact, not a wrong one.
  const PlacedShape box = atRest(Cuboid{V(0.5, 0.5, 0.5)}, V::Zero());
  EXPECT_FALSE(contactGeometry(box, box, 1e-9, kNoApproach).valid);
  EXPECT_FALSE(firstContact(MovingShape{box}, MovingShape{box}, false, 1.0));
}

// One obstacle of each kind, a point p of its surface and its outward normal m there, known by
// construction; the obstacle moves (v = (0.5, 0, 0), w = (0, 0, 1)).
struct KnownSurface {
  PlacedShape placed;
  V point;    // p
  V outward;  // m
};

std::vector<KnownSurface> oneOfEachKind() {
  const auto moving = [](const Shape& shape, const V& origin) {
    PlacedShape placed = atRest(shape, origin);
    placed.pose.velocity = V(0.5, 0, 0);
    placed.pose.angular_velocity = V(0, 0, 1);
    return placed;
  };
  return {
      {moving(Plane{V::UnitZ(), 0.5}, V(0, 0, 0.5)), V(1, 2, 0.5), V::UnitZ()},
      {moving(Sphere{V(3, 0, 0), 1.0}, V(3, 0, 0)), V(2, 0, 0), -V::UnitX()},
      {moving(Cuboid{V(0.5, 0.25, 0.75)}, V(1, 1, 1)), V(1.125, 1.0625, 1.75), V::UnitZ()},
      {moving(Cylinder{0.3, 0.5}, V::Zero()), V(0.3, 0, 0.125), V::UnitX()},
      {moving(Capsule{0.2, 0.4}, V::Zero()), V(0, 0, 0.6), V::UnitZ()},
      {moving(Mesh{scene_builders::cubeMesh(V(0.5, 0.5, 0.5))}, V::Zero()), V(0.125, -0.25, 0.5),
       V::UnitZ()},
  };
}

// A ball of radius R = 0.125 with its centre at p + (R + d) m, d = 0.0625, against each kind, in
// both orders: the gap is d, the point p + (d / 2) m (half-way across the gap), the normal -m
// from the ball into the obstacle and +m from the obstacle into the ball, the surface velocity
// that of the second side at the point (v + w x r of its pose). The ball's own entry of the
// sphere's row is today's ball code to the bit.
TEST(NarrowPhaseTable, AReversedEntryGivesTheSameContactWithTheNormalReversed) {
  const double radius = 0.125, gap = 0.0625;
  for (const KnownSurface& known : oneOfEachKind()) {
    const std::size_t kind = known.placed.shape.index();
    const V centre = known.point + (radius + gap) * known.outward;
    PlacedShape ball = atRest(Sphere{centre, radius}, centre);
    ball.pose.velocity = V(0, -1, 2);
    ball.pose.angular_velocity = V(3, 0, 0);
    const V point = known.point + (0.5 * gap) * known.outward;
    const auto velocityOf = [&](const PlacedShape& side) -> V {
      return side.pose.velocity +
             side.pose.angular_velocity.cross(point - side.pose.transform.translation());
    };
    const ContactGeometry forward = contactGeometry(ball, known.placed, 1e-9, kNoApproach);
    const ContactGeometry reversed = contactGeometry(known.placed, ball, 1e-9, kNoApproach);
    ASSERT_TRUE(forward.valid) << kind;
    ASSERT_TRUE(reversed.valid) << kind;
    EXPECT_NEAR(forward.gap, gap, 1e-15) << kind;
    EXPECT_NEAR(reversed.gap, gap, 1e-15) << kind;
    EXPECT_LT((forward.normal + known.outward).norm(), 1e-15) << kind;
    EXPECT_LT((reversed.normal - known.outward).norm(), 1e-15) << kind;
    EXPECT_LT((forward.point - point).norm(), 1e-15) << kind;
    EXPECT_LT((reversed.point - point).norm(), 1e-15) << kind;
    EXPECT_LT((forward.surface_velocity - velocityOf(known.placed)).norm(), 1e-14) << kind;
    EXPECT_LT((reversed.surface_velocity - velocityOf(ball)).norm(), 1e-14) << kind;
    EXPECT_EQ(forward.curvature, reversed.curvature) << kind;
    EXPECT_EQ(forward.tolerance, reversed.tolerance) << kind;
    // The sphere's row is the ball code.
    const ContactGeometry direct = contactGeometry(centre, radius, known.placed, 1e-9, kNoApproach);
    EXPECT_EQ(forward.gap, direct.gap) << kind;
    EXPECT_EQ(forward.normal, direct.normal) << kind;
    EXPECT_EQ(forward.point, direct.point) << kind;
    EXPECT_EQ(forward.surface_velocity, direct.surface_velocity) << kind;
  }
}

// The lever arms (ContactPoint's r_a, r_b) of the same ball against each kind: the ball's is
// R n = -R m (from its centre to its surface point), the obstacle's p - its pose origin (for the
// sphere, -R_s n: the point (2, 0, 0) of the sphere about (3, 0, 0) of radius 1); in the other
// order the two swap, to the bit.
TEST(NarrowPhaseTable, TheLeverArmsGoFromEachCentreToItsOwnSurfacePoint) {
  const double radius = 0.125, gap = 0.0625;
  for (const KnownSurface& known : oneOfEachKind()) {
    const std::size_t kind = known.placed.shape.index();
    const V centre = known.point + (radius + gap) * known.outward;
    const PlacedShape ball = atRest(Sphere{centre, radius}, centre);
    const ContactGeometry forward = contactGeometry(ball, known.placed, 1e-9, kNoApproach);
    const ContactGeometry reversed = contactGeometry(known.placed, ball, 1e-9, kNoApproach);
    ASSERT_TRUE(forward.valid) << kind;
    ASSERT_TRUE(reversed.valid) << kind;
    EXPECT_LT((forward.lever_a + radius * known.outward).norm(), 1e-15) << kind;
    EXPECT_LT((forward.lever_b - (known.point - known.placed.pose.transform.translation())).norm(),
              1e-15)
        << kind;
    EXPECT_EQ(reversed.lever_a, forward.lever_b) << kind;
    EXPECT_EQ(reversed.lever_b, forward.lever_a) << kind;
  }
}

// The same ball moving at 2 m/s along -m towards each (still) obstacle, in both orders: it
// touches when it has crossed the gap d, at d / 2 = 0.03125 s; the sphere's row is the ball
// code's instant to the bit.
TEST(NarrowPhaseTable, AReversedFirstContactIsTheSameInstant) {
  const double radius = 0.125, gap = 0.0625, speed = 2.0;
  for (const KnownSurface& known : oneOfEachKind()) {
    const std::size_t kind = known.placed.shape.index();
    const V centre = known.point + (radius + gap) * known.outward;
    const MovingShape ball{atRest(Sphere{centre, radius}, centre), -speed * known.outward,
                           V::Zero()};
    MovingShape obstacle{known.placed};
    obstacle.placed.pose.velocity = V::Zero();
    obstacle.placed.pose.angular_velocity = V::Zero();
    const std::optional<double> forward = firstContact(ball, obstacle, false, 1.0);
    const std::optional<double> reversed = firstContact(obstacle, ball, false, 1.0);
    ASSERT_TRUE(forward) << kind;
    ASSERT_TRUE(reversed) << kind;
    EXPECT_NEAR(*forward, gap / speed, 1e-12) << kind;
    EXPECT_EQ(*forward, *reversed) << kind;
    BallMotion motion;
    motion.centre = centre;
    motion.radius = radius;
    motion.velocity = ball.velocity;
    EXPECT_EQ(*forward, firstContact(motion, obstacle.placed, V::Zero(), V::Zero(), false, 1.0))
        << kind;
  }
}

}  // namespace
}  // namespace collision_response::core
