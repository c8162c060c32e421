// A box at rest struck by a robot's link, played through demo.launch over real topics
// (config/scenes/box_strike.yaml): a 0.1 m cube of 0.5 kg at rest on a frictionless floor, e =
// 1/2, and a flat paddle on the tf frame paddle_link moving at v_o = 0.8 m/s along x, its face d
// = 0.04 m behind the cube's. Closed form: the paddle reaches the cube at d / v_o = 0.05 s, its
// back face's four corners at once; struck by an immovable body moving at v_o along the normal
// through its centre, the cube leaves at (1 + e) v_o = 1.2 m/s without turning. Before, the
// cube's rest watched the floor alone and the paddle went through it. The player does not place
// tf-attached obstacles: its states follow the strike once it hears the node's impact. Held to
// 1e-6 (s, m/s, m): the node takes the link's velocity from tf, a difference of positions
// stamped in whole nanoseconds over its 1 ms placements (up to 2 x 0.5e-9 s x 0.8 m/s / 1e-3 s =
// 8e-7 m/s off).
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"

namespace {

constexpr double kE = 0.5, kHalf = 0.05, kSpeed = 0.8, kGap = 0.04, kPaddleFace = -0.09;

TEST(BoxStrike, TheLinkStrikesTheBoxAtTheClosedFormsInstantAndSpeed) {
  ros::NodeHandle node;
  std::vector<collision_response::Impact> impacts;
  ros::Time start;
  double last_time = 0, worst_inside = -INFINITY, worst_floor = 0, largest_spin = 0;
  double worst_path = 0, last_speed = 0;
  ros::Subscriber impact_subscriber = node.subscribe<collision_response::ImpactArray>(
      "impacts", 100, [&](const collision_response::ImpactArray::ConstPtr& array) {
        impacts.insert(impacts.end(), array->impacts.begin(), array->impacts.end());
      });
  ros::Subscriber states = node.subscribe<collision_response::BodyStateArray>(
      "body_states", 1000, [&](const collision_response::BodyStateArray::ConstPtr& array) {
        if (start.isZero()) start = array->header.stamp;
        last_time = (array->header.stamp - start).toSec();
        for (const auto& state : array->states) {
          if (state.id != "block") continue;
          const double paddle = kPaddleFace + kSpeed * last_time;
          if (state.twist.linear.x > 0) {  // the player has applied the node's impact
            const double strike = kGap / kSpeed;
            worst_path = std::max(worst_path, std::abs(state.pose.position.x -
                                                       (1 + kE) * kSpeed * (last_time - strike)));
            worst_inside = std::max(worst_inside, paddle - (state.pose.position.x - kHalf));
            last_speed = state.twist.linear.x;
          }
          worst_floor = std::max(worst_floor, std::abs(state.pose.position.z - kHalf));
          const auto& w = state.twist.angular;
          largest_spin = std::max(largest_spin, std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z));
        }
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(40.0);
  while (ros::ok() && ros::WallTime::now() < end && last_time < 0.45) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  std::vector<collision_response::Impact> struck;
  for (const auto& impact : impacts) {
    if (impact.body_b == "paddle") struck.push_back(impact);
  }
  ASSERT_EQ(struck.size(), 4u) << "the back face's four corners at once";
  for (const auto& impact : struck) {
    EXPECT_EQ(impact.body_a, "block");
    EXPECT_NEAR((impact.header.stamp - start).toSec(), kGap / kSpeed, 1e-6);
    EXPECT_NEAR(impact.velocity_a_before.linear.x, 0.0, 1e-12);
    EXPECT_NEAR(impact.velocity_a_after.linear.x, (1 + kE) * kSpeed, 1e-6);
    const auto& w = impact.velocity_a_after.angular;
    EXPECT_NEAR(std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z), 0, 1e-9) << "no spin";
  }
  // The player does not place tf-attached obstacles (scene_player.cpp): its states lack the
  // strike until it hears the node's impact, then follow the motion after it.
  EXPECT_LT(worst_path, 1e-6) << "the played box off x = (1 + e) v_o (t - d / v_o)";
  EXPECT_NEAR(last_speed, (1 + kE) * kSpeed, 1e-6);
  EXPECT_LE(worst_inside, 1e-6) << "a played state of the box, struck, inside the paddle";
  EXPECT_LT(worst_floor, 1e-9) << "the box slides on the floor";
  EXPECT_LT(largest_spin, 1e-9);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "box_strike_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
