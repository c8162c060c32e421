// The impact function's own contract: which way the impulse points, what "approaching" and
// "oblique" mean, and the float instantiation.
#include <gtest/gtest.h>

#include <limits>

#include "collision_response/core/impact.h"

namespace collision_response::core {
namespace {

TEST(Impact, ImpulsePushesBAlongTheNormalAndAAgainstIt) {
  // 1 kg at 2 m/s hits 1 kg at rest along x, e = 0.5: J = (1 + e) mu |d| = 1.5 * 0.5 * 2 = 1.5.
  const auto r = resolveImpact(1.0, Eigen::Vector3d(2, 0, 0), 1.0, Eigen::Vector3d::Zero().eval(),
                               Eigen::Vector3d(1, 0, 0), 0.5);
  EXPECT_TRUE(r.approaching);
  EXPECT_EQ(r.approach_speed, 2.0);
  EXPECT_EQ(r.normal_impulse, 1.5);
  EXPECT_EQ(r.velocity_a, Eigen::Vector3d(0.5, 0, 0));  // 2 - 1.5 / 1
  EXPECT_EQ(r.velocity_b, Eigen::Vector3d(1.5, 0, 0));  // 0 + 1.5 / 1
  // (1/2) mu (1 - e^2) d^2 = 0.5 * 0.5 * 0.75 * 4 = 0.75.
  EXPECT_EQ(r.energy_lost, 0.75);
}

TEST(Impact, BodiesMovingApartAreNotApproaching) {
  const auto r = resolveImpact(1.0, Eigen::Vector3d(-1, 0, 0), 1.0, Eigen::Vector3d(1, 0, 0),
                               Eigen::Vector3d(1, 0, 0), 0.5);
  EXPECT_FALSE(r.approaching);
  EXPECT_EQ(r.approach_speed, -2.0);
  EXPECT_EQ(r.normal_impulse, 0.0);
}

TEST(Impact, RelativeVelocityAlongTheTangentIsNotApproaching) {
  // d = 0 exactly: touching and sliding, no impulse.
  const auto r = resolveImpact(1.0, Eigen::Vector3d(0, 3, 0), 2.0, Eigen::Vector3d(0, -1, 0),
                               Eigen::Vector3d(1, 0, 0), 1.0);
  EXPECT_FALSE(r.approaching);
  EXPECT_EQ(r.velocity_a, Eigen::Vector3d(0, 3, 0));
  EXPECT_EQ(r.velocity_b, Eigen::Vector3d(0, -1, 0));
}

TEST(Impact, ObliqueMeansAVelocityAcrossTheLineOfImpact) {
  const Eigen::Vector3d x(1, 0, 0);
  EXPECT_FALSE(hasObliqueComponent(Eigen::Vector3d(5, 0, 0), x));
  EXPECT_FALSE(hasObliqueComponent(Eigen::Vector3d(0, 0, 0), x));
  EXPECT_TRUE(hasObliqueComponent(Eigen::Vector3d(5, 1e-6, 0), x));
  EXPECT_TRUE(hasObliqueComponent(Eigen::Vector3d(0, 1, 0), x));
  // Rounding of a derived normal is not an oblique impact.
  const Eigen::Vector3d n = Eigen::Vector3d(1, 1, 1).normalized();
  EXPECT_FALSE(hasObliqueComponent(Eigen::Vector3d(3 * n), n));
}

TEST(Impact, FloatGivesTheSameSimpleAnswers) {
  // Same case as above in float: every value is a small dyadic rational, so exact.
  const auto r = resolveImpact(1.0f, Eigen::Vector3f(2, 0, 0), 1.0f, Eigen::Vector3f::Zero().eval(),
                               Eigen::Vector3f(1, 0, 0), 0.5f);
  EXPECT_EQ(r.velocity_a, Eigen::Vector3f(0.5f, 0, 0));
  EXPECT_EQ(r.velocity_b, Eigen::Vector3f(1.5f, 0, 0));
  EXPECT_EQ(r.normal_impulse, 1.5f);
  // Immovable wall in float: exactly -e v.
  const auto wall =
      resolveImpact(1.0f / 0.057f, Eigen::Vector3f(0, 0, -4.43f), 0.0f,
                    Eigen::Vector3f::Zero().eval(), Eigen::Vector3f(0, 0, -1), 0.712f);
  EXPECT_EQ(wall.velocity_a.z(), 0.712f * 4.43f);
}

}  // namespace
}  // namespace collision_response::core
