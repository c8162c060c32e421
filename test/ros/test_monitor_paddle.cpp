// A ball against a moving tf-attached paddle, over real topics and tf. Closed form: the ball at
// x = t (1 m/s), radius 0.033; the paddle, a sphere of radius 0.08 at paddle_link, which moves
// at x = 1 - 0.5 t. The gap 1 - 0.113 = 0.887 m closes at 1.5 m/s: contact at t = 0.887 / 1.5.
// Tennis ball on wood, unmeasured pair, rule min: e = min(0.712, 0.603) = 0.603. The paddle is
// immovable: v' = v_p + e (v_p - v) = -0.5 + 0.603 (-1.5) = -1.4045 m/s; it keeps -0.5 m/s.
#include "monitor_harness.h"

namespace collision_response::testing {
namespace {

TEST(MonitorPaddle, BallAgainstAMovingPaddleFromTf) {
  MonitorHarness harness;
  ASSERT_TRUE(harness.connect());
  const ros::Time start = baseStamp();
  tf2_ros::TransformBroadcaster broadcaster;
  ros::WallDuration(0.5).sleep();
  for (int k = -50; k <= 150; ++k) {  // every 0.01 s from -0.5 s to 1.5 s
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translate(Eigen::Vector3d(1.0 - 0.5 * 0.01 * k, 0, 0));
    broadcaster.sendTransform(
        makeTransform(start + ros::Duration(0.01 * k), "world", "paddle_link", pose));
    if (k % 20 == 0) ros::WallDuration(0.01).sleep();
  }
  ros::WallDuration(0.5).sleep();
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.1 * k;
    harness.publish(start + ros::Duration(0, 100000000 * k),
                    {StateSpec{"ball", Eigen::Vector3d(t, 0, 0), Eigen::Vector3d(1, 0, 0)}});
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_TRUE(harness.waitForImpact("ball"));
  ros::WallDuration(0.3).sleep();
  ros::spinOnce();
  const std::vector<Impact> impacts = harness.impactsOf("ball");
  ASSERT_EQ(impacts.size(), 1u);
  const Impact& impact = impacts[0];
  EXPECT_EQ(impact.body_b, "paddle");
  EXPECT_NEAR((impact.header.stamp - start).toSec(), 0.887 / 1.5, 1e-9);
  EXPECT_EQ(impact.restitution, 0.603);
  EXPECT_NEAR(impact.velocity_b_before.linear.x, -0.5, 1e-9);
  EXPECT_NEAR(impact.velocity_a_after.linear.x, -0.5 + 0.603 * (-1.5), 1.4045e-9);
  EXPECT_NEAR(impact.velocity_b_after.linear.x, -0.5, 1e-9);
  // Contact on the ball's surface toward the paddle: x = t + 0.033.
  EXPECT_NEAR(impact.contact_point.x, 0.887 / 1.5 + 0.033, 1e-9);
  // Energy lost, in the paddle's frame: (1/2) m (1 - e^2) d^2 with d = 1.5 m/s.
  EXPECT_NEAR(impact.energy_lost, 0.5 * 0.057 * (1 - 0.603 * 0.603) * 2.25, 1e-9);
}

}  // namespace
}  // namespace collision_response::testing

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "monitor_paddle_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
