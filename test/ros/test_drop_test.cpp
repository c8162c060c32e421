// The seed's drop test over ROS (node + scene player + gravity): each ball dropped from rest with
// its lowest point h = 1 m above the floor comes back up to h' = e^2 h, so e = sqrt(h'/h) from
// the first apex must be the slide's coefficient of that ball on concrete, within 1e-9.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cmath>
#include <map>
#include <string>

#include "collision_response/BodyState.h"

namespace {

// The slide "Coefficients of restitution of balls bounced on a concrete surface", by the drop
// scene's body ids, with each ball's radius from config/scenes/drop_test.yaml.
struct Ball {
  double restitution;
  double radius;
};
const std::map<std::string, Ball> kSlide = {{"range_golf", {0.858, 0.02135}},
                                            {"tennis", {0.712, 0.0335}},
                                            {"billiard", {0.804, 0.028575}},
                                            {"hand", {0.752, 0.095}},
                                            {"wooden", {0.603, 0.03}},
                                            {"steel", {0.597, 0.0127}},
                                            {"glass_marble", {0.658, 0.008}},
                                            {"rubber_band", {0.828, 0.04}},
                                            {"hollow_hard_plastic", {0.688, 0.02}}};

TEST(DropTest, RecoversTheSeedsTableWithin1e9) {
  ros::NodeHandle node;
  std::map<std::string, double> first_apex;
  ros::Subscriber apexes = node.subscribe<collision_response::BodyState>(
      "apexes", 100, [&first_apex](const collision_response::BodyState::ConstPtr& apex) {
        first_apex.emplace(apex->id, apex->pose.position.z);
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(60.0);
  while (ros::ok() && ros::WallTime::now() < end && first_apex.size() < kSlide.size()) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_EQ(first_apex.size(), kSlide.size()) << "an apex for every ball";
  for (const auto& [id, ball] : kSlide) {
    const double bounce = first_apex.at(id) - ball.radius;  // the lowest point's height
    const double recovered = std::sqrt(bounce / 1.0);
    EXPECT_NEAR(recovered, ball.restitution, 1e-9 * ball.restitution) << id;
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "drop_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
