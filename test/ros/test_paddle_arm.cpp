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
#include <optional>
#include <sstream>
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

/// What one run of the scene published, heard once and shared by the tests.
struct Recording {
  std::vector<collision_response::Impact> impacts;
  std::vector<ros::WallTime> impact_heard;  ///< when each impact came (the player hears it then)
  std::vector<JointSample> joints;
  ros::Time start;  ///< the first state's stamp: the ball leaves
  double deepest = -1;
  std::vector<V> resting;
  struct Played {
    ros::Time stamp;
    ros::WallTime heard;
    V position, velocity;
  };
  std::vector<Played> ball;

  /// The first impact with the paddle, if any.
  std::optional<std::size_t> paddleImpact() const {
    for (std::size_t k = 0; k < impacts.size(); ++k) {
      if (impacts[k].body_b == "paddle") return k;
    }
    return std::nullopt;
  }
};

const Recording& recording() {
  static Recording r;
  static bool recorded = false;
  if (recorded) return r;
  recorded = true;
  ros::NodeHandle node;
  ros::Subscriber impact_subscriber = node.subscribe<collision_response::ImpactArray>(
      "impacts", 100, [&](const collision_response::ImpactArray::ConstPtr& array) {
        for (const auto& impact : array->impacts) {
          r.impacts.push_back(impact);
          r.impact_heard.push_back(ros::WallTime::now());
        }
      });
  ros::Subscriber joint_subscriber = node.subscribe<sensor_msgs::JointState>(
      "joint_states", 10000, [&](const sensor_msgs::JointState::ConstPtr& state) {
        r.joints.push_back({state->header.stamp, state->position[0], state->position[1],
                            state->velocity[0], state->velocity[1]});
      });
  ros::Subscriber state_subscriber = node.subscribe<collision_response::BodyStateArray>(
      "body_states", 1000, [&](const collision_response::BodyStateArray::ConstPtr& array) {
        if (r.start.isZero()) r.start = array->header.stamp;
        for (const auto& state : array->states) {
          const V p = toEigen(state.pose.position);
          r.deepest = std::max(r.deepest, depthInTable(p));
          if (state.id == "resting") r.resting.push_back(p);
          if (state.id == "ball") {
            r.ball.push_back(
                {state.header.stamp, ros::WallTime::now(), p, toEigen(state.twist.linear)});
          }
        }
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(60.0);
  while (ros::ok() && ros::WallTime::now() < end && (!r.paddleImpact() || r.resting.size() < 250)) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  return r;
}

TEST(PaddleArm, TheBallLeavesTheMovingPaddleAtTheClosedFormAndNeverEntersTheTable) {
  const Recording& r = recording();
  const std::vector<JointSample>& joints = r.joints;
  const ros::Time start = r.start;
  ASSERT_TRUE(r.paddleImpact()) << "the ball never met the paddle";
  const collision_response::Impact impact = r.impacts[*r.paddleImpact()];
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
  EXPECT_LT(r.deepest, 1e-9 * kR) << "a ball went into the table";
  ASSERT_GT(r.resting.size(), 100u);
  for (const V& p : r.resting) EXPECT_EQ(p, r.resting.front());
}

// Issue 41, item 10: the swing starts with the ball (examples/paddle_arm_joints.py counts its
// phase from the player's first state), so every run meets the ball at the same instant: where
// the ball's centre on its lob, c(t) = (2 - 1.5 t, 0, 0.6 + 4.05 t - g t^2 / 2), is the ball's
// radius plus half the paddle's thickness (0.02 + 0.005 m) out from the paddle's face along its
// normal n = Rz(q1) Ry(q2) x, the face's centre at (0, 0, 0.5) + Rz(q1) ((0.4, 0, 0) +
// Ry(q2) (0.3, 0, 0)), q1 = 0.05 sin(pi t), q2 = 0.3 sin(pi t): t = 0.846476538914 s, 0.0617 m
// from the disc's axis (test/ros/paddle_arm_meeting.py, by bisection). Before, the swing started
// with its own script: the ball met it anywhere in its swing (1.68 to 2.69 m/s off it over five
// runs). The node places the paddle from tf every 1 ms (1e-6 m off the swing's curve, 1e-6 s).
TEST(PaddleArm, TheBallMeetsThePaddleAtTheInstantTheSwingsClosedFormGives) {
  const Recording& r = recording();
  ASSERT_TRUE(r.paddleImpact()) << "the ball never met the paddle";
  const collision_response::Impact& impact = r.impacts[*r.paddleImpact()];
  EXPECT_NEAR((impact.header.stamp - r.start).toSec(), 0.846476538914, 1e-4);
}

// Issue 41, item 10: an answer of the node heard later than a period (held 30 ms by
// paddle_arm_late.test's relay, as on a busy machine) is still applied: the player plays the
// scene again from the impact's instant (~replay_window), so the ball flies from the paddle on
// the parabola from the contact with the node's velocity after, c0 + v' s + g s^2 / 2 (s = t - tau,
// c0 = contact point - r n), not through the paddle, and lands on the table from it: the table's
// impact has the ball's centre and velocity there (the impacts the node found along the states sent
// before the player heard, the ball inside the paddle, are not applied: the forearm's). Checked on
// that impact, and on every state sent once the answer was heard (20 ms later) before it.
TEST(PaddleArm, ThePlayedBallLeavesThePaddleAsTheNodeSaysEvenWhenItsAnswerIsLate) {
  const Recording& r = recording();
  ASSERT_TRUE(r.paddleImpact()) << "the ball never met the paddle";
  const std::size_t k = *r.paddleImpact();
  const collision_response::Impact& impact = r.impacts[k];
  std::ostringstream seen;
  for (std::size_t i = 0; i < r.impacts.size(); ++i) {
    seen << "\n  " << r.impacts[i].body_a << " " << r.impacts[i].body_b << " at "
         << (r.impacts[i].header.stamp - r.start).toSec() << " s, heard "
         << (r.impact_heard[i] - r.impact_heard[k]).toSec() << " s after the paddle's";
  }
  const auto table =
      std::find_if(r.impacts.begin() + static_cast<std::ptrdiff_t>(k), r.impacts.end(),
                   [](const auto& i) { return i.body_b == "table"; });
  ASSERT_NE(table, r.impacts.end()) << "the ball never landed on the table:" << seen.str();
  const V n = toEigen(impact.normal);
  const V centre = toEigen(impact.contact_point) - kR * n;
  const V after = toEigen(impact.velocity_a_after.linear);
  const V g(0, 0, -kG);
  const auto flight = [&](const ros::Time& t) {
    const double s = (t - impact.header.stamp).toSec();
    return std::make_pair(V(centre + after * s + 0.5 * s * s * g), V(after + s * g));
  };
  const auto [landing, landing_velocity] = flight(table->header.stamp);
  EXPECT_NEAR((toEigen(table->contact_point) - kR * toEigen(table->normal) - landing).norm(), 0,
              1e-6)
      << seen.str();
  EXPECT_NEAR((toEigen(table->velocity_a_before.linear) - landing_velocity).norm(), 0, 1e-6);
  std::size_t checked = 0;
  for (const Recording::Played& played : r.ball) {
    if (played.heard < r.impact_heard[k] + ros::WallDuration(0.02) ||
        played.stamp >= table->header.stamp) {
      continue;
    }
    const auto [position, velocity] = flight(played.stamp);
    EXPECT_NEAR((played.position - position).norm(), 0, 1e-9);
    EXPECT_NEAR((played.velocity - velocity).norm(), 0, 1e-9);
    ++checked;
  }
  EXPECT_GE(checked, 1u) << "no state between the answer and the landing";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "paddle_arm_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
