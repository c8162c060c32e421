// The integrated motion of curved lasting contact (contact/constrained_motion.h).
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <memory>
#include <vector>

#include "model/constrained_motion.h"

namespace collision_response::core::monitor {
namespace {

using V = Eigen::Vector3d;

// Integrated as far as it is looked at: the motion is the same (to the bit) whether it is asked
// for at its far end at once or extended piece by piece with queries in between, and so is the
// instant its mode changes. A solid ball (r = 0.05 m, 1 kg) on top of a fixed sphere (R = 0.1 m),
// spinning about x, so that its surface slips along y (mu = 0.5), at s0 = 1e-2 m/s: the slip
// stops after about 0.6 ms (s0 / (7/2 mu g)), within a motion of 2 ms.
TEST(ConstrainedMotion, IntegratedOnDemandTheMotionIsTheSameHoweverItIsAskedFor) {
  const double r = 0.05, big = 0.1, g = 9.81;
  ForceBody ball;
  ball.inverse_mass = 1.0;
  ball.spin_factor = 2.5;
  ball.radius = r;
  ball.angular_velocity = V(1e-2 / r, 0, 0);
  ball.acceleration = V(0, 0, -g);
  ForceBody sphere;
  sphere.radius = big;
  ConstrainedContact contact;
  contact.a = 0;
  contact.b = 1;
  contact.friction = 0.5;
  contact.mode = ContactMode::kSliding;
  const double start = 1.0, until = start + 2e-3;
  const auto make = [&] {
    return std::make_unique<ConstrainedStep>(
        std::vector<ForceBody>{ball, sphere}, std::vector<V>{V(0, 0, big + r), V::Zero()}, 1,
        std::vector<ConstrainedContact>{contact}, start, until, 1e-9, 1e-6, 1e-5);
  };
  const auto at_once = make();
  const V far = at_once->position(0, until);  // integrates on to its end
  ASSERT_TRUE(at_once->complete());
  const auto in_pieces = make();
  EXPECT_FALSE(in_pieces->complete());  // a 4096th of the way at first
  int pieces = 0;
  while (!in_pieces->complete() && pieces < 100) {
    (void)in_pieces->velocity(0, in_pieces->end());  // looked at where it has got to
    in_pieces->extend();
    ++pieces;
  }
  EXPECT_GT(pieces, 2);
  ASSERT_TRUE(in_pieces->complete());
  EXPECT_EQ(in_pieces->end(), at_once->end());
  EXPECT_EQ(in_pieces->modeChanged(), at_once->modeChanged());
  EXPECT_TRUE(at_once->modeChanged());  // the slip falls to the tolerance within the 2 ms
  for (int i = 0; i <= 16; ++i) {
    const double t = start + (at_once->end() - start) * i / 16;
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(in_pieces->position(0, t)[c], at_once->position(0, t)[c]) << t;
      EXPECT_EQ(in_pieces->angularVelocity(0, t)[c], at_once->angularVelocity(0, t)[c]) << t;
    }
  }
  EXPECT_EQ(in_pieces->position(0, until), far);
}

}  // namespace
}  // namespace collision_response::core::monitor
