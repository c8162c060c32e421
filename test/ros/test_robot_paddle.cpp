// A ball against a robot's link over real tf (test/ros/robot_paddle.test): the paddle, a box of
// the URDF's link `paddle` made an obstacle by the scene's `robot:` key, moves at -0.5 m/s along
// x (a prismatic joint driven through robot_state_publisher); the ball flies at +1 m/s into its
// -x face. Tennis ball on wood, rule min: e = min(0.712, 0.603) = 0.603. The paddle is immovable:
// v' = v_p + e (v_p - v) = -0.5 + 0.603 (-1.5) = -1.4045 m/s along x; the line of impact +x.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <map>

#include "collision_response/ImpactArray.h"

namespace {

TEST(RobotPaddle, ABallOffAURDFLinkMovedByItsJointOverTf) {
  ros::NodeHandle node;
  std::vector<collision_response::Impact> impacts;
  ros::Subscriber subscriber = node.subscribe<collision_response::ImpactArray>(
      "impacts", 100, [&](const collision_response::ImpactArray::ConstPtr& array) {
        for (const auto& impact : array->impacts) impacts.push_back(impact);
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(60.0);
  while (ros::ok() && ros::WallTime::now() < end && impacts.empty()) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_FALSE(impacts.empty()) << "the ball never met the paddle";
  const collision_response::Impact& impact = impacts.front();
  EXPECT_EQ(impact.body_a, "ball");
  EXPECT_EQ(impact.body_b, "paddle");  // the link's one <collision>: named as the link
  EXPECT_NEAR(impact.normal.x, 1.0, 1e-9);
  EXPECT_EQ(impact.restitution, 0.603);
  // The paddle's velocity from tf, and the ball's after.
  EXPECT_NEAR(impact.velocity_b_before.linear.x, -0.5, 1e-6);
  EXPECT_NEAR(impact.velocity_a_after.linear.x, -0.5 + 0.603 * (-1.5), 1e-6);
  EXPECT_NEAR(impact.velocity_a_after.linear.y, 0.0, 1e-9);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "robot_paddle_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
