// Bad input on the monitor's topics, over ROS: each dropped with a warning that names what is
// wrong, no crash, no false impact, and the node still right afterwards (the two-ball closed
// form of test_monitor_frames.cpp: contact 0.43 s after the first state, v' = -0.5 and +0.5).
#include <limits>

#include "collision_response/ComputeCollision.h"
#include "monitor_harness.h"
#include "seed_request.h"

namespace collision_response::testing {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

class MonitorBadInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { base_ = baseStamp(); }
  void SetUp() override { ASSERT_TRUE(harness_.connect()); }
  static ros::Time window() {
    static int next = 0;
    return base_ + ros::Duration(10.0 * next++);
  }

  void playTwoBalls(const ros::Time& start, const std::string& a, const std::string& b, double y) {
    for (int k = 0; k <= 10; ++k) {
      const double t = 0.1 * k;
      harness_.publish(start + ros::Duration(0, 100000000 * k),
                       {StateSpec{a, Eigen::Vector3d(t, y, 0), Eigen::Vector3d(1, 0, 0)},
                        StateSpec{b, Eigen::Vector3d(1.06 - t, y, 0), Eigen::Vector3d(-1, 0, 0)}});
      ros::WallDuration(0.01).sleep();
    }
  }

  void expectTwoBallImpactOnce(const std::string& a, const ros::Time& start) {
    ASSERT_TRUE(harness_.waitForImpact(a));
    ros::WallDuration(0.3).sleep();
    ros::spinOnce();
    const std::vector<Impact> impacts = harness_.impactsOf(a);
    ASSERT_EQ(impacts.size(), 1u);
    EXPECT_NEAR((impacts[0].header.stamp - start).toSec(), 0.43, 1e-9);
    EXPECT_NEAR(impacts[0].velocity_a_after.linear.x, -0.5, 1e-9);
    EXPECT_NEAR(impacts[0].velocity_b_after.linear.x, 0.5, 1e-9);
  }

  void expectNoImpactFor(double seconds) {
    const std::size_t before = harness_.impactCount();
    MonitorHarness::waitFor([] { return false; }, seconds);
    EXPECT_EQ(harness_.impactCount(), before) << "a bad state must not make an impact";
  }

  MonitorHarness harness_;
  static ros::Time base_;
};
ros::Time MonitorBadInput::base_;

TEST_F(MonitorBadInput, NonFiniteValueIsNamed) {
  const ros::Time start = window();
  harness_.publish(start, {StateSpec{"nan_a", Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0)}});
  harness_.publish(start + ros::Duration(0.1),
                   {StateSpec{"nan_a", Eigen::Vector3d(kNan, 0, 0), Eigen::Vector3d(1, 0, 0)}});
  EXPECT_TRUE(harness_.waitForWarning({"nan_a", "pose.position.x", "finite", "nan"}));
  ros::WallDuration(1.1).sleep();  // the warning is throttled to one a second
  BodyStateArray array;
  array.states.push_back(
      makeState(start + ros::Duration(0.2),
                StateSpec{"nan_a", Eigen::Vector3d(0.2, 0, 0), Eigen::Vector3d(0, kNan, 0)}));
  harness_.publishRaw(array);
  EXPECT_TRUE(harness_.waitForWarning({"nan_a", "twist.linear.y"}));
  expectNoImpactFor(0.3);
}

TEST_F(MonitorBadInput, UnknownIdIsNamed) {
  harness_.publish(window(),
                   {StateSpec{"ghost", Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::Zero()}});
  EXPECT_TRUE(harness_.waitForWarning({"ghost", "unknown body"}));
  expectNoImpactFor(0.3);
}

TEST_F(MonitorBadInput, ZeroStampIsNamed) {
  BodyStateArray array;
  array.states.push_back(makeState(
      ros::Time(0), StateSpec{"nan_a", Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::Zero()}));
  harness_.publishRaw(array);
  EXPECT_TRUE(harness_.waitForWarning({"nan_a", "header.stamp", "zero"}));
}

TEST_F(MonitorBadInput, MissingTransformNamesTheFrames) {
  harness_.publish(window(), {StateSpec{"lost_a", Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::Zero(),
                                        "nowhere"}});
  EXPECT_TRUE(harness_.waitForWarning({"lost_a", "nowhere", "world", "after waiting"}));
  expectNoImpactFor(0.3);
}

TEST_F(MonitorBadInput, StampsOutOfOrderAreDroppedWithoutAFalseImpact) {
  const ros::Time start = window();
  playTwoBalls(start, "ooo_a", "ooo_b", 10.0);
  expectTwoBallImpactOnce("ooo_a", start);
  // Late states from before the impact, closing again: dropped, no second impact.
  harness_.publish(start + ros::Duration(0.2),
                   {StateSpec{"ooo_a", Eigen::Vector3d(0.2, 10, 0), Eigen::Vector3d(1, 0, 0)},
                    StateSpec{"ooo_b", Eigen::Vector3d(0.86, 10, 0), Eigen::Vector3d(-1, 0, 0)}});
  EXPECT_TRUE(harness_.waitForWarning({"not newer than their body's last state"}));
  expectNoImpactFor(0.3);
  EXPECT_EQ(harness_.impactsOf("ooo_a").size(), 1u);
}

TEST_F(MonitorBadInput, ClockJumpBackResetsAndTheNodeStaysRight) {
  // As `rosbag play --loop` does: the stamps start again 100 s earlier.
  const ros::Time start = base_ - ros::Duration(100.0);
  playTwoBalls(start, "jump_a", "jump_b", 20.0);
  EXPECT_TRUE(harness_.waitForWarning({"jumped back"}));
  expectTwoBallImpactOnce("jump_a", start);
}

TEST_F(MonitorBadInput, ServicesStillAnswerAfterAllThat) {
  ros::ServiceClient client =
      harness_.node().serviceClient<ComputeCollision>("/collision_response/compute_collision");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(10.0)));
  ComputeCollision srv;
  srv.request = seedHeadOnRequest();
  ASSERT_TRUE(client.call(srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.velocity_a.x, kSeedVelocityA);
  EXPECT_EQ(srv.response.velocity_b.x, kSeedVelocityB);
}

}  // namespace
}  // namespace collision_response::testing

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "monitor_bad_input_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
