// The paddle arm over ROS (test/ros/paddle_arm.test: launch/paddle_arm.launch, urdf/
// paddle_arm.urdf, config/scenes/paddle_arm.yaml), checked against what the test computes on its
// own:
//  - the ball before the paddle is on its lob, v = (-1.5, 0, 4.05 - g t) at t s after the first
//    state;
//  - the paddle's surface where the ball meets it moves as the arm's forward kinematics say, from
//    the joint states on /joint_states at the impact's stamp (interpolated between the 1 kHz
//    samples): shoulder about z at (0, 0, 0.5), elbow about the upper arm's y, 0.4 m out along
//    its x; a point c moves at q1' z x (c - shoulder) + q2' a_elbow x (c - elbow);
//  - along the line of impact n the ball leaves at u_s + e (u_s - u), e = min(0.9, 0.8) = 0.8
//    (celluloid on the paddle's rubber, rule min);
//  - no ball is ever inside the table (a box 2.0 x 0.8 x 0.05 m centred at (1.75, 0, 0.125)), and
//    the ball resting on it does not move.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"

namespace {

using V = Eigen::Vector3d;
constexpr double kG = 9.81, kR = 0.02;

V toEigen(const geometry_msgs::Vector3& v) { return V(v.x, v.y, v.z); }
V toEigen(const geometry_msgs::Point& p) { return V(p.x, p.y, p.z); }

/// How far a ball's centre is inside the table grown by the ball (> 0: inside).
double depthInTable(const V& centre) {
  const V half(1.0, 0.4, 0.025);
  const V p = centre - V(1.75, 0, 0.125);
  const V outside = (p.cwiseAbs() - half).cwiseMax(0.0);
  const double inside = std::min(0.0, (p.cwiseAbs() - half).maxCoeff());
  return kR - outside.norm() - inside;
}

struct JointSample {
  ros::Time stamp;
  double q1, q2, w1, w2;
};

TEST(PaddleArm, TheBallLeavesTheMovingPaddleAtTheClosedFormAndNeverEntersTheTable) {
  ros::NodeHandle node;
  std::vector<collision_response::Impact> impacts;
  std::vector<JointSample> joints;
  ros::Time start;
  double deepest = -1;
  std::vector<V> resting;
  ros::Subscriber impact_subscriber = node.subscribe<collision_response::ImpactArray>(
      "impacts", 100, [&](const collision_response::ImpactArray::ConstPtr& array) {
        for (const auto& impact : array->impacts) impacts.push_back(impact);
      });
  ros::Subscriber joint_subscriber = node.subscribe<sensor_msgs::JointState>(
      "joint_states", 10000, [&](const sensor_msgs::JointState::ConstPtr& state) {
        joints.push_back({state->header.stamp, state->position[0], state->position[1],
                          state->velocity[0], state->velocity[1]});
      });
  ros::Subscriber state_subscriber = node.subscribe<collision_response::BodyStateArray>(
      "body_states", 1000, [&](const collision_response::BodyStateArray::ConstPtr& array) {
        if (start.isZero()) start = array->header.stamp;
        for (const auto& state : array->states) {
          const V p = toEigen(state.pose.position);
          deepest = std::max(deepest, depthInTable(p));
          if (state.id == "resting") resting.push_back(p);
        }
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(60.0);
  const auto paddle_impact = [&] {
    return std::find_if(impacts.begin(), impacts.end(),
                        [](const auto& impact) { return impact.body_b == "paddle"; });
  };
  while (ros::ok() && ros::WallTime::now() < end &&
         (paddle_impact() == impacts.end() || resting.size() < 250)) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_NE(paddle_impact(), impacts.end()) << "the ball never met the paddle";
  const collision_response::Impact impact = *paddle_impact();
  EXPECT_EQ(impact.body_a, "ball");
  EXPECT_EQ(impact.restitution, 0.8);

  // The ball on its lob.
  const double t = (impact.header.stamp - start).toSec();
  const V before(-1.5, 0, 4.05 - kG * t);
  EXPECT_NEAR((toEigen(impact.velocity_a_before.linear) - before).norm(), 0, 1e-6);

  // The arm at the impact's stamp, from the joint states around it.
  const auto after_it = std::find_if(joints.begin(), joints.end(), [&](const JointSample& j) {
    return j.stamp >= impact.header.stamp;
  });
  ASSERT_TRUE(after_it != joints.end() && after_it != joints.begin());
  const JointSample& a = *(after_it - 1);
  const JointSample& b = *after_it;
  const double s = (impact.header.stamp - a.stamp).toSec() / (b.stamp - a.stamp).toSec();
  const double q1 = a.q1 + s * (b.q1 - a.q1), w1 = a.w1 + s * (b.w1 - a.w1);
  const double w2 = a.w2 + s * (b.w2 - a.w2);
  const V shoulder(0, 0, 0.5);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(q1, V::UnitZ()).toRotationMatrix();
  const V elbow = shoulder + turn * V(0.4, 0, 0);
  const V elbow_axis = turn * V::UnitY();
  const V c = toEigen(impact.contact_point);
  const V surface = w1 * V::UnitZ().cross(c - shoulder) + w2 * elbow_axis.cross(c - elbow);
  // The node holds a link's twist from tf over ~obstacle_update_period (1 ms): the elbow's
  // angular acceleration (up to 0.3 pi^2 = 3 rad/s^2) over it is 1e-3 m/s at the paddle's 0.3 m,
  // and its velocity from tf is a finite difference. (Placed once an update, at its end, the
  // paddle was 5e-3 m/s off.)
  constexpr double kModel = 2e-3;
  EXPECT_NEAR((toEigen(impact.velocity_b_before.linear) - surface).norm(), 0, kModel);

  // The closed form along the line of impact, from the values computed here.
  const V n = toEigen(impact.normal);
  const double u = before.dot(n), u_s = surface.dot(n);
  EXPECT_NEAR(toEigen(impact.velocity_a_after.linear).dot(n), u_s + 0.8 * (u_s - u), 2 * kModel);

  // The table: never entered; the resting ball still.
  EXPECT_LT(deepest, 1e-9 * kR) << "a ball went into the table";
  ASSERT_GT(resting.size(), 100u);
  for (const V& p : resting) EXPECT_EQ(p, resting.front());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "paddle_arm_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
