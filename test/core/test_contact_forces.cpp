// Contact forces of lasting contact against the closed forms of statics and of a ball on an
// incline (each expected value derived in the comment above its test).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "solver/contact_forces.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
constexpr double kG = 9.81;
const V kGravity(0, 0, -kG);

ForceBody ball(double mass, double radius, bool spin = false) {
  ForceBody body;
  body.inverse_mass = 1.0 / mass;
  body.radius = radius;
  body.spin_factor = spin ? 2.5 : 0.0;
  body.acceleration = kGravity;
  return body;
}

ForceBody fixed() { return ForceBody{}; }

/// A ball resting on a plane with outward normal `up` (the contact's normal points from the
/// ball into the plane).
ForceContact onPlane(std::size_t ball_index, std::size_t plane_index, const V& up,
                     double friction = 0.0) {
  ForceContact contact;
  contact.a = ball_index;
  contact.b = plane_index;
  contact.normal = -up.normalized();
  contact.friction = friction;
  return contact;
}

/// b resting on a (two spheres), the normal from a's centre to b's.
ForceContact sphereOnSphere(std::size_t a, std::size_t b, const V& from_a_to_b, double distance,
                            double friction = 0.0) {
  ForceContact contact;
  contact.a = a;
  contact.b = b;
  contact.normal = from_a_to_b.normalized();
  contact.curvature = 1.0 / distance;
  contact.friction = friction;
  return contact;
}

// An incline at theta descending towards +x: outward normal (sin t, 0, cos t). Without
// friction the plane pushes with N = m g cos t and the ball slides down at g sin t, along
// (cos t, 0, -sin t).
TEST(ContactForces, FrictionlessInclineSlidesAtGSinTheta) {
  const double theta = 10.0 * M_PI / 180.0, m = 0.2;
  const V up(std::sin(theta), 0, std::cos(theta)), down(std::cos(theta), 0, -std::sin(theta));
  const auto solution = solveContactForces({ball(m, 0.05), fixed()}, {onPlane(0, 1, up)});
  ASSERT_TRUE(solution.converged);
  EXPECT_NEAR(solution.contacts[0].normal, m * kG * std::cos(theta), 1e-13);
  EXPECT_EQ(solution.contacts[0].mode, ContactMode::kSliding);
  EXPECT_NEAR((solution.acceleration[0] - kG * std::sin(theta) * down).norm(), 0.0, 1e-14);
}

// With spin and enough friction a solid ball rolls: m a = m g sin t - f, f r = I alpha,
// a = alpha r, I = 2/5 m r^2, so a = 5/7 g sin t and f = 2/7 m g sin t (needs mu >= 2/7 tan t).
TEST(ContactForces, SolidBallRollsAtFiveSevenths) {
  const double theta = 20.0 * M_PI / 180.0, m = 0.3, r = 0.04;
  const V up(std::sin(theta), 0, std::cos(theta)), down(std::cos(theta), 0, -std::sin(theta));
  const auto solution = solveContactForces({ball(m, r, true), fixed()}, {onPlane(0, 1, up, 0.5)});
  ASSERT_TRUE(solution.converged);
  EXPECT_EQ(solution.contacts[0].mode, ContactMode::kSticking);
  EXPECT_NEAR((solution.acceleration[0] - 5.0 / 7.0 * kG * std::sin(theta) * down).norm(), 0.0,
              1e-13);
  EXPECT_NEAR(solution.contacts[0].tangential.norm(), 2.0 / 7.0 * m * kG * std::sin(theta), 1e-13);
  // It turns about the axis down x up = -y... rolling: alpha = a / r about (up x down).
  EXPECT_NEAR(
      (solution.angular_acceleration[0] - 5.0 / 7.0 * kG * std::sin(theta) / r * up.cross(down))
          .norm(),
      0.0, 1e-11);
  EXPECT_NEAR(solution.contacts[0].slip_acceleration.norm(), 0.0, 1e-13);
}

// Too little friction for rolling (mu < 2/7 tan t): the ball slides and spins up; friction is
// mu N = mu m g cos t, so a = g (sin t - mu cos t).
TEST(ContactForces, SolidBallSlidesWhenFrictionIsShort) {
  const double theta = 40.0 * M_PI / 180.0, m = 0.3, r = 0.04, mu = 0.1;
  ASSERT_LT(mu, 2.0 / 7.0 * std::tan(theta));
  const V up(std::sin(theta), 0, std::cos(theta)), down(std::cos(theta), 0, -std::sin(theta));
  const auto solution = solveContactForces({ball(m, r, true), fixed()}, {onPlane(0, 1, up, mu)});
  ASSERT_TRUE(solution.converged);
  EXPECT_EQ(solution.contacts[0].mode, ContactMode::kSliding);
  EXPECT_NEAR(
      (solution.acceleration[0] - kG * (std::sin(theta) - mu * std::cos(theta)) * down).norm(), 0.0,
      1e-13);
  EXPECT_NEAR(solution.contacts[0].tangential.norm(), mu * m * kG * std::cos(theta), 1e-13);
}

// Without spin a ball is a block: below the friction angle (tan t <= mu) static friction holds
// it (a = 0, friction m g sin t up the slope); above it, it slides at g (sin t - mu cos t).
TEST(ContactForces, RoughInclineHoldsBelowTheFrictionAngle) {
  const double theta = 20.0 * M_PI / 180.0, m = 0.3;
  const V up(std::sin(theta), 0, std::cos(theta)), down(std::cos(theta), 0, -std::sin(theta));
  const double holds = std::tan(theta) * 1.01, slips = std::tan(theta) * 0.99;
  const auto held = solveContactForces({ball(m, 0.04), fixed()}, {onPlane(0, 1, up, holds)});
  ASSERT_TRUE(held.converged);
  EXPECT_EQ(held.contacts[0].mode, ContactMode::kSticking);
  EXPECT_NEAR(held.acceleration[0].norm(), 0.0, 1e-14);
  EXPECT_NEAR(held.contacts[0].tangential.norm(), m * kG * std::sin(theta), 1e-13);
  const auto slid = solveContactForces({ball(m, 0.04), fixed()}, {onPlane(0, 1, up, slips)});
  ASSERT_TRUE(slid.converged);
  EXPECT_EQ(slid.contacts[0].mode, ContactMode::kSliding);
  EXPECT_NEAR(
      (slid.acceleration[0] - kG * (std::sin(theta) - slips * std::cos(theta)) * down).norm(), 0.0,
      1e-13);
}

// Sliding up the incline at speed v, friction and gravity both pull down the slope:
// a = -g (sin t + mu cos t) along the motion.
TEST(ContactForces, SlidingUpDecelerates) {
  const double theta = 15.0 * M_PI / 180.0, m = 0.3, mu = 0.4;
  const V up(std::sin(theta), 0, std::cos(theta)), down(std::cos(theta), 0, -std::sin(theta));
  ForceBody body = ball(m, 0.04);
  body.velocity = -2.0 * down;
  const auto solution = solveContactForces({body, fixed()}, {onPlane(0, 1, up, mu)});
  ASSERT_TRUE(solution.converged);
  EXPECT_EQ(solution.contacts[0].mode, ContactMode::kSliding);
  EXPECT_NEAR(
      (solution.acceleration[0] - kG * (std::sin(theta) + mu * std::cos(theta)) * down).norm(), 0.0,
      1e-13);
}

// The corner of the incline and a wall facing up-slope (normal -x): the incline holds
// N_i cos t = m g, the wall N_w = N_i sin t, so N_i = m g / cos t and N_w = m g tan t.
TEST(ContactForces, CornerOfAnInclineAndAWall) {
  const double theta = 10.0 * M_PI / 180.0, m = 0.2;
  const V up(std::sin(theta), 0, std::cos(theta));
  const auto solution = solveContactForces({ball(m, 0.05), fixed(), fixed()},
                                           {onPlane(0, 1, up), onPlane(0, 2, V(-1, 0, 0))});
  ASSERT_TRUE(solution.converged);
  EXPECT_NEAR(solution.contacts[0].normal, m * kG / std::cos(theta), 1e-13);
  EXPECT_NEAR(solution.contacts[1].normal, m * kG * std::tan(theta), 1e-13);
  EXPECT_NEAR(solution.acceleration[0].norm(), 0.0, 1e-14);
}

// The same corner with friction (mu = 1) and a solid ball (spin), at rest: both contacts stick.
// Statics leaves the forces indeterminate: six components (N and a tangential force at each
// contact) against the net force and torque (-r n_i x T_i - r n_w x T_w; the normal forces pass
// through the centre), six conditions of which five are independent: in the plane of the
// normals, the torque gives both frictions one magnitude t (opposite moments), and the net force
// two equations for N_i, N_w and t. A one-parameter family whose members all give the same
// accelerations, 0. Determined: no contact pulls, the contacts' forces on the ball sum to
// its weight, and the ball stays (acceleration, angular acceleration 0). The solver takes the
// least static friction (doc/model.md, "Lasting contact"): the frictionless N = m g / cos t
// and m g tan t with no friction lie in the family, so that is the answer. (The family's
// minimum-norm member, friction 0.288 N at each contact, has the wall pull: N_w = -0.17 N.)
TEST(ContactForces, RoughCornerWithSpinHoldsWithoutPulling) {
  const double theta = 10.0 * M_PI / 180.0, m = 0.1, mu = 1.0;
  const V up(std::sin(theta), 0, std::cos(theta)), wall(-1, 0, 0);
  const auto solution = solveContactForces({ball(m, 0.05, true), fixed(), fixed()},
                                           {onPlane(0, 1, up, mu), onPlane(0, 2, wall, mu)});
  ASSERT_TRUE(solution.converged);
  V on_ball = V::Zero();
  for (std::size_t k = 0; k < 2; ++k) {
    const ContactForce& force = solution.contacts[k];
    EXPECT_EQ(force.mode, ContactMode::kSticking) << k;
    EXPECT_GE(force.normal, 0.0) << k;
    EXPECT_LE(force.tangential.norm(), mu * force.normal) << k;
    on_ball -= force.normal * -(k == 0 ? up : wall) + force.tangential;
  }
  EXPECT_LT((on_ball - V(0, 0, m * kG)).norm(), 1e-13);
  EXPECT_EQ(solution.acceleration[0].norm(), 0.0);
  EXPECT_EQ(solution.angular_acceleration[0].norm(), 0.0);
  EXPECT_NEAR(solution.contacts[0].normal, m * kG / std::cos(theta), 1e-13);
  EXPECT_NEAR(solution.contacts[1].normal, m * kG * std::tan(theta), 1e-13);
  EXPECT_LT(solution.contacts[0].tangential.norm() + solution.contacts[1].tangential.norm(), 1e-13);
}

// A V-groove of two planes tilted by b either way: by symmetry N = m g / (2 cos b) each.
TEST(ContactForces, VGrooveSharesTheWeight) {
  const double b = 35.0 * M_PI / 180.0, m = 0.2;
  const auto solution = solveContactForces({ball(m, 0.05), fixed(), fixed()},
                                           {onPlane(0, 1, V(std::sin(b), 0, std::cos(b))),
                                            onPlane(0, 2, V(-std::sin(b), 0, std::cos(b)))});
  ASSERT_TRUE(solution.converged);
  EXPECT_NEAR(solution.contacts[0].normal, m * kG / (2 * std::cos(b)), 1e-13);
  EXPECT_EQ(solution.contacts[0].normal, solution.contacts[1].normal) << "mirror images";
  EXPECT_NEAR(solution.acceleration[0].norm(), 0.0, 1e-14);
}

// A centred stack on the floor: each contact carries the weight of what is above it.
TEST(ContactForces, StackOfThreeCarriesTheWeightsAbove) {
  const double m1 = 0.3, m2 = 0.2, m3 = 0.1, r = 0.05;
  const auto solution =
      solveContactForces({ball(m1, r), ball(m2, r), ball(m3, r), fixed()},
                         {onPlane(0, 3, V(0, 0, 1)), sphereOnSphere(0, 1, V(0, 0, 1), 2 * r),
                          sphereOnSphere(1, 2, V(0, 0, 1), 2 * r)});
  ASSERT_TRUE(solution.converged);
  EXPECT_NEAR(solution.contacts[0].normal, (m1 + m2 + m3) * kG, 1e-13);
  EXPECT_NEAR(solution.contacts[1].normal, (m2 + m3) * kG, 1e-13);
  EXPECT_NEAR(solution.contacts[2].normal, m3 * kG, 1e-13);
  for (const V& a : solution.acceleration) EXPECT_NEAR(a.norm(), 0.0, 1e-14);
}

// A pyramid between walls: two balls on the floor, each against a wall, apart by 2 c (c = 1.2 r:
// they do not touch), and one on top touching both. Its contacts lean by phi, sin phi = c / 2r
// = 0.6: 2 N cos phi = m_t g, N = m_t g / 1.6; each wall holds N sin phi = 0.375 m_t g; the floor
// carries m_b g + m_t g / 2 under each.
TEST(ContactForces, PyramidBetweenWallsFromStatics) {
  const double r = 0.05, c = 1.2 * r, mb = 0.3, mt = 0.2;
  const double height = std::sqrt(4 * r * r - c * c);
  const auto solution = solveContactForces(
      {ball(mb, r), ball(mb, r), ball(mt, r), fixed(), fixed(), fixed()},
      {onPlane(0, 3, V(0, 0, 1)), onPlane(1, 3, V(0, 0, 1)), onPlane(0, 4, V(1, 0, 0)),
       onPlane(1, 5, V(-1, 0, 0)), sphereOnSphere(0, 2, V(c, 0, height), 2 * r),
       sphereOnSphere(1, 2, V(-c, 0, height), 2 * r)});
  ASSERT_TRUE(solution.converged);
  EXPECT_NEAR(solution.contacts[0].normal, mb * kG + mt * kG / 2, 1e-13);
  EXPECT_NEAR(solution.contacts[2].normal, 0.375 * mt * kG, 1e-13);
  EXPECT_NEAR(solution.contacts[4].normal, mt * kG / 1.6, 1e-13);
  EXPECT_EQ(solution.contacts[4].normal, solution.contacts[5].normal) << "mirror images";
  for (const V& a : solution.acceleration) EXPECT_NEAR(a.norm(), 0.0, 1e-14);
}

// A ball at angle t from the top of a fixed sphere, moving at v across it: the sphere pushes
// with N = m (g cos t - v^2 / d), d the distance of the centres; at N = 0 it lets go.
TEST(ContactForces, BallOnASphereFeelsTheCentripetalTerm) {
  const double t = 0.6, m = 0.1, d = 1.1, v = 1.5;
  const V out(std::sin(t), 0, std::cos(t)), across(std::cos(t), 0, -std::sin(t));
  ForceBody body = ball(m, 0.1);
  body.velocity = v * across;
  const auto solution = solveContactForces({fixed(), body}, {sphereOnSphere(0, 1, out, d)});
  ASSERT_TRUE(solution.converged);
  EXPECT_NEAR(solution.contacts[0].normal, m * (kG * std::cos(t) - v * v / d), 1e-13);
  // Faster than sqrt(g d cos t) it flies off: no force, and the gap opens.
  body.velocity = 1.01 * std::sqrt(kG * d * std::cos(t)) * across;
  const auto flying = solveContactForces({fixed(), body}, {sphereOnSphere(0, 1, out, d)});
  EXPECT_EQ(flying.contacts[0].mode, ContactMode::kSeparating);
  EXPECT_EQ(flying.contacts[0].normal, 0.0);
  EXPECT_GT(flying.contacts[0].gap_acceleration, 0.0);
}

// A ball lying on the floor beside another: the contact between them is touching but carries
// no force, and nobody moves.
TEST(ContactForces, NeighboursOnTheFloorDoNotPush) {
  const double r = 0.05;
  const auto solution = solveContactForces({ball(0.1, r), ball(0.1, r), fixed()},
                                           {onPlane(0, 2, V(0, 0, 1)), onPlane(1, 2, V(0, 0, 1)),
                                            sphereOnSphere(0, 1, V(1, 0, 0), 2 * r)});
  ASSERT_TRUE(solution.converged);
  EXPECT_EQ(solution.contacts[2].normal, 0.0);
  EXPECT_NEAR(solution.contacts[0].normal, 0.1 * kG, 1e-14);
  for (const V& a : solution.acceleration) EXPECT_NEAR(a.norm(), 0.0, 1e-14);
}

// A stack of four spinning balls on the floor, mu = 1, as a settling pile left it (the state of
// the accuracy benchmark's 100-ball pile with friction and spin at 0.16038 s, from a scratch
// run): the modes with friction do not settle within the iterations, and the clamped forces of
// the last ones let the lowest pair's gap accelerate inwards at 10.7 m/s^2, so the second ball
// fell into the first. Whatever the modes, no contact may close: every gap's acceleration
// >= 0, every normal force >= 0 and acting only where its gap's acceleration is 0 (Signorini),
// friction within mu N. Where friction is dropped for that, the forces are frictionless.
TEST(ContactForces, ModesThatDoNotSettleNeverLetAContactClose) {
  const auto spinning = [](const V& velocity, const V& angular_velocity) {
    ForceBody body = ball(0.1, 0.05, true);
    body.velocity = velocity;
    body.angular_velocity = angular_velocity;
    return body;
  };
  const std::vector<ForceBody> bodies = {
      spinning(V(0.044762405218542377, -0.080892871575880265, 1.6543612251060553e-24),
               V(1.6185085401118049, 0.89538097350635726, 0.071608816666484137)),
      spinning(V(0.056644020240107687, -0.18881575339716106, -0.012445228497498914),
               V(0.55472097180446323, -0.66479566473065455, 0.0027065368604605633)),
      spinning(V(-0.0298994493229825, -0.035882843883892179, -0.032868289102743441),
               V(-3.6300235399649905, -1.0848381886989065, -0.072532504687676372)),
      spinning(V(-0.033573244459426402, 0.071443530758402068, -0.032415461999101162),
               V(1.4830534159523281, 1.0116778187418722, -0.0036302248816528822)),
      fixed()};
  const std::vector<ForceContact> contacts = {
      sphereOnSphere(0, 1, V(0.015897147741110024, -0.11281492503935889, 0.99348883908278562), 0.1,
                     1.0),
      onPlane(0, 4, V(0, 0, 1), 1.0),
      sphereOnSphere(1, 2, V(-0.055069760320623412, 0.10148590585543582, 0.99331159885049691), 0.1,
                     1.0),
      sphereOnSphere(2, 3, V(0.0053991003203204824, -0.0040342518931435478, 0.99997728700575683),
                     0.1, 1.0)};
  ContactForceSettings settings;
  settings.slip_tolerance = 1e-6;
  const ContactForceSolution solution = solveContactForces(bodies, contacts, settings);
  EXPECT_TRUE(solution.converged || solution.friction_dropped);
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const ContactForce& force = solution.contacts[k];
    EXPECT_GE(force.gap_acceleration, -1e-12 * kG) << "contact " << k;
    EXPECT_GE(force.normal, 0.0) << "contact " << k;
    EXPECT_LE(force.normal * force.gap_acceleration, 1e-12 * 0.4 * kG * kG) << "contact " << k;
    const double mu = solution.friction_dropped ? 0.0 : contacts[k].friction;
    EXPECT_LE(force.tangential.norm(), mu * force.normal * (1 + 1e-12) + 1e-12 * 0.1 * kG)
        << "contact " << k;
  }
}

}  // namespace
}  // namespace collision_response::core
