// Time of impact against closed forms worked out by hand in the comments.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "collision_response/core/time_of_impact.h"

namespace collision_response::core {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
using V = Eigen::Vector3d;

TEST(TimeOfImpact, HeadOn) {
  // Centres 1 m apart closing at 2 m/s, contact distance 0.2 m: the gap 0.8 m closes in 0.4 s.
  const auto t = timeOfImpactSpheres<double>(V(1, 0, 0), V(-2, 0, 0), 0.2, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 0.4, 2 * kEps);
}

TEST(TimeOfImpact, OffCentre) {
  // s = (3, 0.6, 0), v = (-1, 0, 0), R = 1: (3 - t)^2 + 0.36 = 1, so 3 - t = 0.8, t = 2.2.
  const auto t = timeOfImpactSpheres<double>(V(3, 0.6, 0), V(-1, 0, 0), 1.0, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 2.2, 4 * kEps * 3);
}

TEST(TimeOfImpact, DiscriminantExactlyZeroIsATangentTouch) {
  // s = (3, 1, 0), v = (-1, 0, 0), R = 1: (3 - t)^2 + 1 = 1 has the double root t = 3.
  const auto t = timeOfImpactSpheres<double>(V(3, 1, 0), V(-1, 0, 0), 1.0, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 3.0, 4 * kEps * 3);
}

TEST(TimeOfImpact, NoContact) {
  // Passing by (miss distance 2 > R = 1), separating, overlapping already, too late.
  EXPECT_FALSE(timeOfImpactSpheres<double>(V(3, 2, 0), V(-1, 0, 0), 1.0, 10.0));
  EXPECT_FALSE(timeOfImpactSpheres<double>(V(3, 0, 0), V(1, 0, 0), 1.0, 10.0));
  EXPECT_FALSE(timeOfImpactSpheres<double>(V(0.5, 0, 0), V(-1, 0, 0), 1.0, 10.0));
  EXPECT_FALSE(timeOfImpactSpheres<double>(V(3, 0, 0), V(-1, 0, 0), 1.0, 1.9));
  EXPECT_FALSE(timeOfImpactSpheres<double>(V(3, 0, 0), V(0, 0, 0), 1.0, 10.0));
}

TEST(TimeOfImpact, TouchingAndClosingIsNow) {
  const auto t = timeOfImpactSpheres<double>(V(1, 0, 0), V(-1, 0, 0), 1.0, 10.0);
  ASSERT_TRUE(t);
  EXPECT_EQ(*t, 0.0);
}

TEST(TimeOfImpact, TinyGap) {
  // Gap 2^-40 m (~9e-13) closing at 1 m/s: t = 2^-40 s, to a few ulps of itself.
  const double gap = std::ldexp(1.0, -40);
  const auto t = timeOfImpactSpheres<double>(V(1 + gap, 0, 0), V(-1, 0, 0), 1.0, 1.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, gap, 4 * kEps * gap);
}

TEST(TimeOfImpact, FarAndFast) {
  // 1e8 m apart closing at 3e8 m/s, R = 1: t = (1e8 - 1) / 3e8.
  const auto t = timeOfImpactSpheres<double>(V(1e8, 0, 0), V(-3e8, 0, 0), 1.0, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, (1e8 - 1) / 3e8, 4 * kEps);
}

TEST(TimeOfImpact, HugeAndTinyMagnitudesDoNotOverflow) {
  // HeadOn with lengths and speeds both scaled by 1e150, then by 1e-150: unscaled, the squares
  // would overflow (underflow); t stays 0.4 s.
  auto t = timeOfImpactSpheres<double>(V(1e150, 0, 0), V(-2e150, 0, 0), 0.2e150, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 0.4, 4 * kEps);
  t = timeOfImpactSpheres<double>(V(1e-150, 0, 0), V(-2e-150, 0, 0), 0.2e-150, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 0.4, 4 * kEps);
}

TEST(TimeOfImpact, Plane) {
  // Surface 0.5 m above the plane, falling at 2 m/s: 0.25 s.
  const auto t = timeOfImpactPlane(0.5, -2.0, 1.0);
  ASSERT_TRUE(t);
  EXPECT_EQ(*t, 0.25);
  EXPECT_FALSE(timeOfImpactPlane(0.5, 2.0, 1.0));    // rising
  EXPECT_FALSE(timeOfImpactPlane(0.5, 0.0, 1.0));    // gliding along
  EXPECT_FALSE(timeOfImpactPlane(-0.1, -2.0, 1.0));  // already through
  EXPECT_FALSE(timeOfImpactPlane(0.5, -2.0, 0.2));   // after the horizon
}

TEST(TimeOfImpact, Float) {
  const auto t =
      timeOfImpactSpheres<float>(Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(-2, 0, 0), 0.2f, 10.0f);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 0.4f, 4 * std::numeric_limits<float>::epsilon());
}

}  // namespace
}  // namespace collision_response::core
