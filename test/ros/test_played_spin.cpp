// Spin over ROS as a user plays it (played_spin.test): demo.launch on test/ros/played_spin.yaml,
// the scene player's states on body_states, the node's contacts and impacts. Every expected
// number is a closed form of a solid ball (I = 2/5 m r^2) on a floor with Coulomb friction,
// g = 9.81 m/s^2 (README, "Effects"):
//
// Sliding on the floor, friction mu m g acts against the slip at the contact point; it slows
// the centre by mu g and spins the ball up by (mu m g r) / I = 5/2 mu g / r, until the contact
// point stops slipping (v = omega_y r, for motion along +x on a floor with normal +z):
// - slider, v0 = 2 m/s, omega0 = 0: v = v0 - mu g t, omega_y = 5/2 mu g t / r, rolling from
//   t = 2 v0 / (7 mu g) at v = 5/7 v0; its friction on the floor is +mu m g along x while it
//   slides (the ball is pushed back), zero once it rolls.
// - spinner, v0 = 0, omega0 = 50 rad/s about y: the contact point slips backwards at omega0 r,
//   so friction pushes the ball forwards: v = mu g t, omega_y = omega0 - 5/2 mu g t / r, rolling
//   from t = omega0 r / (7/2 mu g) at v = 2/7 omega0 r; friction on the floor -mu m g along x.
// - bouncer, dropped from h = 0.2 m with v0 = 2 m/s sideways (e = 0.5, mu = 0.3): it meets the
//   floor at t = sqrt(2 h / g) with normal speed vn = sqrt(2 g h). Stopping the slip v0 takes
//   the tangential impulse 2/7 m v0, within Coulomb's mu (1 + e) m vn (0.57 m <= 0.89 m), so it
//   leaves rolling: v = 5/7 v0, omega_y = v / r, vz = e vn. Every later bounce finds no slip and
//   keeps v; the ball ends rolling at 5/7 v0 with no friction force.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <Eigen/Core>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ContactArray.h"
#include "collision_response/ImpactArray.h"

namespace {

using V = Eigen::Vector3d;
constexpr double kG = 9.81;
constexpr double kVelocityTolerance = 1e-9;  // m/s (the played motion is a closed form)
constexpr double kForceTolerance = 1e-9;     // relative to m g
// The node forms its contacts from the states it hears at 100 Hz: the state at an instant
// within two periods of a change of slip is not judged.
constexpr double kAroundChange = 0.02;  // s

V eigen(const geometry_msgs::Vector3& v) { return V(v.x, v.y, v.z); }

/// A solid ball set down on the floor sliding at v0 and spinning at omega0 about y: the centre's
/// speed along x and the spin about y at t, and the instant it starts rolling.
struct SlidingBall {
  double mass, radius, friction, v0, omega0;
  double slip() const { return v0 - omega0 * radius; }  // m/s, the contact point's along x
  double deceleration() const { return std::copysign(friction * kG, slip()); }
  double rollingFrom() const { return std::abs(slip()) / (3.5 * friction * kG); }
  double speed(double t) const {
    return t < rollingFrom() ? v0 - deceleration() * t : (5.0 * v0 + 2.0 * omega0 * radius) / 7.0;
  }
  double spin(double t) const {
    return t < rollingFrom() ? omega0 + 2.5 * deceleration() * t / radius : speed(t) / radius;
  }
  /// N along x, on the floor: the opposite of the ball's friction force while it slides.
  double frictionOnFloor(double t) const { return t < rollingFrom() ? mass * deceleration() : 0.0; }
};

const SlidingBall kSlider{0.17, 0.028575, 0.2, 2.0, 0.0};
const SlidingBall kSpinner{0.17, 0.028575, 0.2, 0.0, 50.0};

struct Bouncer {
  double mass = 0.057, radius = 0.0335, friction = 0.3, restitution = 0.5, v0 = 2.0, drop = 0.2;
  double firstImpact() const { return std::sqrt(2.0 * drop / kG); }
  double arrival() const { return std::sqrt(2.0 * kG * drop); }
  double rollingSpeed() const { return 5.0 / 7.0 * v0; }
};
const Bouncer kBouncer;

struct Played {
  double t;
  V velocity, angular_velocity;
};

class PlayedSpin : public ::testing::Test {
 protected:
  void SetUp() override {
    states_ = node_.subscribe<collision_response::BodyStateArray>(
        "body_states", 1000, [this](const collision_response::BodyStateArray::ConstPtr& array) {
          if (first_stamp_.isZero()) first_stamp_ = array->header.stamp;
          last_stamp_ = array->header.stamp;
          for (const auto& state : array->states) {
            played_[state.id].push_back(
                {since(state.header.stamp), eigen(state.twist.linear), eigen(state.twist.angular)});
          }
        });
    contacts_ = node_.subscribe<collision_response::ContactArray>(
        "contacts", 1000, [this](const collision_response::ContactArray::ConstPtr& array) {
          contact_arrays_.push_back(*array);
        });
    impacts_ = node_.subscribe<collision_response::ImpactArray>(
        "impacts", 1000, [this](const collision_response::ImpactArray::ConstPtr& array) {
          for (const auto& impact : array->impacts) impacts_received_.push_back(impact);
        });
  }

  double since(const ros::Time& stamp) const { return (stamp - first_stamp_).toSec(); }

  /// Spins until `seconds` of states have been played (by their stamps).
  bool play(double seconds) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(60.0);
    while (ros::ok() && ros::WallTime::now() < end) {
      ros::spinOnce();
      if (!first_stamp_.isZero() && since(last_stamp_) >= seconds) break;
      ros::WallDuration(0.005).sleep();
    }
    ros::WallDuration(0.3).sleep();  // the node's answer to the last states
    ros::spinOnce();
    return !first_stamp_.isZero() && since(last_stamp_) >= seconds;
  }

  /// Every state the player published of a ball set down sliding or spinning.
  void expectPlayed(const std::string& id, const SlidingBall& ball) const {
    ASSERT_TRUE(played_.count(id)) << "no state of " << id;
    for (const Played& state : played_.at(id)) {
      EXPECT_NEAR(state.velocity.x(), ball.speed(state.t), kVelocityTolerance)
          << id << " at " << state.t << " s";
      EXPECT_NEAR(state.angular_velocity.y(), ball.spin(state.t), kVelocityTolerance / ball.radius)
          << id << " at " << state.t << " s";
      EXPECT_NEAR(state.velocity.y(), 0.0, kVelocityTolerance) << id;
      EXPECT_NEAR(state.velocity.z(), 0.0, kVelocityTolerance) << id;
      EXPECT_NEAR(state.angular_velocity.x(), 0.0, kVelocityTolerance) << id;
      EXPECT_NEAR(state.angular_velocity.z(), 0.0, kVelocityTolerance) << id;
    }
  }

  /// Every contact the node published of a ball set down sliding or spinning: sliding with
  /// mu m g until it rolls, rolling without friction after, always carrying its weight.
  void expectContacts(const std::string& id, const SlidingBall& ball) const {
    const double weight = ball.mass * kG;
    int sliding = 0, rolling = 0;
    for (const auto& array : contact_arrays_) {
      const double t = since(array.header.stamp);
      for (const auto& contact : array.contacts) {
        if (contact.body_a != id) continue;
        EXPECT_EQ(contact.body_b, "floor");
        EXPECT_NEAR(contact.normal_force, weight, kForceTolerance * weight) << id << " at " << t;
        if (std::abs(t - ball.rollingFrom()) < kAroundChange) continue;
        const bool slides = t < ball.rollingFrom();
        EXPECT_EQ(contact.state, slides ? "sliding" : "rolling") << id << " at " << t << " s";
        EXPECT_NEAR(contact.friction_force.x, ball.frictionOnFloor(t), kForceTolerance * weight)
            << id << " at " << t << " s";
        EXPECT_NEAR(contact.friction_force.y, 0.0, kForceTolerance * weight) << id;
        EXPECT_NEAR(contact.friction_force.z, 0.0, kForceTolerance * weight) << id;
        ++(slides ? sliding : rolling);
      }
    }
    // 100 Hz over the slip and after it: contacts at most inputs of each part.
    EXPECT_GT(sliding, static_cast<int>(ball.rollingFrom() * 100) / 2) << id;
    EXPECT_GT(rolling, 20) << id;
  }

  ros::NodeHandle node_;
  ros::Subscriber states_, contacts_, impacts_;
  ros::Time first_stamp_, last_stamp_;
  std::map<std::string, std::vector<Played>> played_;
  std::vector<collision_response::ContactArray> contact_arrays_;
  std::vector<collision_response::Impact> impacts_received_;
};

TEST_F(PlayedSpin, RollingAfterSlippingAndASetSpinAndABounceWithFrictionAndSpin) {
  ASSERT_TRUE(play(1.2)) << "the scene player published no 1.2 s of states";

  // Rolling after slipping, and a ball set down spinning (the scene's angular_velocity key).
  expectPlayed("slider", kSlider);
  expectContacts("slider", kSlider);
  expectPlayed("spinner", kSpinner);
  expectContacts("spinner", kSpinner);

  // The bounce: the node's first impact of the bouncer, and every played state after it.
  const collision_response::Impact* first = nullptr;
  for (const auto& impact : impacts_received_) {
    if (impact.body_a == "bouncer" || impact.body_b == "bouncer") {
      first = &impact;
      break;
    }
  }
  ASSERT_NE(first, nullptr) << "no impact of the bouncer";
  EXPECT_EQ(first->body_a, "bouncer");
  EXPECT_EQ(first->body_b, "floor");
  EXPECT_NEAR(since(first->header.stamp), kBouncer.firstImpact(), 1e-6);
  const V after = eigen(first->velocity_a_after.linear);
  const V spin_after = eigen(first->velocity_a_after.angular);
  EXPECT_NEAR(after.x(), kBouncer.rollingSpeed(), kVelocityTolerance);
  EXPECT_NEAR(after.z(), kBouncer.restitution * kBouncer.arrival(), 1e-6);
  EXPECT_NEAR(spin_after.y(), kBouncer.rollingSpeed() / kBouncer.radius,
              kVelocityTolerance / kBouncer.radius);
  EXPECT_NEAR(std::abs(first->friction_impulse), 2.0 / 7.0 * kBouncer.mass * kBouncer.v0, 1e-9);

  ASSERT_TRUE(played_.count("bouncer"));
  int after_bounce = 0;
  for (const Played& state : played_.at("bouncer")) {
    if (state.t < kBouncer.firstImpact() + kAroundChange) continue;
    EXPECT_NEAR(state.velocity.x(), kBouncer.rollingSpeed(), kVelocityTolerance)
        << "at " << state.t << " s";
    EXPECT_NEAR(state.angular_velocity.y(), kBouncer.rollingSpeed() / kBouncer.radius,
                kVelocityTolerance / kBouncer.radius)
        << "at " << state.t << " s";
    ++after_bounce;
  }
  EXPECT_GT(after_bounce, 50);
  // Bounced to rest by 3 vn / g (the flights' sum 2 e vn / (g (1 - e)) after the fall): rolling.
  const collision_response::Contact* last = nullptr;
  for (const auto& contact : contact_arrays_.back().contacts) {
    if (contact.body_a == "bouncer") last = &contact;
  }
  ASSERT_NE(last, nullptr) << "the bouncer is not in lasting contact at the end";
  EXPECT_EQ(last->state, "rolling");
  EXPECT_NEAR(last->normal_force, kBouncer.mass * kG, kForceTolerance * kBouncer.mass * kG);
  EXPECT_NEAR(eigen(last->friction_force).norm(), 0.0, kForceTolerance * kBouncer.mass * kG);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "played_spin_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
