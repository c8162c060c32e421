// A box landing flat while it slides, played through demo.launch over real topics
// (config/scenes/box_skid.yaml): a cube of half size a = c = 0.05 m and m = 0.5 kg thrown level at
// u = 2 m/s, its lowest face h = 0.5 m above a floor of mu = 0.3, e = 1/2, g = 9.81. Closed forms
// of the joint law (doc/model.md, "One impact of a shaped body"), worked here:
//  - it lands flat at t1 = sqrt(2 h / g) at v_n = g t1 on its four corners at once; the plastic
//    frictionless impulses are m v_n / 4 each, the sticking ones -m u / 4 along x each with normal
//    parts m v_n / 4 +- c m u x / (4 a^2) (front corners, x = +a, more), so D = (-m u / 4, 0,
//    +-m u / 4) and on the rear corners' cone kappa = mu (1 + e) v_n / (u (1 + mu c / a));
//  - it leaves at (u (1 - kappa), 0, e v_n) without turning, each corner's normal impulse
//    (1 + e) m v_n / 4 +- kappa m u / 4 and friction kappa m u / 4;
//  - it flies 2 e v_n / g and lands again at e v_n sliding at u (1 - kappa), the same law again.
// The instants are read from the stamps (whole nanoseconds; the second flight starts up to half a
// nanosecond off, as in test_box_drop.cpp).
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cmath>
#include <vector>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"

namespace {

constexpr double kG = 9.81, kE = 0.5, kMass = 0.5, kHalf = 0.05, kDrop = 0.5, kMu = 0.3,
                 kSpeed = 2.0;

TEST(BoxSkid, TheNodesLandingsAreTheJointLawsClosedForm) {
  ros::NodeHandle node;
  std::vector<collision_response::Impact> impacts;
  ros::Time start;
  double last_time = 0;
  ros::Subscriber impact_subscriber = node.subscribe<collision_response::ImpactArray>(
      "impacts", 100, [&](const collision_response::ImpactArray::ConstPtr& array) {
        impacts.insert(impacts.end(), array->impacts.begin(), array->impacts.end());
      });
  ros::Subscriber states = node.subscribe<collision_response::BodyStateArray>(
      "body_states", 1000, [&](const collision_response::BodyStateArray::ConstPtr& array) {
        if (start.isZero()) start = array->header.stamp;
        last_time = (array->header.stamp - start).toSec();
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(40.0);
  while (ros::ok() && ros::WallTime::now() < end && last_time < 0.7) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_GE(impacts.size(), 8u) << "two landings on four corners each";

  double at = std::sqrt(2 * kDrop / kG), v_n = kG * at, u = kSpeed;
  double centre = u * at;  // the box's centre along x at the landing
  for (std::size_t landing = 0; landing < 2; ++landing) {
    const double kappa = kMu * (1 + kE) * v_n / (u * (1 + kMu));  // c / a = 1
    for (std::size_t k = 4 * landing; k < 4 * landing + 4; ++k) {
      const collision_response::Impact& impact = impacts[k];
      SCOPED_TRACE("landing " + std::to_string(landing) + ", impact " + std::to_string(k));
      EXPECT_EQ(impact.body_b, "floor");
      EXPECT_NEAR((impact.header.stamp - start).toSec(), at, landing == 0 ? 2e-9 : 1e-8);
      const double tolerance = landing == 0 ? 1e-9 : 1e-7;
      EXPECT_NEAR(impact.velocity_a_before.linear.x, u, tolerance);
      EXPECT_NEAR(impact.velocity_a_before.linear.z, -v_n, tolerance);
      EXPECT_NEAR(impact.velocity_a_after.linear.x, u * (1 - kappa), tolerance);
      EXPECT_NEAR(impact.velocity_a_after.linear.z, kE * v_n, tolerance);
      const auto& w = impact.velocity_a_after.angular;
      EXPECT_NEAR(std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z), 0, 1e-9) << "no turn";
      const double ahead = impact.contact_point.x > centre ? 1.0 : -1.0;  // front: +x
      EXPECT_NEAR(impact.impulse, (1 + kE) * kMass * v_n / 4 + ahead * kappa * kMass * u / 4,
                  tolerance);
      EXPECT_NEAR(impact.friction_impulse, kappa * kMass * u / 4, tolerance);
    }
    at += 2 * kE * v_n / kG;
    u *= 1 - kappa;
    centre += u * 2 * kE * v_n / kG;
    v_n *= kE;
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "box_skid_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
