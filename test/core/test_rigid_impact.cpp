// One impact of two rigid bodies with rotation (issue 42, build step 3): the closed forms of
// test/exact/rigid_impact.py (rationals, written here as the doubles of their fractions), the
// law's guarantees over random impacts, balls bit for bit as today, and simultaneous contacts of
// a box.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <tuple>
#include <vector>

#include "collision_response/core/friction.h"
#include "collision_response/core/impact.h"
#include "collision_response/core/rigid_impact.h"
#include "collision_response/core/simultaneous.h"
#include "solver/impulse_response.h"

namespace collision_response::core {
namespace {

using RealL = long double;
constexpr double kEps = std::numeric_limits<double>::epsilon();

SolverBody floorBody() { return SolverBody{}; }  // immovable, still

SolverBody tensorBody(double mass, const Eigen::Matrix3d& inverse_inertia,
                      const Eigen::Vector3d& velocity, const Eigen::Vector3d& angular_velocity) {
  SolverBody body;
  body.inverse_mass = 1.0 / mass;
  body.inertia_kind = InverseInertiaKind::kTensor;
  body.inverse_inertia = inverse_inertia;
  body.velocity = velocity;
  body.angular_velocity = angular_velocity;
  return body;
}

ContactPoint contactOf(const Eigen::Vector3d& normal, const Eigen::Vector3d& lever_a,
                       const Eigen::Vector3d& lever_b) {
  ContactPoint contact;
  contact.a = 0;
  contact.b = 1;
  contact.normal = normal;
  contact.lever_a = lever_a;
  contact.lever_b = lever_b;
  return contact;
}

/// |x - y| within `ulps` units in the last place of `scale` in every component.
void expectNear(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected, double scale,
                double ulps, const char* what) {
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(actual[i], expected[i], ulps * kEps * scale) << what << "[" << i << "]";
  }
}

/// Kinetic energy of a body given by its mass (inf: immovable, none) and inertia tensor I.
RealL kineticEnergy(const SolverBody& body, const Eigen::Matrix3d& inertia) {
  if (body.inverse_mass == 0.0) return 0;
  const Eigen::Matrix<RealL, 3, 1> v = body.velocity.cast<RealL>();
  const Eigen::Matrix<RealL, 3, 1> w = body.angular_velocity.cast<RealL>();
  return RealL(0.5) * v.dot(v) / RealL(body.inverse_mass) +
         RealL(0.5) * w.dot(inertia.cast<RealL>() * w);
}

// A box of edges (1, 2, 3) m and 6 kg, turned by the rational rotation of the quaternion
// (2, 1, -1, 1) (rows (3, -6, -2)/7, (2, 3, -6)/7, (6, 2, 3)/7), its corner (-1/2, -1, -3/2) of
// its own frame at (15/14, 5/7, -19/14) from its centre, strikes a still floor (n = z) moving at
// (1/2, -1/4, -3) m/s and turning at (1, -2, 1/2) rad/s, e = 1/2, frictionless. Exact
// (test/exact/rigid_impact.py): P = 126/353 N s along z, v' = (1/2, -1/4, -1038/353),
// w' = (2561/2471, -5239/2471, 2579/4942), energy lost 9/706 J.
TEST(RigidImpact, ABoxStruckAtACornerFrictionlessIsItsClosedForm) {
  Eigen::Matrix3d inverse_inertia;
  inverse_inertia << 662.0 / 3185, 138.0 / 3185, -132.0 / 3185,  //
      138.0 / 3185, 1093.0 / 3185, -54.0 / 637,                  //
      -132.0 / 3185, -54.0 / 637, 646.0 / 3185;
  SolverBody floor = floorBody();
  SolverBody box = tensorBody(6.0, inverse_inertia, Eigen::Vector3d(0.5, -0.25, -3.0),
                              Eigen::Vector3d(1.0, -2.0, 0.5));
  const ContactPoint contact = contactOf(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::Zero(),
                                         Eigen::Vector3d(15.0 / 14, 5.0 / 7, -19.0 / 14));
  const auto outcome = resolveRigidImpact(floor, box, contact, 0.5, 0.0);
  ASSERT_TRUE(outcome.ok()) << outcome.error().message();
  EXPECT_NEAR(outcome->normal_impulse, 126.0 / 353, 4 * kEps * (126.0 / 353));
  expectNear(outcome->impulse, Eigen::Vector3d(0, 0, 126.0 / 353), 126.0 / 353, 4, "impulse");
  EXPECT_EQ(outcome->tangential_impulse.norm(), 0.0);
  expectNear(box.velocity, Eigen::Vector3d(0.5, -0.25, -1038.0 / 353), 3.0, 4, "v'");
  expectNear(box.angular_velocity, Eigen::Vector3d(2561.0 / 2471, -5239.0 / 2471, 2579.0 / 4942),
             2.2, 4, "w'");
  EXPECT_NEAR(outcome->energy_lost, 9.0 / 706, 4 * kEps * (9.0 / 706));
  const Eigen::Vector3d corner(15.0 / 14, 5.0 / 7, -19.0 / 14);
  EXPECT_NEAR(outcome->approach_speed, 1.0 / 7, 8 * kEps);  // -(v + w x r).z = 3 - 20/7
  EXPECT_EQ(floor.velocity, Eigen::Vector3d::Zero());       // immovable
}

// A rod (a box 0.2 x 2 x 0.2 m, 1 kg, long along its y) tilted by theta (sin 5/13, cos 12/13)
// about z falls at 1 m/s drifting at -0.1 m/s onto a still floor (n = y), its lower end's centre
// (5/13, -12/13, 0) from its centre striking, e = 1, mu = 1/2 (Kane and Levinson's example;
// Stronge 1991). Newton's algebraic law with Coulomb friction along the initial slip (u_n' =
// -e u_n, P_t = -mu P_n s0) gives P = (17069/33569, 34138/33569, 0) and GAINS 3821544272 /
// 5634388805 = 0.678 J (more than the 0.505 J the rod had): the slip reverses under it. The
// law here sticks (kappa = 1): P = (-155431/677690, 2593273922/1665016561, 0), v' =
// (-22320/67769, 928257361/1665016561, 0), w' = (0, 0, 147351840/128078197), and LOSES
// 24158795761/333003312200 = 0.0725 J (test/exact/rigid_impact.py).
TEST(RigidImpact, ARodOnItsEndLosesEnergyWhereNewtonsLawWithCoulombFrictionGainsIt) {
  Eigen::Matrix3d inverse_inertia;
  inverse_inertia << 421950.0 / 17069, -891000.0 / 17069, 0.0,  //
      -891000.0 / 17069, 2189100.0 / 17069, 0.0,                //
      0.0, 0.0, 300.0 / 101;
  const Eigen::Vector3d end(5.0 / 13, -12.0 / 13, 0.0);
  const ContactPoint contact = contactOf(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero(), end);
  SolverBody floor = floorBody();
  SolverBody rod =
      tensorBody(1.0, inverse_inertia, Eigen::Vector3d(-0.1, -1.0, 0.0), Eigen::Vector3d::Zero());

  // Newton's algebraic law, written out here from K (the comparison, not the law under test).
  Eigen::Matrix3d cross;
  cross << 0, -end.z(), end.y(), end.z(), 0, -end.x(), -end.y(), end.x(), 0;
  const Eigen::Matrix3d k = Eigen::Matrix3d::Identity() - cross * inverse_inertia * cross;
  const Eigen::Vector3d u0 = rod.velocity;  // not turning
  const Eigen::Vector3d n = contact.normal;
  const Eigen::Vector3d along = n - 0.5 * Eigen::Vector3d(u0.x() > 0 ? 1.0 : -1.0, 0, 0);
  const Eigen::Vector3d newton = (-(1.0 + 1.0) * u0.dot(n) / n.dot(k * along)) * along;
  expectNear(newton, Eigen::Vector3d(17069.0 / 33569, 34138.0 / 33569, 0), 1.0, 16, "Newton");
  const double newton_gain = newton.dot(u0) + 0.5 * newton.dot(k * newton);
  EXPECT_NEAR(newton_gain, 3821544272.0 / 5634388805, 1e-14);
  EXPECT_GT(newton_gain, 0.505);  // more than the rod had

  const auto outcome = resolveRigidImpact(floor, rod, contact, 1.0, 0.5);
  ASSERT_TRUE(outcome.ok()) << outcome.error().message();
  EXPECT_TRUE(outcome->sticking);
  expectNear(outcome->impulse, Eigen::Vector3d(-155431.0 / 677690, 2593273922.0 / 1665016561, 0),
             1.6, 16, "P");
  expectNear(rod.velocity, Eigen::Vector3d(-22320.0 / 67769, 928257361.0 / 1665016561, 0), 1.0, 16,
             "v'");
  expectNear(rod.angular_velocity, Eigen::Vector3d(0, 0, 147351840.0 / 128078197), 1.2, 16, "w'");
  EXPECT_NEAR(outcome->energy_lost, 24158795761.0 / 333003312200, 16 * kEps);
  // The loss measured from the states: 1/2 m v^2 + 1/2 w.I.w before and after.
  const Eigen::Matrix3d inertia = inverse_inertia.inverse();
  SolverBody before =
      tensorBody(1.0, inverse_inertia, Eigen::Vector3d(-0.1, -1.0, 0.0), Eigen::Vector3d::Zero());
  EXPECT_NEAR(static_cast<double>(kineticEnergy(before, inertia) - kineticEnergy(rod, inertia)),
              24158795761.0 / 333003312200, 1e-14);
  // Newton's e along the normal: the end leaves at e times its approach.
  EXPECT_NEAR((rod.velocity + rod.angular_velocity.cross(end)).dot(n), 1.0, 8 * kEps);
}

/// A random unit quaternion's rotation.
Eigen::Matrix3d randomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> gauss;
  Eigen::Quaterniond q(gauss(rng), gauss(rng), gauss(rng), gauss(rng));
  return q.normalized().toRotationMatrix();
}

/// A random body's inertia (principal moments from random second moments c_i >= 0: I_1 =
/// c_2 + c_3, ..., the triangle inequality held), turned at random, and the mass.
struct RandomBody {
  SolverBody body;
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

RandomBody randomBody(std::mt19937_64& rng, bool immovable) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> symmetric(-1.0, 1.0);
  RandomBody random;
  random.body.velocity = Eigen::Vector3d(symmetric(rng), symmetric(rng), symmetric(rng));
  random.body.angular_velocity =
      3.0 * Eigen::Vector3d(symmetric(rng), symmetric(rng), symmetric(rng));
  if (immovable) {  // still: a moving wall may give energy
    random.body.velocity.setZero();
    random.body.angular_velocity.setZero();
    return random;
  }
  const double mass = 0.1 + 10.0 * unit(rng);
  random.body.inverse_mass = 1.0 / mass;
  if (unit(rng) < 0.2) {  // a ball
    random.body.inertia_kind = InverseInertiaKind::kIsotropic;
    random.body.radius = 0.05 + unit(rng);
    random.body.spin_factor = unit(rng) < 0.5 ? 2.5 : 1.5;
    random.inertia = Eigen::Matrix3d::Identity() *
                     (mass * random.body.radius * random.body.radius / random.body.spin_factor);
    return random;
  }
  const Eigen::Vector3d second =
      mass * Eigen::Vector3d(0.01 + unit(rng), 0.01 + unit(rng), 0.01 + unit(rng));
  const Eigen::Vector3d moments(second.y() + second.z(), second.x() + second.z(),
                                second.x() + second.y());
  const Eigen::Matrix3d turn = randomRotation(rng);
  random.body.inertia_kind = InverseInertiaKind::kTensor;
  random.body.inverse_inertia = turn * moments.cwiseInverse().asDiagonal() * turn.transpose();
  random.inertia = turn * moments.asDiagonal() * turn.transpose();
  return random;
}

/// A random contact between `a` and `b`: lever arms of up to 1 m (a ball's R n, -R n), a random
/// normal.
ContactPoint randomContact(std::mt19937_64& rng, const SolverBody& a, const SolverBody& b) {
  std::uniform_real_distribution<double> symmetric(-1.0, 1.0);
  ContactPoint contact;
  contact.a = 0;
  contact.b = 1;
  contact.normal = randomRotation(rng).col(2);
  const auto lever = [&](const SolverBody& body, double side) -> Eigen::Vector3d {
    if (body.inertia_kind == InverseInertiaKind::kIsotropic) {
      return side * body.radius * contact.normal;
    }
    return Eigen::Vector3d(symmetric(rng), symmetric(rng), symmetric(rng));
  };
  contact.lever_a = lever(a, 1.0);
  contact.lever_b = lever(b, -1.0);
  return contact;
}

/// The number of random impacts: COLLISION_RESPONSE_RANDOM_IMPACTS, by default 10^6 (the
/// sanitizer lane may ask for fewer).
long randomImpactCount() {
  const char* text = std::getenv("COLLISION_RESPONSE_RANDOM_IMPACTS");
  return text != nullptr ? std::max(1L, std::atol(text)) : 1000000L;
}

// 10^6 random impacts (random masses, tensors in random orientations, balls among them, lever
// arms, normals, velocities, e in [0, 1] (1 a tenth of the time), mu in [0, 2], 0 or 100): no
// energy gained past 1e-12 of
// the energy before, Newton's e along the normal, the impulse in Coulomb's cone, and each
// body's angular momentum about the contact point conserved (to 64 eps of its terms).
TEST(RigidImpact, RandomImpactsNeverGainEnergyAndConserveAngularMomentumAboutTheContact) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const long count = randomImpactCount();
  long impacts = 0, sliding = 0;
  RealL worst_gain = -1;
  double worst_momentum = 0;  // in eps of its terms
  for (long trial = 0; trial < count; ++trial) {
    RandomBody a = randomBody(rng, unit(rng) < 0.3);
    RandomBody b = randomBody(rng, false);
    const ContactPoint contact = randomContact(rng, a.body, b.body);
    // e = 1 and mu = 0 a tenth of the time each: where the energy is kept (e = 1 frictionless),
    // rounding is all that could gain it.
    const double restitution = unit(rng) < 0.1 ? 1.0 : unit(rng);
    const double pick = unit(rng);
    const double friction = pick < 0.1 ? 100.0 : pick < 0.2 ? 0.0 : 2.0 * unit(rng);
    const RealL before = kineticEnergy(a.body, a.inertia) + kineticEnergy(b.body, b.inertia);
    const SolverBody a0 = a.body, b0 = b.body;
    const auto outcome = resolveRigidImpact(a.body, b.body, contact, restitution, friction);
    ASSERT_TRUE(outcome.ok()) << outcome.error().message();
    if (outcome->approach_speed <= 0) continue;
    ++impacts;
    sliding += outcome->sticking ? 0 : 1;
    const RealL after = kineticEnergy(a.body, a.inertia) + kineticEnergy(b.body, b.inertia);
    const RealL gain = (after - before) / before;
    worst_gain = std::max(worst_gain, gain);
    ASSERT_LE(gain, 1e-12L) << "trial " << trial;
    ASSERT_GE(outcome->energy_lost, 0.0);
    ASSERT_NEAR(static_cast<double>(before - after), outcome->energy_lost,
                1e-12 * static_cast<double>(before))
        << "trial " << trial;
    ASSERT_LE(outcome->tangential_impulse.norm(),
              friction * outcome->normal_impulse * (1 + 1e-12) + 1e-300)
        << "trial " << trial;
    if (a.body.inertia_kind == InverseInertiaKind::kTensor ||
        b.body.inertia_kind == InverseInertiaKind::kTensor) {
      const Eigen::Vector3d n = contact.normal;
      const double after_normal =
          ((b.body.velocity + b.body.angular_velocity.cross(contact.lever_b)) -
           (a.body.velocity + a.body.angular_velocity.cross(contact.lever_a)))
              .dot(n);
      ASSERT_NEAR(after_normal, restitution * outcome->approach_speed,
                  1e-12 * (1 + b0.velocity.norm() + a0.velocity.norm() +
                           3 * (b0.angular_velocity.norm() + a0.angular_velocity.norm())))
          << "trial " << trial;
    }
    // L about the contact point of each body: m (-r) x v + I w, which the impulse there leaves.
    for (const auto& side : {std::tuple{&a.body, &a0, &a.inertia, contact.lever_a},
                             std::tuple{&b.body, &b0, &b.inertia, contact.lever_b}}) {
      // Named copies rather than a structured binding: the lambda below captures them (C++17,
      // and clang, allow no capture of a binding).
      const SolverBody* body = std::get<0>(side);
      const SolverBody* start = std::get<1>(side);
      const auto* inertia = std::get<2>(side);
      const Eigen::Vector3d lever = std::get<3>(side);
      if (body->inverse_mass == 0.0) continue;
      const double mass = 1.0 / body->inverse_mass;
      const auto momentum = [&](const SolverBody& s) -> Eigen::Vector3d {
        return mass * (-lever).cross(s.velocity) + *inertia * s.angular_velocity;
      };
      const double terms =
          mass * lever.norm() * (start->velocity.norm() + body->velocity.norm()) +
          inertia->norm() * (start->angular_velocity.norm() + body->angular_velocity.norm());
      const double drift = (momentum(*body) - momentum(*start)).norm();
      worst_momentum = std::max(worst_momentum, drift / (kEps * terms));
      ASSERT_LE(drift, 64 * kEps * terms) << "trial " << trial;
    }
  }
  EXPECT_GT(impacts, count / 3);
  EXPECT_GT(sliding, impacts / 10);
  EXPECT_LE(worst_gain, 1e-12L);
  std::printf(
      "%ld impacts, %ld sliding: the largest energy change %.3Lg of the energy before, "
      "angular momentum about the contact within %.3g eps of its terms\n",
      impacts, sliding, worst_gain, worst_momentum);
}

/// Today's answer for one contact of two balls, as the monitor's solveContact gives it:
/// resolveImpact, then applyFriction with the spin effect.
RigidImpactOutcome todaysBalls(SolverBody& a, SolverBody& b, const ContactPoint& contact,
                               double restitution, double friction) {
  RigidImpactOutcome outcome;
  const ImpactResponse<double> response = resolveImpact(a.inverse_mass, a.velocity, b.inverse_mass,
                                                        b.velocity, contact.normal, restitution);
  if (!response.approaching) return outcome;
  a.velocity = response.velocity_a;
  b.velocity = response.velocity_b;
  outcome.normal_impulse = response.normal_impulse;
  outcome.energy_lost = response.energy_lost;
  if (friction > 0) {
    outcome.energy_lost +=
        applyFriction<true>(a, b, contact, friction, response.normal_impulse).energy_lost;
  }
  return outcome;
}

SolverBody randomBall(std::mt19937_64& rng, bool immovable) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> symmetric(-1.0, 1.0);
  SolverBody ball;
  ball.velocity = Eigen::Vector3d(symmetric(rng), symmetric(rng), symmetric(rng));
  if (immovable) return ball;
  ball.inverse_mass = 1.0 / (0.1 + unit(rng));
  ball.radius = 0.01 + unit(rng);
  ball.spin_factor = unit(rng) < 0.5 ? 2.5 : 1.5;
  ball.angular_velocity = 5.0 * Eigen::Vector3d(symmetric(rng), symmetric(rng), symmetric(rng));
  return ball;
}

// Balls: resolveRigidImpact gives today's answer to the bit (it is today's code); the law
// written for any body (resolveRigidImpactByLaw) gives it to a few ulps (16 eps of the
// velocities' scale), sticking and sliding alike, over 10,000 random pairs (a third against an
// immovable ball or plane).
TEST(RigidImpact, BallsGiveTodaysAnswerBitForBitAndTheGeneralLawAgreesToAFewUlps) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int compared = 0;
  double worst = 0;  // the law's velocities against today's, in eps of the speeds
  for (int trial = 0; trial < 10000; ++trial) {
    SolverBody a = randomBall(rng, unit(rng) < 0.3);
    SolverBody b = randomBall(rng, false);
    ContactPoint contact =
        contactOf(randomRotation(rng).col(0), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    contact.lever_a = a.radius * contact.normal;
    contact.lever_b = -b.radius * contact.normal;
    const double restitution = unit(rng);
    const double friction = unit(rng) < 0.2 ? 0.0 : unit(rng);

    SolverBody today_a = a, today_b = b;
    const RigidImpactOutcome today = todaysBalls(today_a, today_b, contact, restitution, friction);
    SolverBody ours_a = a, ours_b = b;
    const auto ours = resolveRigidImpact(ours_a, ours_b, contact, restitution, friction);
    ASSERT_TRUE(ours.ok());
    for (int i = 0; i < 3; ++i) {
      ASSERT_EQ(ours_a.velocity[i], today_a.velocity[i]) << trial;
      ASSERT_EQ(ours_b.velocity[i], today_b.velocity[i]) << trial;
      ASSERT_EQ(ours_a.angular_velocity[i], today_a.angular_velocity[i]) << trial;
      ASSERT_EQ(ours_b.angular_velocity[i], today_b.angular_velocity[i]) << trial;
    }
    ASSERT_EQ(ours->normal_impulse, today.normal_impulse);
    ASSERT_EQ(ours->energy_lost, today.energy_lost);

    if (today.normal_impulse == 0) continue;  // not approaching
    ++compared;
    SolverBody law_a = a, law_b = b;
    const RigidImpactOutcome law =
        resolveRigidImpactByLaw(law_a, law_b, contact, restitution, friction, 0.0);
    const double speed = 1 + a.velocity.norm() + b.velocity.norm() +
                         a.radius * a.angular_velocity.norm() +
                         b.radius * b.angular_velocity.norm();
    for (int i = 0; i < 3; ++i) {
      worst = std::max({worst, std::abs(law_a.velocity[i] - today_a.velocity[i]) / (kEps * speed),
                        std::abs(law_b.velocity[i] - today_b.velocity[i]) / (kEps * speed)});
      ASSERT_NEAR(law_a.velocity[i], today_a.velocity[i], 16 * kEps * speed) << trial;
      ASSERT_NEAR(law_b.velocity[i], today_b.velocity[i], 16 * kEps * speed) << trial;
      if (a.inverse_mass > 0) {
        ASSERT_NEAR(law_a.radius * law_a.angular_velocity[i],
                    today_a.radius * today_a.angular_velocity[i], 16 * kEps * speed)
            << trial;
      }
      ASSERT_NEAR(law_b.radius * law_b.angular_velocity[i],
                  today_b.radius * today_b.angular_velocity[i], 16 * kEps * speed)
          << trial;
    }
    // The same closeness for the impulse: 16 eps of the speeds times the reduced mass (the
    // approach, the difference of the speeds, is known to eps of them, not of itself).
    ASSERT_NEAR(law.normal_impulse, today.normal_impulse,
                16 * kEps * speed / (a.inverse_mass + b.inverse_mass))
        << trial;
  }
  EXPECT_GT(compared, 3000);
  std::printf("%d ball impacts: the law's velocities within %.3g eps of the speeds of today's\n",
              compared, worst);
}

// The same impact of a cylinder (axisymmetric: I = diag(1, 1, 1/2) m r^2-like) on a floor, with
// friction, in 200 orientations of the whole problem (its tensor, lever arm, velocities and
// normal turned by R): the answer is R times the first, to 64 eps of its scale.
TEST(RigidImpact, ASymmetricBodyGivesTheSameAnswerInAnyOrientation) {
  const Eigen::Matrix3d inverse_inertia = Eigen::Vector3d(4.0, 4.0, 8.0).asDiagonal();
  const Eigen::Vector3d lever(0.25, 0.0, -0.5);  // a point of the bottom rim
  const Eigen::Vector3d velocity(0.3, 0.1, -2.0), spin(0.5, -1.0, 3.0);
  SolverBody floor = floorBody();
  SolverBody body = tensorBody(2.0, inverse_inertia, velocity, spin);
  const ContactPoint contact = contactOf(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::Zero(), lever);
  const auto first = resolveRigidImpact(floor, body, contact, 0.6, 0.3);
  ASSERT_TRUE(first.ok());
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d turn = randomRotation(rng);
    SolverBody turned_floor = floorBody();
    SolverBody turned =
        tensorBody(2.0, turn * inverse_inertia * turn.transpose(), turn * velocity, turn * spin);
    const ContactPoint turned_contact =
        contactOf(turn * contact.normal, Eigen::Vector3d::Zero(), turn * lever);
    const auto outcome = resolveRigidImpact(turned_floor, turned, turned_contact, 0.6, 0.3);
    ASSERT_TRUE(outcome.ok());
    EXPECT_EQ(outcome->sticking, first->sticking);
    expectNear(outcome->impulse, turn * first->impulse, first->impulse.norm(), 64, "impulse");
    expectNear(turned.velocity, turn * body.velocity, 3.0, 64, "v'");
    expectNear(turned.angular_velocity, turn * body.angular_velocity, 4.0, 64, "w'");
    EXPECT_NEAR(outcome->energy_lost, first->energy_lost, 64 * kEps * first->energy_lost);
  }
}

/// A box of edges (2a, 2b, 2c) and mass m, its four bottom corners on the floor (z = 0 below its
/// centre by c), in the order given.
struct FlatBox {
  std::vector<SolverBody> bodies;
  std::vector<ClusterContact> contacts;
};

FlatBox flatBox(double mass, const Eigen::Vector3d& half, const Eigen::Vector3d& velocity,
                double restitution) {
  FlatBox box;
  const Eigen::Vector3d moments = mass / 3.0 *
                                  Eigen::Vector3d(half.y() * half.y() + half.z() * half.z(),
                                                  half.x() * half.x() + half.z() * half.z(),
                                                  half.x() * half.x() + half.y() * half.y());
  box.bodies.push_back(floorBody());
  box.bodies.push_back(
      tensorBody(mass, moments.cwiseInverse().asDiagonal(), velocity, Eigen::Vector3d::Zero()));
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      ClusterContact contact;
      contact.a = 0;
      contact.b = 1;
      contact.normal = Eigen::Vector3d::UnitZ();
      contact.lever_b = Eigen::Vector3d(sx * half.x(), sy * half.y(), -half.z());
      contact.point = contact.lever_b;  // the box's centre at the origin
      contact.restitution = restitution;
      box.contacts.push_back(contact);
    }
  }
  return box;
}

// A box (1 x 2 x 3 m, 2 kg) landing flat at 3 m/s on its four bottom corners: e = 1 leaves at
// +3 m/s exactly, without spin; any e in [0, 1] leaves at 3 e m/s and loses (1/2) m (1 - e^2) v^2
// (the outcomes' sum and the states); all 24 orders of the corners give the same bits.
TEST(RigidImpact, ABoxLandingFlatOnFourCornersLeavesStraightAndLosesItsClosedForm) {
  const Eigen::Vector3d half(0.5, 1.0, 1.5);
  for (const double e : {1.0, 0.0, 0.25, 0.5, 0.75}) {
    FlatBox box = flatBox(2.0, half, Eigen::Vector3d(0, 0, -3.0), e);
    const auto outcome = resolveRigidSimultaneous(box.bodies, box.contacts);
    ASSERT_TRUE(outcome.ok()) << outcome.error().message();
    const SolverBody& landed = box.bodies[1];
    EXPECT_EQ(landed.velocity, Eigen::Vector3d(0, 0, 3.0 * e)) << "e " << e;
    EXPECT_EQ(landed.angular_velocity, Eigen::Vector3d::Zero()) << "e " << e;
    double lost = 0.0;
    for (const ContactOutcome& contact : *outcome) {
      EXPECT_EQ(contact.impulse, (1 + e) * 2.0 * 3.0 / 4) << "e " << e;
      lost += contact.energy_lost;
    }
    EXPECT_NEAR(lost, 0.5 * 2.0 * (1 - e * e) * 9.0, 4 * kEps * 9.0) << "e " << e;

    std::vector<std::size_t> order = {0, 1, 2, 3};
    while (std::next_permutation(order.begin(), order.end())) {
      FlatBox shuffled = flatBox(2.0, half, Eigen::Vector3d(0, 0, -3.0), e);
      std::vector<ClusterContact> contacts;
      for (const std::size_t k : order) contacts.push_back(shuffled.contacts[k]);
      const auto again = resolveRigidSimultaneous(shuffled.bodies, contacts);
      ASSERT_TRUE(again.ok());
      EXPECT_EQ(shuffled.bodies[1].velocity, landed.velocity);
      EXPECT_EQ(shuffled.bodies[1].angular_velocity, landed.angular_velocity);
    }
  }
}

/// The box's kinetic energy (its moments' inverse in `body`).
double kineticEnergy(const SolverBody& body) {
  const Eigen::Matrix3d inertia = body.inverse_inertia.inverse();
  return 0.5 * body.velocity.squaredNorm() / body.inverse_mass +
         0.5 * body.angular_velocity.dot(inertia * body.angular_velocity);
}

// The box (1 x 2 x 3 m, 2 kg, a = 0.5 ahead of its centre, c = 1.5 below it) landing flat at
// v_n = 3 m/s while sliding at u = 4 m/s along x, e = 1/2, by the joint law (Chatterjee and
// Ruina's over the four corners): P_I = m v_n / 4 = 1.5 N s at each corner; the sticking
// impulses that stop the box without turning it carry -m u / 4 = -2 N s along x each, and to
// hold the moment c m u of that friction about the centre, normal impulses m v_n / 4 + c m u x /
// (4 a^2) = 1.5 +- 6 N s (the front corners more); so D = (-2, 0, +-6) and, on the rear corners'
// cone kappa 2 = mu (2.25 - 6 kappa), kappa = 2.25 mu / (2 + 6 mu) (the front ones' is wider):
// 0.0865 at mu = 0.1, 0.28125 at mu = 1, 0.3629 at mu = 10 (the rear corners' normal impulse
// nearly spent: no flat landing this fast sticks). The box leaves at (u (1 - kappa), 0, e v_n)
// without turning (friction's moment is held by the corners' normal impulses, as a real box's
// shift forward: the two-stage rule before turned it over its front edge, w_y' = c mu J / I), each
// corner's normal impulse 2.25 +- 6 kappa and friction 2 kappa, the energy lost
// (1 - e^2) m v_n^2 / 2 + kappa (2 - kappa) m u^2 / 2; all 24 orders of the corners give the same
// bits.
TEST(RigidImpact, ABoxLandingFlatWhileSlidingTakesTheJointLawsFrictionWithoutTurning) {
  const Eigen::Vector3d half(0.5, 1.0, 1.5);
  const double m = 2.0, e = 0.5, v_n = 3.0, u = 4.0;
  for (const double mu : {0.1, 1.0, 10.0}) {
    SCOPED_TRACE("mu " + std::to_string(mu));
    const double kappa = 2.25 * mu / (2 + 6 * mu);
    FlatBox box = flatBox(m, half, Eigen::Vector3d(u, 0, -v_n), e);
    const double before = kineticEnergy(box.bodies[1]);
    const auto outcome = resolveRigidSimultaneous(box.bodies, box.contacts, {mu, mu, mu, mu});
    ASSERT_TRUE(outcome.ok()) << outcome.error().message();
    const SolverBody& landed = box.bodies[1];
    EXPECT_NEAR((landed.velocity - Eigen::Vector3d(u * (1 - kappa), 0, e * v_n)).norm(), 0.0,
                16 * kEps * u);
    EXPECT_NEAR(landed.angular_velocity.norm(), 0.0, 16 * kEps * u);
    double lost = 0.0;
    for (std::size_t k = 0; k < 4; ++k) {
      const FrictionalOutcome& corner = (*outcome)[k];
      const double ahead = box.contacts[k].lever_b.x() > 0 ? 1.0 : -1.0;
      EXPECT_NEAR(corner.normal.impulse, 2.25 + ahead * 6 * kappa, 64 * kEps * 9);
      EXPECT_NEAR(corner.friction_impulse, 2 * kappa, 64 * kEps * 9);
      EXPECT_LE(corner.friction_impulse, mu * corner.normal.impulse * (1 + 1e-12));
      lost += corner.normal.energy_lost + corner.friction_energy_lost;
    }
    const double closed = 0.5 * (1 - e * e) * m * v_n * v_n + 0.5 * kappa * (2 - kappa) * m * u * u;
    EXPECT_NEAR(lost, closed, 64 * kEps * before);
    EXPECT_NEAR(before - kineticEnergy(landed), closed, 64 * kEps * before);
    std::vector<std::size_t> order = {0, 1, 2, 3};
    while (std::next_permutation(order.begin(), order.end())) {
      FlatBox shuffled = flatBox(m, half, Eigen::Vector3d(u, 0, -v_n), e);
      std::vector<ClusterContact> contacts;
      for (const std::size_t k : order) contacts.push_back(shuffled.contacts[k]);
      ASSERT_TRUE(resolveRigidSimultaneous(shuffled.bodies, contacts, {mu, mu, mu, mu}).ok());
      EXPECT_EQ(shuffled.bodies[1].velocity, landed.velocity);
      EXPECT_EQ(shuffled.bodies[1].angular_velocity, landed.angular_velocity);
    }
  }
}

// One contact struck alone: the joint law is Chatterjee and Ruina's (resolveRigidImpactByLaw),
// to 1e-12 of the speeds (that law's n.K.n is rounded to doubles first), over 2,000 random
// bodies, lever arms, normals, e and mu.
TEST(RigidImpact, TheJointLawOnOneContactIsChatterjeeAndRuinas) {
  std::mt19937_64 random(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto vector = [&](double scale) -> Eigen::Vector3d {
    return Eigen::Vector3d(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5) * scale;
  };
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Vector3d half = Eigen::Vector3d(0.1, 0.1, 0.1) + vector(1.0).cwiseAbs();
    FlatBox box = flatBox(0.1 + 5 * unit(random), half, vector(4.0), unit(random));
    box.bodies[1].angular_velocity = vector(4.0);
    ClusterContact contact = box.contacts[0];
    contact.normal = (Eigen::Vector3d::UnitZ() + vector(1.0)).normalized();
    contact.lever_b = vector(2.0);
    const double mu = 2 * unit(random);
    std::vector<SolverBody> law = box.bodies;
    const RigidImpactOutcome single =
        resolveRigidImpactByLaw(law[0], law[1], contact, contact.restitution, mu, 0.0);
    std::vector<SolverBody> joint = box.bodies;
    const auto outcome = resolveRigidSimultaneous(joint, {contact}, {mu});
    ASSERT_TRUE(outcome.ok()) << outcome.error().message();
    const double scale = box.bodies[1].velocity.norm() +
                         box.bodies[1].angular_velocity.norm() * contact.lever_b.norm() + 1;
    EXPECT_NEAR((joint[1].velocity - law[1].velocity).norm(), 0.0, 1e-12 * scale) << trial;
    EXPECT_NEAR(
        (joint[1].angular_velocity - law[1].angular_velocity).norm() * contact.lever_b.norm(), 0.0,
        1e-12 * scale)
        << trial;
    EXPECT_NEAR((*outcome)[0].normal.impulse, single.normal_impulse,
                1e-12 * (single.impulse.norm() + 1e-300))
        << trial;
  }
}

// 2,000 random boxes (edges 0.1 to 2 m, masses, tilts, slides and spins) landing on their four
// bottom corners with e in [0, 1] and mu in [0, 2] (every 4th with each corner's own mu, some 0):
// the joint law never adds energy (1e-12 of the energy before), no corner pulled, each corner's
// friction within its cone (mu_k J_k), every corner that approached and is pressed leaving, the
// energies lost adding up to the change.
TEST(RigidImpact, RandomFrictionalFlatLandingsNeverGainEnergy) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int frictionless = 0;  // landings the law leaves to the frictionless joint rule
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Vector3d half = Eigen::Vector3d(0.05, 0.05, 0.05) +
                                 0.95 * Eigen::Vector3d(unit(random), unit(random), unit(random));
    const Eigen::Vector3d velocity(4 * unit(random) - 2, 4 * unit(random) - 2,
                                   -0.1 - 3 * unit(random));
    FlatBox box = flatBox(0.1 + 5 * unit(random), half, velocity, unit(random));
    box.bodies[1].angular_velocity =
        Eigen::Vector3d(unit(random) - 0.5, unit(random) - 0.5, 4 * unit(random) - 2);
    // One mu for the four corners, or (every 4th landing) each its own, some 0.
    const double mu = 2 * unit(random);
    std::vector<double> mus(4, mu);
    if (trial % 4 == 3) {
      for (double& corner_mu : mus) corner_mu = unit(random) < 0.3 ? 0.0 : 2 * unit(random);
    }
    const double before = kineticEnergy(box.bodies[1]);
    const auto outcome = resolveRigidSimultaneous(box.bodies, box.contacts, mus);
    if (!outcome.ok()) {
      ADD_FAILURE() << trial << ": " << outcome.error().message();
      continue;
    }
    const double after = kineticEnergy(box.bodies[1]);
    EXPECT_LE(after, before * (1 + 1e-12)) << trial;
    bool frictional = false;
    for (std::size_t k = 0; k < 4; ++k) {
      const ClusterContact& corner = box.contacts[k];
      const SolverBody& landed = box.bodies[1];
      const double leaving =
          (landed.velocity + landed.angular_velocity.cross(corner.lever_b)).dot(corner.normal);
      if ((*outcome)[k].normal.impulse > 0 && (*outcome)[k].normal.approach_speed > 0) {
        EXPECT_GE(leaving, -1e-12 * velocity.norm()) << trial;
      }
      frictional = frictional || (*outcome)[k].friction_impulse > 0;
    }
    if (trial % 4 != 3 && mu > 0 && !frictional) ++frictionless;
    double lost = 0.0;
    for (std::size_t k = 0; k < 4; ++k) {
      const FrictionalOutcome& corner = (*outcome)[k];
      EXPECT_GE(corner.normal.impulse, 0.0) << trial;
      EXPECT_LE(corner.friction_impulse, mus[k] * corner.normal.impulse * (1 + 1e-12) + 1e-300)
          << trial;
      lost += corner.normal.energy_lost + corner.friction_energy_lost;
    }
    EXPECT_NEAR(lost, before - after, 1e-12 * before) << trial;
  }
  // A corner the frictionless joint rule leaves apart but D would press (the rule's active set
  // is Newton's, not a complementarity solve's): there the law gives the frictionless rule.
  std::printf("frictionless joint rule in %d of 2000 landings\n", frictionless);
  EXPECT_LT(frictionless, 400);
}

// The same box landing flat while drifting and turning about z (the floor frictionless, the
// corners approaching alike): only the normal velocity changes, v_z' = -e v_z; in any order of
// the corners, the same bits; and on a floor turned by a rotation R (the whole problem turned)
// the answer is R times the first, to 16 eps, each corner receiving (1 + e) m v / 4.
TEST(RigidImpact, ABoxLandingFlatIsIndependentOfTheCornersOrderAndOfTheFloorsOrientation) {
  const Eigen::Vector3d half(0.5, 1.0, 1.5);
  FlatBox box = flatBox(2.0, half, Eigen::Vector3d(0.25, -0.5, -3.0), 0.5);
  box.bodies[1].angular_velocity = Eigen::Vector3d(0, 0, 0.75);
  const std::vector<SolverBody> start = box.bodies;
  const auto outcome = resolveRigidSimultaneous(box.bodies, box.contacts);
  ASSERT_TRUE(outcome.ok());
  EXPECT_EQ(box.bodies[1].velocity, Eigen::Vector3d(0.25, -0.5, 1.5));
  EXPECT_EQ(box.bodies[1].angular_velocity, Eigen::Vector3d(0, 0, 0.75));

  std::vector<std::size_t> order = {3, 1, 0, 2};
  std::vector<ClusterContact> contacts;
  for (const std::size_t k : order) contacts.push_back(box.contacts[k]);
  std::vector<SolverBody> bodies = start;
  ASSERT_TRUE(resolveRigidSimultaneous(bodies, contacts).ok());
  EXPECT_EQ(bodies[1].velocity, box.bodies[1].velocity);
  EXPECT_EQ(bodies[1].angular_velocity, box.bodies[1].angular_velocity);

  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Matrix3d turn = randomRotation(rng);
    std::vector<SolverBody> turned = start;
    turned[1].velocity = turn * start[1].velocity;
    turned[1].angular_velocity = turn * start[1].angular_velocity;
    turned[1].inverse_inertia = turn * start[1].inverse_inertia * turn.transpose();
    std::vector<ClusterContact> turned_contacts = box.contacts;
    for (std::size_t k = 0; k < turned_contacts.size(); ++k) {
      ClusterContact& contact = turned_contacts[k];
      // Each corner's normal as a narrow phase gives it: the floor's, to its own rounding
      // (a few 1e-16 apart from corner to corner).
      contact.normal =
          (turn * contact.normal + 4e-16 * static_cast<double>(k) * turn * Eigen::Vector3d::UnitX())
              .normalized();
      contact.lever_b = turn * contact.lever_b;
      contact.point = turn * contact.point;
    }
    const auto turned_outcome = resolveRigidSimultaneous(turned, turned_contacts);
    ASSERT_TRUE(turned_outcome.ok());
    expectNear(turned[1].velocity, turn * box.bodies[1].velocity, 3.0, 16, "v'");
    expectNear(turned[1].angular_velocity, turn * box.bodies[1].angular_velocity, 1.0, 16, "w'");
    // The corners, whose normals differ by their rounding only, share the impulse evenly:
    // (1 + e) m v / 4 = 2.25 N s each (redundant contacts found as such, not solved as a
    // near-singular system).
    for (const ContactOutcome& corner : *turned_outcome) {
      EXPECT_NEAR(corner.impulse, 2.25, 1e-12) << "trial " << trial;
    }
  }
}

// A box (edges 2a = 1, 2b = 2, 2c = 3 m, 2 kg) tilted about x by theta (sin 3/5, cos 4/5) lands
// on its bottom edge along x (two corners), falling at 2 m/s, e = 1/2: by symmetry the same as
// one contact at the edge's middle, lever r = R (0, -b, -c): P = (1 + e) v / (1/m + (r x n).
// I^-1 (r x n)) with I^-1 turned about x, r x n = (r_y, -r_x, 0) = (r_y, 0, 0), so
// P = 3 / (1/2 + r_y^2 / I_xx), I_xx = m (b^2 + c^2) / 3 = 13/6, r_y = -(4/5) 1 + (3/5) 3/2 =
// 1/10: P = 3 / (1/2 + 3/650) = 975/164 N s, v_z' = -2 + P / m = 319/328 m/s,
// w_x' = r_y P / I_xx = (1/10)(975/164)(6/13) = 45/164 rad/s (the edge then leaves at
// 319/328 + w_x' r_y = 1 m/s = e 2 m/s).
TEST(RigidImpact, ABoxLandingOnAnEdgeIsItsClosedForm) {
  const double mass = 2.0;
  const Eigen::Vector3d half(0.5, 1.0, 1.5);
  Eigen::Matrix3d turn;
  turn << 1, 0, 0, 0, 0.8, -0.6, 0, 0.6, 0.8;
  const Eigen::Vector3d moments = mass / 3.0 *
                                  Eigen::Vector3d(half.y() * half.y() + half.z() * half.z(),
                                                  half.x() * half.x() + half.z() * half.z(),
                                                  half.x() * half.x() + half.y() * half.y());
  std::vector<SolverBody> bodies = {
      floorBody(), tensorBody(mass, turn * moments.cwiseInverse().asDiagonal() * turn.transpose(),
                              Eigen::Vector3d(0, 0, -2.0), Eigen::Vector3d::Zero())};
  std::vector<ClusterContact> contacts;
  for (const double sx : {1.0, -1.0}) {
    ClusterContact contact;
    contact.a = 0;
    contact.b = 1;
    contact.normal = Eigen::Vector3d::UnitZ();
    contact.lever_b = turn * Eigen::Vector3d(sx * half.x(), -half.y(), -half.z());
    contact.point = contact.lever_b;
    contact.restitution = 0.5;
    contacts.push_back(contact);
  }
  const auto outcome = resolveRigidSimultaneous(bodies, contacts);
  ASSERT_TRUE(outcome.ok()) << outcome.error().message();
  EXPECT_NEAR((*outcome)[0].impulse + (*outcome)[1].impulse, 975.0 / 164, 16 * kEps * 6);
  EXPECT_EQ((*outcome)[0].impulse, (*outcome)[1].impulse);
  expectNear(bodies[1].velocity, Eigen::Vector3d(0, 0, 319.0 / 328), 2.0, 16, "v'");
  expectNear(bodies[1].angular_velocity, Eigen::Vector3d(45.0 / 164, 0, 0), 1.0, 16, "w'");
}

// Balls only: resolveRigidSimultaneous is resolveSimultaneous, bit for bit (three balls in a row,
// the middle one struck from both sides).
TEST(RigidImpact, SimultaneousBallsAreTodaysJointSolveBitForBit) {
  std::vector<SolverBody> bodies(3);
  for (std::size_t i = 0; i < 3; ++i) {
    bodies[i].inverse_mass = 1.0 / (1.0 + 0.5 * static_cast<double>(i));
    bodies[i].radius = 0.5;
    bodies[i].spin_factor = 2.5;
  }
  bodies[0].velocity = Eigen::Vector3d(1.0, 0.1, 0.0);
  bodies[2].velocity = Eigen::Vector3d(-2.0, 0.0, 0.3);
  std::vector<ClusterContact> contacts(2);
  for (std::size_t k = 0; k < 2; ++k) {
    contacts[k].a = k;
    contacts[k].b = k + 1;
    contacts[k].normal = Eigen::Vector3d::UnitX();
    contacts[k].lever_a = 0.5 * Eigen::Vector3d::UnitX();
    contacts[k].lever_b = -0.5 * Eigen::Vector3d::UnitX();
    contacts[k].restitution = 0.3 + 0.4 * static_cast<double>(k);
  }
  std::vector<SolverBody> today = bodies;
  const std::vector<ContactOutcome> expected = resolveSimultaneous(today, contacts);
  const auto ours = resolveRigidSimultaneous(bodies, contacts);
  ASSERT_TRUE(ours.ok());
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(bodies[i].velocity, today[i].velocity);
  for (std::size_t k = 0; k < 2; ++k) EXPECT_EQ((*ours)[k].impulse, expected[k].impulse);
}

// Bad input, each named by its field, the bodies untouched.
// A lever arm along the normal (a sphere given a tensor, r = R n) turns nothing: the impact is
// Newton's j = (1 + e) m d whatever the tensor. With I far below m R^2 (R = 5e6 m, I = 3.9e-8
// kg m^2: R^2 / I ~ 6e20 against 1/m = 0.1), n.K.n taken from the matrix K lost w to the
// cancellation of its rotational entries (~eps 6e20 = 1e5) and gave a negative impulse,
// -1.05e7 N s, gaining energy; (r x n).I^-1 (r x n) itself is ~1e-11 (effective_mass.h).
TEST(RigidImpact, ALeverArmAlongTheNormalWithATinyInertiaIsNewtonsImpulse) {
  const Eigen::Vector3d n = Eigen::Vector3d(2, 3, 6) / 7;
  SolverBody wall;  // immovable
  wall.inertia_kind = InverseInertiaKind::kTensor;
  SolverBody ball;
  ball.inverse_mass = 0.1;
  ball.inertia_kind = InverseInertiaKind::kTensor;
  ball.inverse_inertia = Eigen::Matrix3d::Identity() / 3.9e-8;
  ball.velocity = -1.36e11 * n;
  ContactPoint contact;
  contact.normal = n;
  contact.lever_a = Eigen::Vector3d(1e5, -2e5, 3e5);
  contact.lever_b = -5e6 * n;
  for (const double mu : {0.0, 0.4}) {
    SolverBody a = wall, b = ball;
    const auto outcome = resolveRigidImpact(a, b, contact, 0.127, mu);
    ASSERT_TRUE(outcome.ok()) << outcome.error().message();
    const double newton = (1 + 0.127) * 1.36e11 / 0.1;
    EXPECT_NEAR(outcome->normal_impulse, newton, 1e-12 * newton) << mu;
    EXPECT_GE(outcome->energy_lost, 0.0) << mu;
    EXPECT_NEAR(b.velocity.dot(n), 0.127 * 1.36e11, 1e-12 * 1.36e11) << mu;
  }
}

TEST(RigidImpact, BadInputIsRefusedByName) {
  const SolverBody box = tensorBody(1.0, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, -1),
                                    Eigen::Vector3d::Zero());
  const ContactPoint contact =
      contactOf(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::Zero(), Eigen::Vector3d(0.5, 0.5, -0.5));
  const auto refused = [&](SolverBody a, SolverBody b, ContactPoint c, double e, double mu,
                           double et = 0.0) {
    const SolverBody b0 = b;
    const auto outcome = resolveRigidImpact(a, b, c, e, mu, et);
    EXPECT_EQ(b.velocity, b0.velocity);
    return outcome.ok() ? std::string("accepted") : outcome.error().field;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(refused(floorBody(), box, contact, 1.5, 0.0), "restitution");
  EXPECT_EQ(refused(floorBody(), box, contact, -0.1, 0.0), "restitution");
  EXPECT_EQ(refused(floorBody(), box, contact, nan, 0.0), "restitution");
  EXPECT_EQ(refused(floorBody(), box, contact, 0.5, -1.0), "friction");
  EXPECT_EQ(refused(floorBody(), box, contact, 0.5, inf), "friction");
  EXPECT_EQ(refused(floorBody(), box, contact, 0.5, 0.5, 1.5), "tangential_restitution");
  ContactPoint bad = contact;
  bad.lever_b.y() = nan;
  EXPECT_EQ(refused(floorBody(), box, bad, 0.5, 0.5), "contact.lever_b.y");
  bad = contact;
  bad.lever_a.x() = inf;
  EXPECT_EQ(refused(floorBody(), box, bad, 0.5, 0.5), "contact.lever_a.x");
  bad = contact;
  bad.normal = Eigen::Vector3d(0, 0, 2);
  EXPECT_EQ(refused(floorBody(), box, bad, 0.5, 0.5), "contact.normal");
  SolverBody wrong = box;
  wrong.inverse_inertia(0, 1) = nan;
  EXPECT_EQ(refused(floorBody(), wrong, contact, 0.5, 0.5), "b.inverse_inertia(0, 1)");
  wrong = box;
  wrong.inverse_inertia(2, 2) = -1.0;
  EXPECT_EQ(refused(floorBody(), wrong, contact, 0.5, 0.5), "b.inverse_inertia(2, 2)");
  wrong = box;
  wrong.inverse_mass = -1.0;
  EXPECT_EQ(refused(floorBody(), wrong, contact, 0.5, 0.5), "b.inverse_mass");
  wrong = box;
  wrong.angular_velocity.z() = inf;
  EXPECT_EQ(refused(floorBody(), wrong, contact, 0.5, 0.5), "b.angular_velocity.z");
  wrong = box;
  wrong.inverse_mass = 0.0;
  EXPECT_EQ(refused(floorBody(), wrong, contact, 0.5, 0.5), "b.inverse_mass");  // both immovable
  SolverBody ball = floorBody();
  ball.spin_factor = -2.5;
  EXPECT_EQ(refused(ball, box, contact, 0.5, 0.5), "a.spin_factor");

  FlatBox flat = flatBox(1.0, Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(0, 0, -1), 0.5);
  flat.contacts[2].restitution = 2.0;
  auto outcome = resolveRigidSimultaneous(flat.bodies, flat.contacts);
  ASSERT_FALSE(outcome.ok());
  EXPECT_EQ(outcome.error().field, "contacts[2].restitution");
  EXPECT_EQ(flat.bodies[1].velocity, Eigen::Vector3d(0, 0, -1));
  flat.contacts[2].restitution = 0.5;
  flat.contacts[1].b = 7;
  outcome = resolveRigidSimultaneous(flat.bodies, flat.contacts);
  ASSERT_FALSE(outcome.ok());
  EXPECT_EQ(outcome.error().field, "contacts[1].b");
  flat.contacts[1].b = 1;
  flat.bodies[1].velocity.x() = nan;
  outcome = resolveRigidSimultaneous(flat.bodies, flat.contacts);
  ASSERT_FALSE(outcome.ok());
  EXPECT_EQ(outcome.error().field, "bodies[1].velocity.x");
}

}  // namespace
}  // namespace collision_response::core

namespace collision_response::core {
namespace {

// Extreme but representable: a box of 1e-50 kg at 1e100 m/s against one of 1e50 kg, lever arms
// of 1e-50 m to 1e50 m: a finite answer that gains no energy (relative 1e-12). A lever arm
// so long that K passes the doubles (|r|^2 / I ~ 1e320): refused as beyond the doubles, by name,
// the bodies untouched, never a NaN.
TEST(RigidImpact, ExtremeScalesGiveAFiniteAnswerOrANamedRefusal) {
  for (const double scale : {1e-50, 1e-20, 1.0, 1e20, 1e50}) {
    const double mass_a = 1e50, mass_b = 1e-50;
    SolverBody a = tensorBody(mass_a, Eigen::Matrix3d::Identity() / (mass_a * scale * scale),
                              Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    SolverBody b =
        tensorBody(mass_b, Eigen::Vector3d(1, 2, 3).asDiagonal() * (1.0 / (mass_b * scale * scale)),
                   Eigen::Vector3d(0.3, 0.2, -1) * 1e100, Eigen::Vector3d(1, -1, 2));
    const ContactPoint contact = contactOf(Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 0, scale),
                                           Eigen::Vector3d(0.5, 0.25, -1) * scale);
    const Eigen::Matrix3d inertia_a = Eigen::Matrix3d::Identity() * (mass_a * scale * scale);
    const Eigen::Matrix3d inertia_b =
        Eigen::Vector3d(1.0, 0.5, 1.0 / 3).asDiagonal() * (mass_b * scale * scale);
    const RealL before = kineticEnergy(a, inertia_a) + kineticEnergy(b, inertia_b);
    const auto outcome = resolveRigidImpact(a, b, contact, 0.7, 0.4);
    ASSERT_TRUE(outcome.ok()) << outcome.error().message();
    EXPECT_TRUE(b.velocity.allFinite() && b.angular_velocity.allFinite()) << scale;
    EXPECT_TRUE(a.velocity.allFinite() && a.angular_velocity.allFinite()) << scale;
    const RealL after = kineticEnergy(a, inertia_a) + kineticEnergy(b, inertia_b);
    EXPECT_LE(static_cast<double>((after - before) / before), 1e-12) << scale;
    EXPECT_GT(outcome->energy_lost, 0.0) << scale;
  }
  SolverBody floor = floorBody();
  SolverBody box = tensorBody(1.0, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, -1),
                              Eigen::Vector3d::Zero());
  const ContactPoint far =
      contactOf(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::Zero(), Eigen::Vector3d(1e160, 0, -1));
  const auto refused = resolveRigidImpact(floor, box, far, 0.5, 0.5);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().field, "b.velocity");
  EXPECT_EQ(box.velocity, Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(box.angular_velocity, Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace collision_response::core

namespace collision_response::core {
namespace {

// 20,000 boxes (random edges 0.02 to 20 m, masses, orientations, speeds) landing flat, e = 1/2:
// each corner receives (1 + e) m v / 4 to 1e-9 and the box leaves at e v without spin. Four
// contacts with one normal make A singular; its computed pivots are not exactly 0, and with long
// double's default rank threshold (4e-19 n of the largest pivot) 1 box in ~7,000 was solved as
// full rank, its impulses wild along A's null direction (the velocities right, the impulses and
// their energy shares not).
TEST(RigidImpact, RandomBoxesLandingFlatShareTheImpulseEvenly) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.01, 10.0);
  for (int trial = 0; trial < 20000; ++trial) {
    const Eigen::Vector3d half(unit(rng), unit(rng), unit(rng));
    const double mass = unit(rng);
    const Eigen::Matrix3d turn = randomRotation(rng);
    const double speed = unit(rng);
    FlatBox box = flatBox(mass, half, Eigen::Vector3d(0, 0, -speed), 0.5);
    SolverBody& body = box.bodies[1];
    body.inverse_inertia = turn * body.inverse_inertia * turn.transpose();
    body.velocity = turn * body.velocity;
    for (ClusterContact& contact : box.contacts) {
      contact.normal = turn.col(2);
      contact.lever_b = turn * contact.lever_b;
      contact.point = contact.lever_b;
    }
    const auto outcome = resolveRigidSimultaneous(box.bodies, box.contacts);
    ASSERT_TRUE(outcome.ok());
    const double each = 1.5 * mass * speed / 4;
    for (const ContactOutcome& corner : *outcome) {
      ASSERT_NEAR(corner.impulse, each, 1e-9 * each) << "trial " << trial;
    }
    expectNear(turn.transpose() * body.velocity, Eigen::Vector3d(0, 0, 0.5 * speed), speed, 64,
               "v'");
    EXPECT_LE(body.angular_velocity.norm(), 1e-12 * speed / half.minCoeff()) << trial;
  }
}

}  // namespace
}  // namespace collision_response::core
