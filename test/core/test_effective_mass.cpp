// The effective mass of a contact (solver/effective_mass.h): K against closed forms for a box
// struck at a corner and for spheres, K J as the velocity change it stands for, and its normal
// entry for spheres the normal inverse mass w_a + w_b of the ball solvers to the bit; the turn,
// the slip and the tangential inverse mass of solver bodies (solver/impulse_response.h): a
// ball's as its formulas, a body with a tensor as the closed form of a box.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "collision_response/core/friction.h"
#include "solver/effective_mass.h"
#include "solver/impulse_response.h"

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

// A ball's turn, slip and tangential inverse mass (impulse_response.h) are the formulas the ball
// solvers wrote out before they shared them, to the bit (written out here again): random balls,
// solid and hollow, immovable and points, with spin and without, in double and long double.
TEST(ImpulseResponse, ABallsTurnSlipAndTangentialInverseMassAreItsFormulasToTheBit) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> exponent(-6.0, 6.0), radius_exponent(-4.0, 1.0),
      unit(-1.0, 1.0);
  std::uniform_int_distribution<int> choice(0, 7);
  const auto vector = [&] { return V(unit(random), unit(random), unit(random)); };
  const auto ball = [&] {
    const int kind = choice(random);
    SolverBody s;
    s.inverse_mass = kind == 0 ? 0.0 : 1.0 / std::pow(10.0, exponent(random));
    s.radius = kind == 1 ? 0.0 : std::pow(10.0, radius_exponent(random));
    const Inertia inertia = kind % 2 ? Inertia::kSolid : Inertia::kHollow;
    s.spin_factor = kind == 2 ? 0.0 : spinFactor(s.inverse_mass, s.radius, inertia);
    s.velocity = vector();
    s.angular_velocity = 10 * vector();
    return s;
  };
  for (int trial = 0; trial < 10000; ++trial) {
    const SolverBody a = ball(), b = ball();
    ContactPoint contact;
    contact.normal = vector().normalized();
    const V& n = contact.normal;
    contact.lever_a = a.radius * n;
    contact.lever_b = -b.radius * n;
    V slip = b.velocity - a.velocity;
    slip += b.angular_velocity.cross(-b.radius * n) - a.angular_velocity.cross(a.radius * n);
    ASSERT_EQ(slipAt<true>(a, b, contact), V(slip - slip.dot(n) * n)) << trial;
    const V still = b.velocity - a.velocity;
    ASSERT_EQ(slipAt<false>(a, b, contact), V(still - still.dot(n) * n)) << trial;
    const auto unused = [] { return V(V::Constant(NAN)); };  // a ball's needs no direction
    ASSERT_EQ(tangentialInverseMass<true>(a, b, contact, unused),
              (a.inverse_mass + b.inverse_mass) +
                  (a.inverse_mass * a.spin_factor + b.inverse_mass * b.spin_factor))
        << trial;
    ASSERT_EQ(tangentialInverseMass<false>(a, b, contact, unused), a.inverse_mass + b.inverse_mass);
    const V impulse = vector();
    for (const SolverBody& body : {a, b}) {
      ASSERT_EQ(turns(body), body.spin_factor != 0.0 && body.radius > 0.0);
      if (!turns(body)) continue;
      const double factor = body.inverse_mass * body.spin_factor / body.radius;
      const auto unused_lever = [] { return V(V::Constant(NAN)); };  // a ball's is R n
      ASSERT_EQ(turnOf<double>(body, n, unused_lever, impulse), V(factor * n.cross(impulse)));
      using W = Eigen::Matrix<long double, 3, 1>;
      const W wide_n = n.cast<long double>(), wide_impulse = impulse.cast<long double>();
      const long double wide_factor = static_cast<long double>(body.inverse_mass) *
                                      static_cast<long double>(body.spin_factor) /
                                      static_cast<long double>(body.radius);
      ASSERT_EQ(turnOf<long double>(body, W(-wide_n), unused_lever, wide_impulse),
                W(wide_factor * (-wide_n).cross(wide_impulse)));
    }
  }
}

// A box given by its tensor (kTensor): the box of BoxStruckAtACornerAsItsClosedForm, w = 1/3,
// I^-1 = diag(64/17, 16/5, 64/5), its corner r = (0.25, -0.125, 0.5) on an immovable floor
// (side a, normal +z into the box). An impulse J = (0, 0, 1) there turns it by I^-1 (r x J) =
// I^-1 (-1/8, -1/4, 0) = (-8/17, -4/5, 0); moving at v = (1, 0, 0), w = (0, 0, 2), its corner
// slips at v + w x r = (1 + 1/4, 1/2, 0); along x its tangential inverse mass is K_xx = 4/3, along
// y 529/255 (the closed form's entries).
TEST(ImpulseResponse, ABoxGivenByItsTensorTurnsAndSlipsAsItsClosedForm) {
  SolverBody floor;
  SolverBody box;
  box.inverse_mass = 1.0 / 3.0;
  box.inertia_kind = InverseInertiaKind::kTensor;
  box.inverse_inertia = V(64.0 / 17.0, 16.0 / 5.0, 64.0 / 5.0).asDiagonal();
  box.velocity = V(1, 0, 0);
  box.angular_velocity = V(0, 0, 2);
  ContactPoint contact;
  contact.normal = V::UnitZ();
  contact.lever_b = V(0.25, -0.125, 0.5);
  ASSERT_TRUE(turns(box));
  ASSERT_FALSE(turns(floor));
  const V turn = turnOf<double>(
      box, V(-contact.normal), [&] { return contact.lever_b; }, V::UnitZ());
  EXPECT_NEAR(turn.x(), -8.0 / 17.0, 2 * kEps);
  EXPECT_NEAR(turn.y(), -4.0 / 5.0, 2 * kEps);
  EXPECT_EQ(turn.z(), 0.0);
  EXPECT_EQ(slipAt<true>(floor, box, contact), V(1.25, 0.5, 0));
  EXPECT_EQ(slipAt<false>(floor, box, contact), V(1, 0, 0));
  EXPECT_NEAR(tangentialInverseMass<true>(floor, box, contact, [] { return V(V::UnitX()); }),
              4.0 / 3.0, 4 * kEps);
  EXPECT_NEAR(tangentialInverseMass<true>(floor, box, contact, [] { return V(V::UnitY()); }),
              529.0 / 255.0, 8 * kEps);
  EXPECT_EQ(tangentialInverseMass<false>(floor, box, contact, [] { return V(V::UnitY()); }),
            1.0 / 3.0);
}

}  // namespace
}  // namespace collision_response::core
