// The effective mass of a contact (solver/effective_mass.h): K against closed forms for a box
// struck at a corner and for spheres, K J as the velocity change it stands for, and its normal
// entry for spheres the normal inverse mass w_a + w_b of the ball solvers to the bit.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "collision_response/core/friction.h"
#include "solver/effective_mass.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using M = Eigen::Matrix3d;

constexpr double kEps = std::numeric_limits<double>::epsilon();

// A box of 0.5 x 0.25 x 1 m and 3 kg, its edges along the axes, struck at its corner r =
// (0.25, -0.125, 0.5) by an immovable body. I = m/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2) =
// diag(17/64, 5/16, 5/64); with D = I^-1 and w = 1/3, -[r]x D [r]x written out by hand gives
// K_xx = w + r_y^2 D_z + r_z^2 D_y, K_xy = -r_x r_y D_z, and their permutations; in rationals
// (Python's fractions): K = [[4/3, 2/5, -2/5], [2/5, 529/255, 4/17], [-2/5, 4/17, 151/255]].
TEST(EffectiveMass, BoxStruckAtACornerAsItsClosedForm) {
  ContactSide box;
  box.inverse_mass = 1.0 / 3.0;
  box.inverse_inertia = V(64.0 / 17.0, 16.0 / 5.0, 64.0 / 5.0).asDiagonal();
  box.lever_arm = V(0.25, -0.125, 0.5);
  const ContactSide floor;  // immovable: w = 0, I^-1 = 0
  M expected;
  expected << 4.0 / 3.0, 2.0 / 5.0, -2.0 / 5.0, 2.0 / 5.0, 529.0 / 255.0, 4.0 / 17.0, -2.0 / 5.0,
      4.0 / 17.0, 151.0 / 255.0;
  for (const M& k : {inverseEffectiveMass(box, floor), inverseEffectiveMass(floor, box)}) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        EXPECT_NEAR(k(i, j), expected(i, j), 8 * kEps) << i << ", " << j;
      }
    }
  }
  // Along the floor's normal the box's effective mass is 255/151 kg, not its 3 kg.
  EXPECT_NEAR(inverseEffectiveMassAlong(box, floor, V::UnitZ()), 151.0 / 255.0, 4 * kEps);
  EXPECT_NEAR(inverseEffectiveMassAlong(box, floor, V(0, 0.6, 0.8)),
              0.36 * 529.0 / 255.0 + 2 * 0.48 * 4.0 / 17.0 + 0.64 * 151.0 / 255.0, 8 * kEps);
}

// K J is the relative velocity change at the contact from J on b and -J on a: each side's point
// moves by w J + (I^-1 (r x J)) x r (the impulse's linear and angular effect). Random bodies with
// full inertia tensors (a rotated diagonal one) and random lever arms; K is symmetric.
TEST(EffectiveMass, KTimesAnImpulseIsTheVelocityChangeAtThePoint) {
  std::mt19937_64 random(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), positive(0.1, 2.0);
  const auto side = [&] {
    ContactSide s;
    s.inverse_mass = positive(random);
    const Eigen::Quaterniond turn =
        Eigen::Quaterniond(unit(random), unit(random), unit(random), unit(random)).normalized();
    const M r = turn.toRotationMatrix();
    s.inverse_inertia =
        r * V(positive(random), positive(random), positive(random)).asDiagonal() * r.transpose();
    s.lever_arm = V(unit(random), unit(random), unit(random));
    return s;
  };
  for (int trial = 0; trial < 100; ++trial) {
    const ContactSide a = side(), b = side();
    const V impulse(unit(random), unit(random), unit(random));
    const auto change = [&](const ContactSide& s, const V& j) -> V {
      return s.inverse_mass * j + (s.inverse_inertia * s.lever_arm.cross(j)).cross(s.lever_arm);
    };
    const V relative = change(b, impulse) - change(a, -impulse);
    const M k = inverseEffectiveMass(a, b);
    EXPECT_LT((k * impulse - relative).lpNorm<Eigen::Infinity>(), 64 * kEps) << trial;
    EXPECT_LT((k - k.transpose()).lpNorm<Eigen::Infinity>(), 16 * kEps) << trial;
    const V d = V(unit(random), unit(random), unit(random)).normalized();
    EXPECT_NEAR(inverseEffectiveMassAlong(a, b, d), d.dot(k * d), 64 * kEps) << trial;
  }
}

// Two spheres (or a sphere and an immovable body) whose lever arms lie along the normal, r_a =
// R_a n and r_b = -R_b n: the normal entry n.K.n is w_a + w_b to the bit, the normal inverse
// mass the ball solvers use (resolveImpact's W, the stepped solve's energy owed), for masses from
// 1e-6 to 1e6 kg and immovable, radii from 1e-4 to 10 m and points, solid and hollow, with and
// without spin. Across the normal the entry is w (1 + 1/k) per side: a sphere's r^2 / I = w / k.
TEST(EffectiveMass, SpheresNormalEntryIsTheSumOfInverseMassesToTheBit) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> exponent(-6.0, 6.0), radius_exponent(-4.0, 1.0),
      gaussian_ish(-1.0, 1.0);
  std::uniform_int_distribution<int> choice(0, 7);
  struct Ball {
    double inverse_mass, spin_factor, radius;
  };
  const auto ball = [&] {
    const int kind = choice(random);
    Ball s;
    s.inverse_mass = kind == 0 ? 0.0 : 1.0 / std::pow(10.0, exponent(random));
    s.radius = kind == 1 ? 0.0 : std::pow(10.0, radius_exponent(random));
    const Inertia inertia = kind % 2 ? Inertia::kSolid : Inertia::kHollow;
    s.spin_factor = kind == 2 ? 0.0 : spinFactor(s.inverse_mass, s.radius, inertia);
    return s;
  };
  int tested = 0;
  for (int trial = 0; trial < 100000; ++trial) {
    const Ball a = ball(), b = ball();
    if (a.inverse_mass + b.inverse_mass == 0.0) continue;  // no impact between two immovables
    V n(gaussian_ish(random), gaussian_ish(random), gaussian_ish(random));
    if (!(n.norm() > 0.01)) continue;
    n.normalize();
    ContactSide side_a{a.inverse_mass,
                       sphereInverseInertia(a.inverse_mass, a.spin_factor, a.radius), a.radius * n};
    ContactSide side_b{b.inverse_mass,
                       sphereInverseInertia(b.inverse_mass, b.spin_factor, b.radius),
                       -b.radius * n};
    const double solvers = a.inverse_mass + b.inverse_mass;
    ASSERT_EQ(inverseEffectiveMassAlong(side_a, side_b, n), solvers) << trial;
    ASSERT_EQ(inverseEffectiveMassAlong(side_b, side_a, -n), solvers) << trial;
    // A unit t across n: r x t has length R, and R^2 (w / k) / R^2 = w / k.
    const V t = n.unitOrthogonal();
    const double across =
        a.inverse_mass * (1 + a.spin_factor) + b.inverse_mass * (1 + b.spin_factor);
    EXPECT_NEAR(inverseEffectiveMassAlong(side_a, side_b, t), across, 16 * kEps * across) << trial;
    ++tested;
  }
  EXPECT_GT(tested, 90000);
}

}  // namespace
}  // namespace collision_response::core
