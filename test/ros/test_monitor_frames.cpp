// The impact monitor over real topics and real tf2 frames. Expected values are closed forms:
//
// Two balls of 1 kg, radius 0.1 m, e = 0.5: a at x = 0 moving +1 m/s, b at x = 1.06 moving
// -1 m/s. The gap 1.06 - 0.2 = 0.86 m closes at 2 m/s: contact at t = 0.43 s, between the 10 Hz
// samples at 0.4 and 0.5 s, at x = 0.43 + 0.1 = 0.53 m. Equal masses: v_a' = (1 - e)/2 * 1 +
// (1 + e)/2 * (-1) = -0.5, v_b' = +0.5; impulse (1 + e) mu |d| = 1.5 * 0.5 * 2 = 1.5 N s; energy
// lost (1/2) mu (1 - e^2) d^2 = 0.5 * 0.5 * 0.75 * 4 = 0.75 J. Whatever frame b is published in,
// these are the numbers in the fixed frame.
#include "monitor_harness.h"

#include <cmath>

namespace collision_response::testing {
namespace {

constexpr double kTime = 1e-9;      // s: instants of impact, exact up to the ns of a stamp
constexpr double kRelative = 1e-9;  // velocities, relative

class MonitorFrames : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { base_ = baseStamp(); }
  void SetUp() override { ASSERT_TRUE(harness_.connect()); }

  /// Each test its own 10 s window of stamps.
  static ros::Time window() {
    static int next = 0;
    return base_ + ros::Duration(10.0 * next++);
  }

  /// Publishes the two-ball case at 10 Hz from `start`; `b_in_frame` gives b's state as its
  /// source would publish it at time t (s after start) from its state in the world.
  void playTwoBalls(const ros::Time& start, const std::string& a, const std::string& b, double y,
                    const std::function<StateSpec(double, const StateSpec&)>& b_in_frame) {
    for (int k = 0; k <= 10; ++k) {
      const double t = 0.1 * k;
      const ros::Time stamp = start + ros::Duration(0, 100000000 * k);
      const StateSpec state_a{a, Eigen::Vector3d(t, y, 10), Eigen::Vector3d(1, 0, 0)};
      const StateSpec world_b{b, Eigen::Vector3d(1.06 - t, y, 10), Eigen::Vector3d(-1, 0, 0)};
      harness_.publish(stamp, {state_a, b_in_frame(t, world_b)});
      ros::WallDuration(0.01).sleep();
    }
  }

  void expectTwoBallImpact(const std::string& a, const std::string& b, const ros::Time& start,
                           double y) {
    ASSERT_TRUE(harness_.waitForImpact(a)) << "no impact of " << a;
    ros::WallDuration(0.3).sleep();
    ros::spinOnce();
    const std::vector<Impact> impacts = harness_.impactsOf(a);
    ASSERT_EQ(impacts.size(), 1u) << "the impact is reported once";
    const Impact& impact = impacts[0];
    EXPECT_EQ(impact.body_a, a);
    EXPECT_EQ(impact.body_b, b);
    EXPECT_EQ(impact.header.frame_id, "world");
    EXPECT_NEAR((impact.header.stamp - start).toSec(), 0.43, kTime);
    EXPECT_NEAR(impact.contact_point.x, 0.53, 1e-9);
    EXPECT_NEAR(impact.contact_point.y, y, 1e-9);
    EXPECT_NEAR(impact.contact_point.z, 10.0, 1e-9);
    EXPECT_NEAR(impact.normal.x, 1.0, 1e-12);
    EXPECT_NEAR(impact.velocity_a_before.linear.x, 1.0, kRelative);
    EXPECT_NEAR(impact.velocity_b_before.linear.x, -1.0, kRelative);
    EXPECT_NEAR(impact.velocity_a_after.linear.x, -0.5, 0.5 * kRelative);
    EXPECT_NEAR(impact.velocity_b_after.linear.x, 0.5, 0.5 * kRelative);
    EXPECT_NEAR(impact.velocity_a_after.linear.y, 0.0, 1e-9);
    EXPECT_NEAR(impact.velocity_b_after.linear.y, 0.0, 1e-9);
    EXPECT_NEAR(impact.impulse, 1.5, 1.5 * kRelative);
    EXPECT_NEAR(impact.energy_lost, 0.75, 0.75 * kRelative);
    EXPECT_EQ(impact.restitution, 0.5);
    EXPECT_FALSE(impact.oblique);
  }

  MonitorHarness harness_;
  static ros::Time base_;
};
ros::Time MonitorFrames::base_;

TEST_F(MonitorFrames, TwoBallsInTheFixedFrameHitBetweenSamples) {
  const ros::Time start = window();
  playTwoBalls(start, "same_a", "same_b", 0.0, [](double, const StateSpec& s) { return s; });
  expectTwoBallImpact("same_a", "same_b", start, 0.0);
}

TEST_F(MonitorFrames, StatePublishedInAStaticCameraFrame) {
  // camera: 90 degrees about z, at (2, 3, 1) in the world.
  tf2_ros::StaticTransformBroadcaster broadcaster;
  Eigen::Isometry3d camera = Eigen::Isometry3d::Identity();
  camera.translate(Eigen::Vector3d(2, 3, 1));
  camera.rotate(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  broadcaster.sendTransform(makeTransform(ros::Time(0), "world", "camera", camera));
  ros::WallDuration(0.5).sleep();
  const ros::Time start = window();
  playTwoBalls(start, "static_a", "static_b", 100.0, [&camera](double, const StateSpec& s) {
    return StateSpec{s.id, camera.inverse() * s.position, camera.linear().transpose() * s.velocity,
                     "camera"};
  });
  expectTwoBallImpact("static_a", "static_b", start, 100.0);
}

TEST_F(MonitorFrames, StatePublishedInAMovingCameraFrame) {
  // moving_camera: 30 degrees about z, its origin at (5, -1, 0) + u t with u = (0.3, 0.2, 0).
  // A tracker in it sees b at R^T (p - o(t)) moving at R^T (v - u) (relative to the camera).
  const ros::Time start = window();
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d origin(5, -1, 0);
  const Eigen::Vector3d u(0.3, 0.2, 0);
  const auto pose_at = [&](double t) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translate(origin + u * t);
    pose.rotate(rotation);
    return pose;
  };
  tf2_ros::TransformBroadcaster broadcaster;
  ros::WallDuration(0.5).sleep();
  for (int k = -10; k <= 30; ++k) {  // every 0.05 s from -0.5 s to 1.5 s
    broadcaster.sendTransform(makeTransform(start + ros::Duration(0.05 * k), "world",
                                            "moving_camera", pose_at(0.05 * k)));
  }
  ros::WallDuration(0.3).sleep();
  playTwoBalls(start, "moving_a", "moving_b", 200.0, [&](double t, const StateSpec& s) {
    return StateSpec{s.id, pose_at(t).inverse() * s.position,
                     rotation.transpose() * (s.velocity - u), "moving_camera"};
  });
  expectTwoBallImpact("moving_a", "moving_b", start, 200.0);
}

TEST_F(MonitorFrames, BodyOnItsOwnTopic) {
  ros::Publisher own = harness_.node().advertise<BodyState>("/own_b/state", 100);
  ros::WallDuration(0.5).sleep();  // let the connection settle before the first state
  ASSERT_TRUE(MonitorHarness::waitFor([&own] { return own.getNumSubscribers() > 0; }, 10.0));
  const ros::Time start = window();
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.1 * k;
    const ros::Time stamp = start + ros::Duration(0, 100000000 * k);
    harness_.publish(stamp,
                     {StateSpec{"own_a", Eigen::Vector3d(t, 300, 10), Eigen::Vector3d(1, 0, 0)}});
    BodyState b = makeState(stamp, StateSpec{"", Eigen::Vector3d(1.06 - t, 300, 10),
                                             Eigen::Vector3d(-1, 0, 0)});  // id from the topic
    own.publish(b);
    ros::WallDuration(0.01).sleep();
  }
  expectTwoBallImpact("own_a", "own_b", start, 300.0);
}

TEST_F(MonitorFrames, BallDroppedOnTheFloorPlane) {
  // Centre 0.5 m up, falling at 2 m/s, radius 0.033: the surface reaches the floor after
  // (0.5 - 0.033) / 2 = 0.2335 s. Tennis ball on concrete, e = 0.712: v' = 0.712 * 2 = 1.424.
  const ros::Time start = window();
  for (int k = 0; k <= 4; ++k) {
    const double t = 0.1 * k;
    harness_.publish(
        start + ros::Duration(0, 100000000 * k),
        {StateSpec{"dropped", Eigen::Vector3d(0, 400, 0.5 - 2 * t), Eigen::Vector3d(0, 0, -2)}});
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_TRUE(harness_.waitForImpact("dropped"));
  const Impact impact = harness_.impactsOf("dropped").at(0);
  EXPECT_EQ(impact.body_b, "floor");
  EXPECT_NEAR((impact.header.stamp - start).toSec(), 0.2335, kTime);
  EXPECT_EQ(impact.restitution, 0.712);
  EXPECT_NEAR(impact.velocity_a_after.linear.z, 1.424, 1.424 * kRelative);
  EXPECT_NEAR(impact.contact_point.z, 0.0, 1e-9);
  EXPECT_NEAR(impact.normal.z, -1.0, 1e-12);
  EXPECT_NEAR(impact.velocity_b_after.linear.z, 0.0, 0.0);  // the floor does not move
}

}  // namespace
}  // namespace collision_response::testing

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "monitor_frames_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
