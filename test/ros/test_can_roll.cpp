// A can rolling off a table on its side, played through demo.launch over real topics
// (config/scenes/can_roll.yaml): a cylinder of r = 0.033 m lying on a frictionless table whose top
// is at z = 0.75 m and whose edge is at x = 1, its axis along the edge, its centre 0.2 m from it,
// sliding out at v = 0.3 m/s, g = 9.81. Closed forms:
//  - its side reaches the edge at 0.2 / v;
//  - it turns over the edge, its centre on the circle of radius r about the edge's line, with
//    r theta'^2 = v^2 / r + 2 g (1 - cos theta) (no friction: its energy kept, no turn about its
//    axis), until the edge's force m (g cos theta - r theta'^2) is 0 at
//    cos theta = (2 g r + v^2) / (3 g r), after the integral of dtheta / theta' (the test's
//    quadrature);
//  - it flies from there at sqrt(g r cos theta) along the circle's tangent, and lands on its side
//    where its centre is r above the floor.
// The instant is read from the stamps (whole nanoseconds); the turn is integrated to the scene's
// contact_integration_tolerance (1e-9).
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"
#include "quadrature.h"

namespace {

constexpr double kG = 9.81, kR = 0.033, kSpeed = 0.3, kTop = 0.75, kEdge = 1.0, kFromEdge = 0.2;

TEST(CanRoll, ItLandsOnTheFloorAtTheClosedFormsInstantNeverInsideTheTable) {
  ros::NodeHandle node;
  std::vector<collision_response::Impact> impacts;
  ros::Time start;
  double last_time = 0, worst_table = -INFINITY, worst_floor = -INFINITY;
  ros::Subscriber impact_subscriber = node.subscribe<collision_response::ImpactArray>(
      "impacts", 100, [&](const collision_response::ImpactArray::ConstPtr& array) {
        impacts.insert(impacts.end(), array->impacts.begin(), array->impacts.end());
      });
  ros::Subscriber states = node.subscribe<collision_response::BodyStateArray>(
      "body_states", 1000, [&](const collision_response::BodyStateArray::ConstPtr& array) {
        if (start.isZero()) start = array->header.stamp;
        for (const auto& state : array->states) {
          if (state.id != "can") continue;
          // Its side (its axis along y, level): how far it is inside the table's top-and-edge
          // corner (x <= 1, z <= 0.75) and the floor, > 0 inside.
          const auto& c = state.pose.position;
          const double out = std::max(c.x - kEdge, 0.0), up = std::max(c.z - kTop, 0.0);
          worst_table = std::max(worst_table, kR - std::hypot(out, up));
          worst_floor = std::max(worst_floor, kR - c.z);
          last_time = (array->header.stamp - start).toSec();
        }
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(40.0);
  while (ros::ok() && ros::WallTime::now() < end && last_time < 1.2) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_FALSE(impacts.empty()) << "the landing on the floor";

  const double leaves = std::acos((2 * kG * kR + kSpeed * kSpeed) / (3 * kG * kR));
  const double turned = collision_response::core::quadrature::gaussLegendre(
      [](double theta) {
        return 1 / std::sqrt(kSpeed * kSpeed / (kR * kR) + 2 * kG * (1 - std::cos(theta)) / kR);
      },
      0.0, leaves, 400);
  const double speed = std::sqrt(kG * kR * std::cos(leaves));
  const double height = kTop + kR * std::cos(leaves) - kR, down = speed * std::sin(leaves);
  const double falls = std::sqrt(down * down + 2 * kG * height);
  const double lands = kFromEdge / kSpeed + turned + (falls - down) / kG;
  const collision_response::Impact& landing = impacts.front();
  EXPECT_EQ(landing.body_a, "can");
  EXPECT_EQ(landing.body_b, "floor");
  EXPECT_NEAR((landing.header.stamp - start).toSec(), lands, 1e-8);
  EXPECT_NEAR(landing.velocity_a_before.linear.x, speed * std::cos(leaves), 1e-8);
  EXPECT_NEAR(landing.velocity_a_before.linear.z, -falls, 1e-8);
  EXPECT_NEAR(landing.contact_point.z, 0, 1e-9);
  EXPECT_LT(worst_table, 1e-9) << "a played state inside the table";
  EXPECT_LT(worst_floor, 1e-9) << "a played state inside the floor";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "can_roll_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
