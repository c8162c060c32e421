// An open STL floor mesh beside a floor plane, played through demo.launch over real topics
// (test/ros/open_mesh_floor.test, open_mesh_floor.yaml; issue 39, item 1). Closed forms, tennis
// ball on concrete e = 0.712, r = 0.05, g = 9.81, gravity only:
//  - `beside` falls from (10, 0, 0.3), 4 m beside the mesh (x in [14, 16]) and under its plane
//    (z = 0.5): an open mesh has no inside, so it meets the floor plane under itself, at
//    (10, 0, 0), at t = sqrt(2 (0.3 - r) / g) with u = g t, and keeps x = 10 all along (before:
//    no impact, and it ended at (14.05, 0, 0.55) on the mesh's edge);
//  - `on_mesh` falls from (15, 0, 1) onto the mesh's top: it meets it at (15, 0, 0.5) at
//    t = sqrt(2 (1 - 0.5 - r) / g) and leaves at e u straight up.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cmath>
#include <map>
#include <string>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"

namespace {

constexpr double kG = 9.81, kE = 0.712, kR = 0.05;

TEST(OpenMeshFloor, ABallBesideAnOpenMeshMeetsTheFloorUnderItself) {
  ros::NodeHandle node;
  std::map<std::string, collision_response::Impact> first;
  ros::Time start;
  bool started_at_rest = false;
  double beside_x_off = 0, last = 0;  // the farthest `beside` strays from x = 10; scene time
  ros::Subscriber impacts = node.subscribe<collision_response::ImpactArray>(
      "impacts", 100, [&](const collision_response::ImpactArray::ConstPtr& array) {
        for (const auto& impact : array->impacts) first.emplace(impact.body_a, impact);
      });
  ros::Subscriber states = node.subscribe<collision_response::BodyStateArray>(
      "body_states", 1000, [&](const collision_response::BodyStateArray::ConstPtr& array) {
        if (start.isZero()) {
          // The player's first state (the scene's instant 0): both balls at rest.
          start = array->header.stamp;
          started_at_rest = !array->states.empty();
          for (const auto& state : array->states) {
            started_at_rest = started_at_rest && state.twist.linear.z == 0.0;
          }
        }
        last = (array->header.stamp - start).toSec();
        for (const auto& state : array->states) {
          if (state.id == "beside") {
            beside_x_off = std::max(beside_x_off, std::abs(state.pose.position.x - 10.0));
          }
        }
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(40.0);
  while (ros::ok() && ros::WallTime::now() < end && (last < 1.0 || first.size() < 2)) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_TRUE(started_at_rest) << "the first state heard was not the scene's first";
  ASSERT_TRUE(first.count("beside")) << "no impact of the ball beside the open mesh";
  ASSERT_TRUE(first.count("on_mesh")) << "no impact of the ball dropped onto the open mesh";

  const collision_response::Impact& beside = first.at("beside");
  const double t_floor = std::sqrt(2 * (0.3 - kR) / kG);
  EXPECT_EQ(beside.body_b, "floor");
  EXPECT_NEAR((beside.header.stamp - start).toSec(), t_floor, 1e-9);
  EXPECT_NEAR(beside.contact_point.x, 10.0, 1e-9);
  EXPECT_NEAR(beside.contact_point.y, 0.0, 1e-9);
  EXPECT_NEAR(beside.contact_point.z, 0.0, 1e-9);
  EXPECT_NEAR(beside.normal.z, -1.0, 1e-12);
  EXPECT_NEAR(beside.velocity_a_before.linear.z, -kG * t_floor, 1e-9);
  EXPECT_NEAR(beside.velocity_a_after.linear.z, kE * kG * t_floor, 1e-9);
  EXPECT_LE(beside_x_off, 1e-9) << "the ball beside the mesh was moved sideways";

  const collision_response::Impact& top = first.at("on_mesh");
  const double t_top = std::sqrt(2 * (1.0 - 0.5 - kR) / kG);
  EXPECT_EQ(top.body_b, "open_floor");
  EXPECT_NEAR((top.header.stamp - start).toSec(), t_top, 1e-9);
  EXPECT_NEAR(top.contact_point.x, 15.0, 1e-9);
  EXPECT_NEAR(top.contact_point.z, 0.5, 1e-9);
  EXPECT_NEAR(top.normal.z, -1.0, 1e-12);
  EXPECT_NEAR(top.velocity_a_after.linear.z, kE * kG * t_top, 1e-9);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "open_mesh_floor_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
