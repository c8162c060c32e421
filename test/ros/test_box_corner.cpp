// A box sliding onto a table's corner and resting over it, played through demo.launch over real
// topics (config/scenes/box_corner.yaml): the table top 1 m square at z = 0.75, e = 0 and mu = 0.4
// against it; a 0.1 m cube (0.5 kg) sliding along the diagonal towards the corner (0.5, 0.5) from
// 0.3 m before it at u = sqrt(2 mu g 0.27). Closed forms, worked here:
//  - along the diagonal d, s(t) = u t - mu g t^2 / 2 from its start, on the table and over its
//    corner alike (the part of its face on the table carries it), stopping at u / (mu g),
//    0.03 m before the corner, at rest there for ever;
//  - the table carries the weight m g (normal forces along -z on the table), and while it slides
//    the friction mu m g against d, at rest none;
//  - over the corner (its face past both edges, from s = -0.0707 m), the table's corner is one of
//    its points, carrying part of its weight.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <Eigen/Core>
#include <cmath>
#include <map>
#include <vector>

#include "played_scene.h"

namespace {

constexpr double kG = 9.81, kMu = 0.4, kTop = 0.75;
const double kU = std::sqrt(2 * kMu * kG * 0.27);
struct Slide {
  double mass;
  Eigen::Vector3d along, corner;
};
const std::map<std::string, Slide> kBodies = {
    {"block", {0.5, Eigen::Vector3d(1, 1, 0).normalized(), Eigen::Vector3d(0.5, 0.5, kTop)}}};

using collision_response::testing::vec;

TEST(BoxCorner, TheBoxSlidesOverTheTablesCornerToTheClosedFormsRest) {
  const double stops = kU / (kMu * kG);
  ros::NodeHandle node;
  collision_response::testing::PlayedScene played(node);
  played.waitFor({"block"}, 0.9, 40.0);
  auto& first = played.first;
  auto& states = played.states;
  // Per body, each contacts message's normal force, the part at the table's corner, the friction
  // on the body and the modes.
  struct Carried {
    double time;
    double normal = 0.0;
    double on_corner = 0.0;
    Eigen::Vector3d friction = Eigen::Vector3d::Zero();
    std::vector<std::string> modes;
  };
  std::map<std::string, std::vector<Carried>> carried;
  for (const auto& [body, messages] : played.contacts) {
    for (const auto& message : messages) {
      Carried c;
      c.time = message.time;
      for (const auto& contact : message.contacts) {
        EXPECT_EQ(contact.body_b, "table");
        c.normal += contact.normal_force;
        if ((vec(contact.contact_point) - kBodies.at(body).corner).norm() < 1e-9) {
          c.on_corner += contact.normal_force;
        }
        c.friction -= vec(contact.friction_force);  // on the body
        c.modes.push_back(contact.state);
      }
      carried[body].push_back(c);
    }
  }
  const std::size_t impacts = played.impacts;
  EXPECT_EQ(impacts, 0u) << "they slide on the table from the start: nothing strikes";
  double worst_position = 0, worst_velocity = 0, worst_force = 0;
  for (const auto& [body, slide] : kBodies) {
    SCOPED_TRACE(body);
    const double weight = slide.mass * kG;
    ASSERT_EQ(first.count(body), 1u) << "the first state heard was not the scene's first";
    ASSERT_GT(states[body].size(), 50u);
    for (const auto& state : states[body]) {
      const double t = std::min(state.time, stops);
      const Eigen::Vector3d expected = first[body] + (kU * t - kMu * kG * t * t / 2) * slide.along;
      worst_position = std::max(worst_position, (state.position - expected).norm());
      const Eigen::Vector3d velocity = state.time < stops
                                           ? Eigen::Vector3d((kU - kMu * kG * t) * slide.along)
                                           : Eigen::Vector3d::Zero();
      // (Within the slip's last 1e-6 m/s of the stop: taken out there.)
      if (std::abs(state.time - stops) > 1e-5) {
        worst_velocity = std::max(worst_velocity, (state.velocity - velocity).norm());
      }
    }
    ASSERT_GT(carried[body].size(), 50u);
    bool rested = false;
    int on_corner = 0;
    for (const Carried& c : carried[body]) {
      SCOPED_TRACE("contacts at " + std::to_string(c.time) + " s");
      const Eigen::Vector3d friction =
          c.time < stops ? Eigen::Vector3d(-kMu * weight * slide.along) : Eigen::Vector3d::Zero();
      worst_force =
          std::max({worst_force, std::abs(c.normal - weight), (c.friction - friction).norm()});
      if (c.on_corner > 0) ++on_corner;
      if (c.time > stops) {
        rested = true;
        EXPECT_GT(c.on_corner, 0.0) << "at rest over the corner, the corner carries part of it";
        for (const std::string& mode : c.modes) EXPECT_NE(mode, "sliding");
      }
    }
    EXPECT_TRUE(rested);
    EXPECT_GT(on_corner, 20);
  }
  EXPECT_LT(worst_position, 1e-9);
  EXPECT_LT(worst_velocity, 1e-8);
  EXPECT_LT(worst_force, 1e-9 * kBodies.at("block").mass * kG);
  std::printf("position %.3g m, velocity %.3g m/s, forces %.3g N\n", worst_position, worst_velocity,
              worst_force);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "box_corner_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
