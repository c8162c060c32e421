// Two boxes sliding into each other, then one into a wall and the other into a ball, played
// through demo.launch over real topics (config/scenes/box_collide.yaml): cubes of 0.125 m on a
// frictionless floor, 'left' (0.5 kg) from x = -0.3 m at +1 m/s, 'right' (1 kg, a mesh body:
// meshes/cube.stl, its hull the cube) from x = +0.3 m at -0.5 m/s, e = 1/2 for every pair, a
// wall at x = 0.425 m. Closed forms:
//  - the faces meet at t1 = (0.6 - 0.125) / 1.5 s, four corners at once; along the line of
//    impact (no lever arm about any axis: the corners are symmetric about the line of centres)
//    v_l' = (m_l v_l + m_r v_r - m_r e (v_l - v_r)) / (m_l + m_r) = -0.5 m/s and v_r' = v_l' +
//    e (v_l - v_r) = 0.25 m/s, without turning;
//  - 'right', sliding on at 0.25 m/s from x = 0.3 - 0.5 t1, reaches the wall at t2 = t1 + (0.425
//    - 0.0625 - 0.3 + 0.5 t1) / 0.25 = 1.2 s and leaves at -0.125 m/s.
//  - 'left', sliding back at -0.5 m/s from x = -0.3 + t1, strikes the ball at rest (0.25 kg,
//    radius 0.0625 m, at x = -0.5 m: its centre at the cubes' height, on the line of impact) at
//    t3 = t1 + (-0.3 + t1 + 0.375) / 0.5 = 1.1 s, leaving at (m_l - e m_b) v / (m_l + m_b) =
//    -0.25 m/s and the ball at (1 + e) m_l v / (m_l + m_b) = -0.5 m/s: a ball among shaped bodies
//    moves as a rigid sphere, and a box and a ball strike each other (before, it went through).
// The instants are read from the stamps (the node's impacts against the player's first state):
// ROS stamps are whole nanoseconds, and the player applies the node's impact from its stamp, so
// the wall's instant is off by up to 0.5e-9 s times 0.5 / 0.25 (held to 1e-8 s).
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"
#include "collision_response/PredictImpacts.h"

namespace {

constexpr double kE = 0.5, kHalf = 0.0625, kWall = 0.425, kRadius = 0.0625;

TEST(BoxCollide, TheNodesImpactsAreTheClosedFormsAndNoBodyEntersAnother) {
  ros::NodeHandle node;
  std::vector<collision_response::Impact> impacts;
  ros::Time start;
  double last_time = 0, worst_overlap = -INFINITY, worst_wall = -INFINITY, worst_floor = 0;
  double worst_ball = -INFINITY;
  double largest_spin = 0;
  ros::Subscriber impact_subscriber = node.subscribe<collision_response::ImpactArray>(
      "impacts", 100, [&](const collision_response::ImpactArray::ConstPtr& array) {
        impacts.insert(impacts.end(), array->impacts.begin(), array->impacts.end());
      });
  ros::Subscriber states = node.subscribe<collision_response::BodyStateArray>(
      "body_states", 1000, [&](const collision_response::BodyStateArray::ConstPtr& array) {
        if (start.isZero()) start = array->header.stamp;
        std::map<std::string, double> x;
        for (const auto& state : array->states) {
          x[state.id] = state.pose.position.x;
          const auto& w = state.twist.angular;
          largest_spin = std::max(largest_spin, std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z));
          worst_floor = std::max(worst_floor, std::abs(state.pose.position.z - kHalf));
        }
        if (x.count("left") && x.count("right")) {
          worst_overlap = std::max(worst_overlap, (x["left"] + kHalf) - (x["right"] - kHalf));
          worst_wall = std::max(worst_wall, x["right"] + kHalf - kWall);
        }
        if (x.count("left") && x.count("ball")) {
          worst_ball = std::max(worst_ball, (x["ball"] + kRadius) - (x["left"] - kHalf));
        }
        last_time = (array->header.stamp - start).toSec();
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(40.0);
  while (ros::ok() && ros::WallTime::now() < end && last_time < 1.45) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  std::vector<collision_response::Impact> pair, wall, ball;
  for (const auto& impact : impacts) {
    if (impact.body_b == "right") pair.push_back(impact);
    if (impact.body_b == "wall") wall.push_back(impact);
    if (impact.body_a == "ball" || impact.body_b == "ball") ball.push_back(impact);
  }
  ASSERT_EQ(pair.size(), 4u) << "the faces' four corners at once";
  for (const auto& impact : pair) {
    EXPECT_EQ(impact.body_a, "left");
    EXPECT_NEAR((impact.header.stamp - start).toSec(), 0.475 / 1.5, 2e-9);
    EXPECT_NEAR(impact.velocity_a_before.linear.x, 1.0, 1e-12);
    EXPECT_NEAR(impact.velocity_b_before.linear.x, -0.5, 1e-12);
    EXPECT_NEAR(impact.velocity_a_after.linear.x, -0.5, 1e-12);
    EXPECT_NEAR(impact.velocity_b_after.linear.x, 0.25, 1e-12);
    EXPECT_NEAR(std::abs(impact.velocity_a_after.linear.z), 0, 1e-12);
    EXPECT_NEAR(std::abs(impact.normal.x), 1.0, 1e-15);
  }
  ASSERT_EQ(wall.size(), 4u) << "the face's four corners at once";
  for (const auto& impact : wall) {
    EXPECT_EQ(impact.body_a, "right");
    EXPECT_NEAR((impact.header.stamp - start).toSec(), 1.2, 1e-8);
    EXPECT_NEAR(impact.velocity_a_before.linear.x, 0.25, 1e-9);
    EXPECT_NEAR(impact.velocity_a_after.linear.x, -kE * 0.25, 1e-9);
  }
  ASSERT_EQ(ball.size(), 1u) << "the ball's one point";
  {
    const bool ball_first = ball[0].body_a == "ball";
    const auto& left_after = ball_first ? ball[0].velocity_b_after : ball[0].velocity_a_after;
    const auto& ball_after = ball_first ? ball[0].velocity_a_after : ball[0].velocity_b_after;
    EXPECT_EQ(ball_first ? ball[0].body_b : ball[0].body_a, "left");
    // 'left' came from the pair's impact, whose instant the stamps carry to 1e-9 s.
    EXPECT_NEAR((ball[0].header.stamp - start).toSec(), 1.1, 1e-8);
    EXPECT_NEAR(left_after.linear.x, -0.25, 1e-12);
    EXPECT_NEAR(ball_after.linear.x, -0.5, 1e-12);
    EXPECT_NEAR(std::abs(ball_after.linear.y) + std::abs(ball_after.linear.z), 0, 1e-12);
  }
  EXPECT_LT(largest_spin, 1e-12) << "no box turns, nor the ball";
  EXPECT_LE(worst_ball, 1e-9) << "a played ball inside 'left'";
  EXPECT_LE(worst_overlap, 1e-9) << "a played 'left' inside 'right'";
  EXPECT_LE(worst_wall, 1e-9) << "a played 'right' inside the wall";
  EXPECT_LT(worst_floor, 1e-9) << "all slide on the floor";

  // A prediction holds the other bodies where the node has them, each of its shape: at 1.45 s
  // 'right' (a mesh body, its hull the cube) slides at -0.125 m/s from the wall, its centre at
  // 0.425 - 0.0625 - 0.125 (1.45 - 1.2) = 0.33125 m. A probe ball (r = 0.0625 m) on the
  // frictionless floor at y = 0.5 m over that x, sliding at -1 m/s along y, meets its face y =
  // 0.0625 when its centre is at y = 0.125, at 0.375 s, and leaves at +e 1 m/s (the held box is
  // immovable). Held as a sphere of its radius (0), as before, it would meet it at 0.4375 s.
  collision_response::PredictImpacts probe;
  probe.request.header.frame_id = "world";
  probe.request.header.stamp = start + ros::Duration(1.45);
  probe.request.body.id = "probe";
  probe.request.body.mass = 0.1;
  probe.request.body.radius = kRadius;
  probe.request.body.material = "block";
  probe.request.body.position.x = 0.33125;
  probe.request.body.position.y = 0.5;
  probe.request.body.position.z = kRadius;
  probe.request.body.velocity.y = -1.0;
  probe.request.horizon = 1.0;
  probe.request.max_impacts = 1;
  ASSERT_TRUE(ros::service::call("/collision_response/predict_impacts", probe));
  ASSERT_TRUE(probe.response.success) << probe.response.message;
  ASSERT_EQ(probe.response.impacts.size(), 1u) << probe.response.message;
  const collision_response::Impact& held = probe.response.impacts[0];
  EXPECT_EQ(held.body_b, "right");
  EXPECT_NEAR((held.header.stamp - probe.request.header.stamp).toSec(), 0.375, 1e-8);
  EXPECT_NEAR(held.velocity_a_after.linear.y, kE * 1.0, 1e-9);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "box_collide_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
