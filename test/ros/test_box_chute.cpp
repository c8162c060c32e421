// A box sliding down a chute on two obstacles at once, played through demo.launch over real
// topics (config/scenes/box_chute.yaml): a cube of m = 0.5 kg in the corner of a chute falling at
// beta = 20 degrees along x, rolled by gamma = 30 degrees towards its wall; the floor's mu1 = 0.4,
// the wall's mu2 = 0.3, launched down it at v0 = 0.6 m/s. Closed forms, worked here:
//  - across the chute nothing moves: the floor carries N1 = m g cos(beta) cos(gamma), the wall
//    N2 = m g cos(beta) sin(gamma) (gravity's parts along their normals);
//  - along it, a = g sin(beta) - (mu1 N1 + mu2 N2) / m while it slides: s = v0 t + a t^2 / 2,
//    both faces' friction summing to m (a - g sin(beta)) along the chute;
//  - it stops at -v0 / a and rests there, held by friction summing to -m g sin(beta).
// A can lying on its side along the chute (m = 0.4 kg), 0.3 m behind it at the same speed, by
// the same closed forms (they do not depend on the body).
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <Eigen/Core>
#include <cmath>
#include <map>
#include <vector>

#include "played_scene.h"

namespace {

constexpr double kG = 9.81, kV0 = 0.6, kMu1 = 0.4, kMu2 = 0.3;
const std::map<std::string, double> kMasses = {{"block", 0.5}, {"can", 0.4}};
const double kBeta = 20 * M_PI / 180, kGamma = 30 * M_PI / 180;

using collision_response::testing::vec;

TEST(BoxChute, TheBoxAndTheCanSlideDownTheChuteOnBothFacesToTheClosedFormsRest) {
  const Eigen::Vector3d down(std::cos(kBeta), 0, -std::sin(kBeta));
  const double a = kG * (std::sin(kBeta) - kMu1 * std::cos(kBeta) * std::cos(kGamma) -
                         kMu2 * std::cos(kBeta) * std::sin(kGamma));
  const double stops = -kV0 / a;
  ros::NodeHandle node;
  collision_response::testing::PlayedScene played(node);
  played.waitFor({"block", "can"}, 0.9, 40.0);
  auto& first = played.first;
  auto& states = played.states;
  // Per body, each contacts message's normal force per obstacle, friction on the body, modes.
  struct Carried {
    double time;
    std::map<std::string, double> normal;
    Eigen::Vector3d friction = Eigen::Vector3d::Zero();
    std::vector<std::string> modes;
  };
  std::map<std::string, std::vector<Carried>> carried;
  for (const auto& [body, messages] : played.contacts) {
    for (const auto& message : messages) {
      Carried c{message.time, {}, Eigen::Vector3d::Zero(), {}};
      for (const auto& contact : message.contacts) {
        c.normal[contact.body_b] += contact.normal_force;
        c.friction -= vec(contact.friction_force);  // on the body
        c.modes.push_back(contact.state);
      }
      carried[body].push_back(c);
    }
  }
  const std::size_t impacts = played.impacts;
  EXPECT_EQ(impacts, 0u) << "they slide on both from the start: nothing strikes";
  double worst_position = 0, worst_velocity = 0, worst_force = 0;
  for (const auto& [body, mass] : kMasses) {
    SCOPED_TRACE(body);
    const double weight = mass * kG;
    ASSERT_EQ(first.count(body), 1u) << "the first state heard was not the scene's first";
    ASSERT_GT(states[body].size(), 50u);
    for (const auto& state : states[body]) {
      const double t = std::min(state.time, stops);
      const Eigen::Vector3d expected = first[body] + (kV0 * t + a * t * t / 2) * down;
      worst_position = std::max(worst_position, (state.position - expected).norm());
      const Eigen::Vector3d velocity =
          state.time < stops ? Eigen::Vector3d((kV0 + a * t) * down) : Eigen::Vector3d::Zero();
      // (Within the slip's last 1e-6 m/s of the stop: taken out there.)
      if (std::abs(state.time - stops) > 1e-5) {
        worst_velocity = std::max(worst_velocity, (state.velocity - velocity).norm());
      }
    }
    ASSERT_GT(carried[body].size(), 50u);
    bool rested = false;
    for (const Carried& c : carried[body]) {
      SCOPED_TRACE("contacts at " + std::to_string(c.time) + " s");
      ASSERT_EQ(c.normal.size(), 2u) << "on the floor and the wall at once";
      worst_force =
          std::max({worst_force,
                    std::abs(c.normal.at("floor") - weight * std::cos(kBeta) * std::cos(kGamma)),
                    std::abs(c.normal.at("wall") - weight * std::cos(kBeta) * std::sin(kGamma))});
      const double along =
          c.time < stops ? mass * (a - kG * std::sin(kBeta)) : -weight * std::sin(kBeta);
      worst_force = std::max(worst_force, (c.friction - along * down).norm());
      if (c.time > stops) {
        rested = true;
        for (const std::string& mode : c.modes) EXPECT_NE(mode, "sliding");
      }
    }
    EXPECT_TRUE(rested);
  }
  EXPECT_LT(worst_position, 1e-9);
  EXPECT_LT(worst_velocity, 1e-8);
  EXPECT_LT(worst_force, 1e-9 * kMasses.at("block") * kG);
  std::printf("position %.3g m, velocity %.3g m/s, forces %.3g N\n", worst_position, worst_velocity,
              worst_force);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "box_chute_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
