// A box dropped flat through air, played through demo.launch over real topics
// (config/scenes/box_drag.yaml): a 0.1 m cube of m = 0.1 kg at rest, its lowest face d = 1.95 m
// above a frictionless floor, e = 1/2, g = 9.81, drag on A = 6 (0.1)^2 / 4 (its mean
// cross-section), C_d = 1.05, rho = 1.204. With k = rho C_d A / (2 m) and v_t = sqrt(g / k):
//  - down, v' = g - k v^2: v = v_t tanh(g t / v_t), fallen (v_t^2 / g) ln cosh(g t / v_t), so it
//    lands flat at t1 = (v_t / g) acosh(exp(g d / v_t^2)) at v1 = v_t sqrt(1 - exp(-2 g d /
//    v_t^2)), on its four corners at once, leaving at u = e v1 without spin;
//  - up, v' = -g - k v^2: it rises for (v_t / g) atan(u / v_t) by H = (v_t^2 / 2 g)
//    ln(1 + u^2 / v_t^2), falls H in (v_t / g) acosh(exp(g H / v_t^2)) and lands at
//    v_t u / sqrt(v_t^2 + u^2).
// The instants are read from the stamps (whole nanoseconds); the flight is integrated to 1e-12
// (the scene's flight_integration_tolerance), the player's second flight starting up to half a
// nanosecond off the exact instant, as in test_box_drop.cpp.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"

namespace {

constexpr double kG = 9.81, kE = 0.5, kMass = 0.1, kHalf = 0.05, kDrop = 1.95, kDensity = 1.204,
                 kDrag = 1.05;

TEST(BoxDrag, TheNodesImpactsAreTheClosedFormsOfQuadraticDrag) {
  ros::NodeHandle node;
  std::vector<collision_response::Impact> impacts;
  ros::Time start;
  double lowest = INFINITY, last_time = 0;
  ros::Subscriber impact_subscriber = node.subscribe<collision_response::ImpactArray>(
      "impacts", 100, [&](const collision_response::ImpactArray::ConstPtr& array) {
        impacts.insert(impacts.end(), array->impacts.begin(), array->impacts.end());
      });
  ros::Subscriber states = node.subscribe<collision_response::BodyStateArray>(
      "body_states", 1000, [&](const collision_response::BodyStateArray::ConstPtr& array) {
        if (start.isZero()) start = array->header.stamp;
        for (const auto& state : array->states) {
          if (state.id != "block") continue;
          lowest = std::min(lowest, state.pose.position.z - kHalf);
          last_time = (array->header.stamp - start).toSec();
        }
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(40.0);
  while (ros::ok() && ros::WallTime::now() < end && last_time < 1.4) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_GE(impacts.size(), 8u) << "two landings on four corners each";

  const double k = kDensity * kDrag * (6 * 4 * kHalf * kHalf / 4) / (2 * kMass);
  const double vt = std::sqrt(kG / k);
  const double t1 = vt / kG * std::acosh(std::exp(kG * kDrop / (vt * vt)));
  const double v1 = vt * std::sqrt(-std::expm1(-2 * kG * kDrop / (vt * vt)));
  const double u = kE * v1;
  const double height = vt * vt / (2 * kG) * std::log1p(u * u / (vt * vt));
  const double t2 =
      t1 + vt / kG * std::atan(u / vt) + vt / kG * std::acosh(std::exp(kG * height / (vt * vt)));
  const double v2 = vt * u / std::hypot(vt, u);
  for (std::size_t c = 0; c < 8; ++c) {
    const collision_response::Impact& impact = impacts[c];
    SCOPED_TRACE("impact " + std::to_string(c));
    const bool first = c < 4;
    EXPECT_EQ(impact.body_a, "block");
    EXPECT_EQ(impact.body_b, "floor");
    EXPECT_NEAR((impact.header.stamp - start).toSec(), first ? t1 : t2, first ? 2e-9 : 1e-8);
    EXPECT_NEAR(impact.velocity_a_before.linear.z, first ? -v1 : -v2, first ? 1e-9 : 1e-7);
    EXPECT_NEAR(impact.velocity_a_after.linear.z, kE * (first ? v1 : v2), first ? 1e-9 : 1e-7);
    const auto& w = impact.velocity_a_after.angular;
    EXPECT_NEAR(std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z), 0, 1e-12) << "no spin";
    EXPECT_NEAR(impact.contact_point.z, 0, 1e-12);
    EXPECT_NEAR(std::abs(impact.contact_point.x), kHalf, 1e-12);
    EXPECT_NEAR(std::abs(impact.contact_point.y), kHalf, 1e-12);
  }
  EXPECT_GT(lowest, -1e-12) << "a played state inside the floor";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "box_drag_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
