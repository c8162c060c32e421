// A box dropped flat, played through demo.launch over real topics (config/scenes/box_drop.yaml):
// a 0.1 m cube of m = 0.5 kg at rest, its lowest face h = 0.5 m above a frictionless floor,
// e = 1/2, g = 9.81. Closed forms:
//  - it lands flat at t1 = sqrt(2 h / g) with v = g t1 = sqrt(2 g h) downwards, on its four
//    corners (+-0.05, +-0.05, 0) at once; Newton's law along the normal with the four contacts'
//    joint rule (doc/model.md, "One impact of a shaped body") leaves it at +e v, without spin,
//    the four impulses equal by symmetry, (1 + e) m v / 4 each;
//  - it flies up and back in 2 e v / g = 2 e t1 and lands at 2 t1 at e v, leaving at e^2 v;
//  - the bounces accumulate at t1 (1 + 2 e / (1 - e)) = 3 t1, where it rests on the floor.
// The instants are read from the stamps (the node's impacts against the player's first state):
// ROS stamps are whole nanoseconds. The player applies the node's impact from its stamp, so the
// second flight starts up to half a nanosecond off the exact instant, up to 0.5e-9 v below or
// above the contact: the second landing's speed is then off by g dz / (e v), about 1e-8 m/s (held
// to 1e-7), its instant by as much as the first's (held to 1e-8 s).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"

namespace {

constexpr double kG = 9.81, kE = 0.5, kMass = 0.5, kHalf = 0.05, kDrop = 0.5;

TEST(BoxDrop, TheNodesImpactsAreTheClosedFormsAndTheMarkerIsACube) {
  ros::NodeHandle node;
  std::vector<collision_response::Impact> impacts;
  ros::Time start;
  double lowest = INFINITY;  // the lowest face's height over every played state
  double last_height = NAN, last_speed = NAN, last_time = 0;
  double largest_spin = 0, worst_orientation = 0;
  std::optional<visualization_msgs::Marker> marker;
  ros::Subscriber impact_subscriber = node.subscribe<collision_response::ImpactArray>(
      "impacts", 100, [&](const collision_response::ImpactArray::ConstPtr& array) {
        impacts.insert(impacts.end(), array->impacts.begin(), array->impacts.end());
      });
  ros::Subscriber states = node.subscribe<collision_response::BodyStateArray>(
      "body_states", 1000, [&](const collision_response::BodyStateArray::ConstPtr& array) {
        if (start.isZero()) start = array->header.stamp;
        for (const auto& state : array->states) {
          if (state.id != "block") continue;
          const auto& q = state.pose.orientation;
          const auto& w = state.twist.angular;
          const auto& v = state.twist.linear;
          lowest = std::min(lowest, state.pose.position.z - kHalf);
          largest_spin = std::max(largest_spin, std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z));
          worst_orientation =
              std::max(worst_orientation,
                       std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + (q.w - 1) * (q.w - 1)));
          last_height = state.pose.position.z;
          last_speed = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
          last_time = (array->header.stamp - start).toSec();
        }
      });
  ros::Subscriber markers = node.subscribe<visualization_msgs::MarkerArray>(
      "markers", 100, [&](const visualization_msgs::MarkerArray::ConstPtr& array) {
        for (const auto& m : array->markers) {
          if (m.ns == "bodies" && m.text == "block") marker = m;
        }
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(40.0);
  while (ros::ok() && ros::WallTime::now() < end && (last_time < 1.4 || !marker)) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_GE(impacts.size(), 8u) << "two landings on four corners each";

  const double t1 = std::sqrt(2 * kDrop / kG);
  const double v = kG * t1;
  // The first landing: four corners at once.
  std::vector<std::pair<double, double>> corners;
  for (std::size_t k = 0; k < 4; ++k) {
    const collision_response::Impact& impact = impacts[k];
    SCOPED_TRACE("impact " + std::to_string(k));
    EXPECT_EQ(impact.body_a, "block");
    EXPECT_EQ(impact.body_b, "floor");
    EXPECT_NEAR((impact.header.stamp - start).toSec(), t1, 2e-9);
    EXPECT_NEAR(impact.normal.z, -1.0, 1e-15);  // from the box into the floor
    EXPECT_NEAR(impact.velocity_a_before.linear.z, -v, 1e-10);
    EXPECT_NEAR(impact.velocity_a_after.linear.z, kE * v, 1e-10);
    EXPECT_NEAR(std::hypot(impact.velocity_a_after.linear.x, impact.velocity_a_after.linear.y), 0,
                1e-12);
    const auto& w = impact.velocity_a_after.angular;
    EXPECT_NEAR(std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z), 0, 1e-12) << "no spin";
    EXPECT_NEAR(impact.impulse, (1 + kE) * kMass * v / 4, 1e-10);
    EXPECT_NEAR(impact.contact_point.z, 0, 1e-12);
    EXPECT_NEAR(std::abs(impact.contact_point.x), kHalf, 1e-12);
    EXPECT_NEAR(std::abs(impact.contact_point.y), kHalf, 1e-12);
    corners.emplace_back(impact.contact_point.x, impact.contact_point.y);
  }
  std::sort(corners.begin(), corners.end());
  EXPECT_EQ(std::unique(corners.begin(), corners.end()) - corners.begin(), 4) << "four corners";
  // The second landing, at 2 t1 at e v.
  for (std::size_t k = 4; k < 8; ++k) {
    const collision_response::Impact& impact = impacts[k];
    SCOPED_TRACE("impact " + std::to_string(k));
    EXPECT_NEAR((impact.header.stamp - start).toSec(), 2 * t1, 1e-8);
    EXPECT_NEAR(impact.velocity_a_before.linear.z, -kE * v, 1e-7);
    EXPECT_NEAR(impact.velocity_a_after.linear.z, kE * kE * v, 1e-7);
    const auto& w = impact.velocity_a_after.angular;
    EXPECT_NEAR(std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z), 0, 1e-12) << "no spin";
  }
  // Every landing before the series' end, 3 t1; the box then rests on the floor, never in it.
  for (const collision_response::Impact& impact : impacts) {
    EXPECT_LT((impact.header.stamp - start).toSec(), 3 * t1 + 1e-6);
  }
  EXPECT_GT(lowest, -1e-12) << "a played state inside the floor";
  EXPECT_NEAR(last_height, kHalf, 1e-12) << "at rest on the floor at " << last_time << " s";
  EXPECT_NEAR(last_speed, 0, 1e-12);
  EXPECT_LT(largest_spin, 1e-12);
  EXPECT_LT(worst_orientation, 1e-12) << "the scene's orientation (not turned) throughout";
  // The node's marker: a CUBE of the box's edges at its orientation.
  ASSERT_TRUE(marker);
  EXPECT_EQ(marker->type, visualization_msgs::Marker::CUBE);
  EXPECT_EQ(marker->scale.x, 2 * kHalf);
  EXPECT_EQ(marker->scale.y, 2 * kHalf);
  EXPECT_EQ(marker->scale.z, 2 * kHalf);
  const auto& q = marker->pose.orientation;
  EXPECT_NEAR(std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + (q.w - 1) * (q.w - 1)), 0, 1e-12);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "box_drop_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
