// The narrow phase's dispatch: for each shape, the contact geometry of a ball at an instant, the
// first contact along its motion (the closed forms of time_of_impact.h, called), and the
// placement of a shape on a moving frame.
#include <gtest/gtest.h>

#include <cmath>

#include "collision_response/core/time_of_impact.h"
#include "geometry/narrow_phase.h"

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

}  // namespace
}  // namespace collision_response::core
