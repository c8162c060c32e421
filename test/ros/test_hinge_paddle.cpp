// A ball at rest struck by a paddle swung about a hinge over real tf (test/ros/hinge_paddle.test):
// the paddle is a box of the URDF's link `paddle` (faces at x = +-0.01 in the link's frame), its
// revolute joint about z at the origin turned at w = 2 rad/s through robot_state_publisher. The
// ball (r = 0.033) rests at p = (-0.06, 0.25, 0). In the link's frame, turned by theta, the
// ball's centre is at q_x = p_x cos theta + p_y sin theta, which the paddle's -x face grown by r
// reaches where q_x = -(0.01 + r): with rho = |p| and beta its angle, cos(theta - beta) =
// -(0.01 + r) / rho, the first theta after -0.5 rad (about 0.068 rad). There the line of impact
// is the link's x axis n = (cos theta, sin theta, 0), the ball at q_y = -p_x sin theta + p_y cos
// theta along the face, whose point there moves at w z x x_c: along n, u_s = -w q_y. Tennis ball
// on wood, rule min: e = 0.603; the ball at rest leaves at (1 + e) u_s n. None of this depends
// on when tf's transforms arrive: the paddle meets the ball where it has turned to it, and the
// node follows the paddle's turning between transforms (a paddle moved straight on between them
// would be met elsewhere, at another normal).
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cmath>
#include <vector>

#include "collision_response/ImpactArray.h"

namespace {

TEST(HingePaddle, ABallOffAPaddleSwungByItsJointAtTheClosedForm) {
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
  ASSERT_FALSE(impacts.empty()) << "the paddle never met the ball";
  const collision_response::Impact& impact = impacts.front();
  EXPECT_EQ(impact.body_a, "ball");
  EXPECT_EQ(impact.body_b, "paddle");
  using LD = long double;
  const LD w = 2, px = -0.06L, py = 0.25L, r = 0.033L, e = 0.603L;
  const LD rho = std::hypot(px, py), beta = std::atan2(py, px);
  const LD theta = beta - std::acos(-(0.01L + r) / rho);
  ASSERT_GT(theta, -0.5L);
  const LD nx = std::cos(theta), ny = std::sin(theta);
  const LD along = -px * std::sin(theta) + py * std::cos(theta);
  const LD u_s = -w * along;
  // To tf's finite differences (the frame's angular velocity; 1e-6 in this test's runs).
  EXPECT_NEAR(impact.normal.x, static_cast<double>(nx), 1e-5);
  EXPECT_NEAR(impact.normal.y, static_cast<double>(ny), 1e-5);
  EXPECT_EQ(impact.restitution, 0.603);
  // The face's point under the ball: x_c = -0.01 n + along (-n_y, n_x, 0), moving at w z x x_c
  // (a paddle moved straight on between transforms: 6e-3 m/s off in y, found by this test).
  const LD xc = -0.01L * nx - along * ny, yc = -0.01L * ny + along * nx;
  EXPECT_NEAR(impact.velocity_b_before.linear.x, static_cast<double>(-w * yc), 1e-5);
  EXPECT_NEAR(impact.velocity_b_before.linear.y, static_cast<double>(w * xc), 1e-5);
  EXPECT_NEAR(impact.velocity_a_after.linear.x, static_cast<double>((1 + e) * u_s * nx), 1e-5);
  EXPECT_NEAR(impact.velocity_a_after.linear.y, static_cast<double>((1 + e) * u_s * ny), 1e-5);
  EXPECT_NEAR(impact.velocity_a_after.linear.z, 0.0, 1e-9);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "hinge_paddle_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
