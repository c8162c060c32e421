// A box or a can over a table top's edge (contact/shaped_edge_tip.h, and lastingOnFace's support
// cut by the edge), against closed forms worked in the comments: the slide on until the centre
// of pressure reaches the edge, the cut support's forces by the least-norm rule, a cube at rest
// past the edge turning about it as a pendulum (the energy integral) until its friction cone
// gives (the angle where |F| = mu N, solved here in long double), a frictionless slide off the
// edge keeping its energy, and what is refused by name. No point of the body is ever inside the
// table.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "contact/shaped_edge_tip.h"
#include "contact/shaped_lasting.h"
#include "lasting_bodies.h"

namespace collision_response::core {
namespace {

using namespace lasting_bodies;  // NOLINT(google-build-using-namespace): the tests' bodies

/// The table top: z = 0.7, x in [-1, 1] (its edge at x = 1), y in [-0.5, 0.5].
FlatFace tableTop(double mu) {
  FlatFace table = plane(V::UnitZ(), mu);
  table.point = V(0, 0, 0.7);
  table.bounded = true;
  table.half_extent = Eigen::Vector2d(1, 0.5);
  return table;
}

/// How far the body's deepest point is inside the table (x < 1 and z < 0.7), over its corners
/// (a box) or 64 points of each rim (a cylinder): > 0 inside.
double insideTable(const LastingBody& body, const LastingMotion& motion, double t) {
  const Eigen::Matrix3d r = motion.orientationAt(t).toRotationMatrix();
  const V c = motion.centreAt(t);
  double deepest = -1.0;
  const auto at = [&](const V& local) {
    const V p = c + r * local;
    deepest = std::max(deepest, std::min(1 - p.x(), 0.7 - p.z()));
  };
  if (const auto* cuboid = std::get_if<Cuboid>(&body.shape)) {
    for (int i = 0; i < 8; ++i) {
      at(V((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1).cwiseProduct(cuboid->half_size));
    }
  } else if (const auto* can = std::get_if<Cylinder>(&body.shape)) {
    for (int i = 0; i < 64; ++i) {
      const double a = 2 * M_PI * i / 64;
      for (const double z : {-can->half_length, can->half_length}) {
        at(V(can->radius * std::cos(a), can->radius * std::sin(a), z));
      }
    }
  }
  return deepest;
}

/// Over [start, until] at 401 instants: never inside the table (beyond 1e-12 m), never gaining
/// energy (beyond `tolerance` of m g reach + kinetic), every normal force >= 0.
void expectSound(const LastingBody& body, const LastingMotion& motion, double tolerance) {
  const double scale = body.mass * (kG * reachOf(body.shape) + body.velocity.squaredNorm());
  const double start = energy(body, motion, motion.start);
  for (int k = 0; k <= 400; ++k) {
    const double t = motion.start + (motion.until - motion.start) * k / 400.0;
    EXPECT_LE(insideTable(body, motion, t), 1e-12) << "at t = " << t;
    EXPECT_LE(energy(body, motion, t), start + tolerance * scale) << "at t = " << t;
    for (const SupportForce& force : motion.forcesAt(t)) EXPECT_GE(force.normal_force, 0.0);
  }
}

TEST(ShapedEdgeTip, ABoxSlidingOverTheEdgeSlidesOnUntilItsCentreOfPressureReachesIt) {
  // A 0.2 m cube of 1 kg, frictionless, its foot 0.05 m from the edge at 1 m/s: it slides on
  // for 0.05 s. At 0.02 s the support is the cube's face from x = 0.87 to the edge (L = 0.13,
  // centroid 0.935) with the centre of pressure at 0.97: the least-norm rule gives each front
  // point m g (1/4 + 0.035 / (2 L)), each back one m g (1/4 - 0.035 / (2 L)).
  LastingBody cube = box(V(0.1, 0.1, 0.1), 1, V(0.95, 0, 0.8));
  cube.velocity = V(1, 0, 0);
  const FlatFace table = tableTop(0);
  const auto slides = lastingOnFace(cube, table);
  ASSERT_TRUE(slides.ok()) << errorOf(slides);
  EXPECT_EQ(slides->state, ContactState::kSliding);
  EXPECT_EQ(slides->ends, "stops");
  EXPECT_NEAR(slides->until, 0.05, 1e-15);
  const auto forces = slides->forcesAt(0.02);
  ASSERT_EQ(forces.size(), 4u);
  double total = 0;
  for (const SupportForce& force : forces) {
    total += force.normal_force;
    const bool front = force.point.x() > 0.99;
    if (front) {
      EXPECT_NEAR(force.point.x(), 1.0, 1e-15);
    }
    EXPECT_NEAR(force.normal_force, kG * (0.25 + (front ? 1 : -1) * 0.035 / 0.26), 1e-12);
  }
  EXPECT_NEAR(total, kG, 1e-12);
  expectSound(cube, *slides, 1e-12);

  // Asked again there, its centre over the edge, it tips over it and leaves it, frictionless:
  // the energy kept to the integration's tolerance, never inside the table, its speed along
  // the edge's out never falling (the edge's force N u has no part against it).
  cube.time = slides->until;
  cube.centre = slides->centreAt(slides->until);
  const auto tips = lastingOnFace(cube, table);
  ASSERT_TRUE(tips.ok()) << errorOf(tips);
  ASSERT_TRUE(tips->pivot);
  EXPECT_EQ(tips->ends, "resumes");
  EXPECT_GT(tips->until, tips->start);
  expectSound(cube, *tips, 1e-8);
  for (int k = 1; k <= 100; ++k) {
    const double t0 = tips->start + (tips->until - tips->start) * (k - 1) / 100.0;
    const double t1 = tips->start + (tips->until - tips->start) * k / 100.0;
    EXPECT_GE(tips->velocityAt(t1).x(), tips->velocityAt(t0).x() - 1e-9);
    for (const SupportForce& force : tips->forcesAt(t1)) {
      EXPECT_NEAR(force.point.x(), 1.0, 1e-15);
      EXPECT_NEAR(force.point.z(), 0.7, 1e-15);
    }
  }
  // Where it resumes, the cube is clear of the edge (kPivotClearance, 1e-5, of its reach): the
  // edge's point in the cube's frame, its distance from the square section.
  const Eigen::Matrix3d r = tips->orientationAt(tips->until).toRotationMatrix();
  const V p = r.transpose() * (V(1, 0, 0.7) - tips->centreAt(tips->until));
  const double dx = std::max(std::abs(p.x()) - 0.1, 0.0), dz = std::max(std::abs(p.z()) - 0.1, 0.0);
  EXPECT_GE(std::hypot(dx, dz), 1e-5 * std::sqrt(0.03));
}

TEST(ShapedEdgeTip, ACubeAtRestPastTheEdgeTurnsAboutItAsAPendulumUntilItsFrictionGives) {
  // A 0.1 m cube of 1 kg (h = 0.05, I = m a^2 / 6 = 1/600), its centre s = 0.01 past the edge,
  // mu = 1. Sticking, it turns about the edge: I_E = I + m (s^2 + h^2), and with rho^2 = s^2 +
  // h^2, tan beta = s / h, the energy integral I_E phi'^2 / 2 = m g rho (cos beta - cos(phi +
  // beta)), phi'' = m g rho sin(phi + beta) / I_E; the edge's force N = m (g cos phi - h phi'^2
  // - s phi''), F = m (h phi'' - s phi'^2 - g sin phi). It slips where |F| = mu N first.
  const double m = 1, h = 0.05, s = 0.01, mu = 1;
  LastingBody cube = box(V(h, h, h), m, V(1 + s, 0, 0.7 + h));
  const FlatFace table = tableTop(mu);
  const auto tips = lastingOnFace(cube, table);
  ASSERT_TRUE(tips.ok()) << errorOf(tips);
  ASSERT_TRUE(tips->pivot);
  EXPECT_EQ(tips->state, ContactState::kRolling);  // sticking
  const long double I = m * (2 * h * h) * 4 / 12.0L, I_E = I + m * (s * s + h * h);
  const long double rho = std::sqrt(static_cast<long double>(s * s + h * h));
  const long double beta = std::atan2(static_cast<long double>(s), static_cast<long double>(h));
  const long double g = kG;
  const auto rate2 = [&](long double phi) {
    return 2 * m * g * rho * (std::cos(beta) - std::cos(phi + beta)) / I_E;
  };
  const auto slack = [&](long double phi) {  // mu N - |F|
    const long double pd2 = rate2(phi), pdd = m * g * rho * std::sin(phi + beta) / I_E;
    const long double N = m * (g * std::cos(phi) - h * pd2 - s * pdd);
    const long double F = m * (h * pdd - s * pd2 - g * std::sin(phi));
    return mu * N - std::abs(F);
  };
  long double lo = 0, hi = 0;
  while (slack(hi) > 0) lo = hi, hi += 1e-3L;
  for (int i = 0; i < 200; ++i) {
    const long double mid = (lo + hi) / 2;
    (slack(mid) > 0 ? lo : hi) = mid;
  }
  const double onset = static_cast<double>(lo);
  // The instant it starts to slip: the first not sticking, by bisection on the path.
  double before = tips->start, after = tips->until;
  ASSERT_EQ(tips->stateAt(after), ContactState::kSliding);
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (before + after);
    (tips->stateAt(mid) == ContactState::kRolling ? before : after) = mid;
  }
  const auto angle = [&](double t) {
    return Eigen::AngleAxisd(tips->orientationAt(t) * cube.orientation.conjugate()).angle();
  };
  EXPECT_NEAR(angle(before), onset, 1e-7);
  // Before it, the energy integral and the centre's distance from the edge (rho: the edge holds).
  for (int k = 1; k <= 50; ++k) {
    const double t = tips->start + (before - tips->start) * k / 50.0;
    const double phi = angle(t);
    const double rate = tips->angularVelocityAt(t).norm();
    EXPECT_NEAR(rate * rate, static_cast<double>(rate2(phi)),
                1e-8 * static_cast<double>(rate2(onset)))
        << t;
    EXPECT_NEAR((tips->centreAt(t) - V(1, 0, 0.7)).norm(), static_cast<double>(rho), 1e-10);
    EXPECT_GT(tips->angularVelocityAt(t).y(), 0.0);  // over the edge, about +y
  }
  expectSound(cube, *tips, 1e-8);
  EXPECT_EQ(tips->ends, "resumes");

  // Given halfway (as a tracker sees it: turned over the edge, its face below the table's plane
  // past the edge), the motion goes on from there: the energy integral and rho again, and the
  // same slip onset.
  LastingBody halfway = cube;
  halfway.time = 0.5 * (tips->start + before);
  halfway.centre = tips->centreAt(halfway.time);
  halfway.velocity = tips->velocityAt(halfway.time);
  halfway.angular_velocity = tips->angularVelocityAt(halfway.time);
  halfway.orientation = tips->orientationAt(halfway.time);
  const auto goes_on = lastingOnFace(halfway, table);
  ASSERT_TRUE(goes_on.ok()) << errorOf(goes_on);
  ASSERT_TRUE(goes_on->pivot);
  const auto turned = [&](double t) {
    return Eigen::AngleAxisd(goes_on->orientationAt(t) * cube.orientation.conjugate()).angle();
  };
  for (int k = 0; k <= 20; ++k) {
    const double t = halfway.time + (before - halfway.time) * k / 21.0;
    const double rate = goes_on->angularVelocityAt(t).norm();
    EXPECT_NEAR(rate * rate, static_cast<double>(rate2(turned(t))),
                1e-8 * static_cast<double>(rate2(onset)))
        << t;
    EXPECT_NEAR((goes_on->centreAt(t) - V(1, 0, 0.7)).norm(), static_cast<double>(rho), 1e-10);
  }
  double again = halfway.time, later = goes_on->until;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (again + later);
    (goes_on->stateAt(mid) == ContactState::kRolling ? again : later) = mid;
  }
  EXPECT_NEAR(turned(again), onset, 1e-7);
}

TEST(ShapedEdgeTip, ACanSlidingOffTheEdgeTipsOverItAndKeepsItsEnergyFrictionless) {
  // A can (r 0.033 m, 0.12 m tall, 0.35 kg) standing on its cap, frictionless, its centre at
  // the edge at 0.5 m/s: the cap's segment on the table, then the turn over the edge's chord.
  LastingBody can =
      cylinder(0.033, 0.06, 0.35, 0.35 * 0.033 * 0.033 / 2, V(0.98, 0.1, 0.76), Q::Identity());
  can.velocity = V(0.5, 0, 0);
  const FlatFace table = tableTop(0);
  const auto slides = lastingOnFace(can, table);
  ASSERT_TRUE(slides.ok()) << errorOf(slides);
  EXPECT_EQ(slides->ends, "stops");
  EXPECT_NEAR(slides->until, 0.04, 1e-15);
  // The segment's forces: the chord's ends and the rim's point on the ray through the centre
  // of pressure, carrying m g, none < 0, the centre of pressure their mean.
  const auto forces = slides->forcesAt(0.02);
  ASSERT_EQ(forces.size(), 3u);
  V moment = V::Zero();
  double total = 0;
  for (const SupportForce& force : forces) {
    total += force.normal_force;
    moment += force.normal_force * force.point;
  }
  EXPECT_NEAR(total, 0.35 * kG, 1e-12);
  EXPECT_NEAR((moment / total - V(0.99, 0.1, 0.7)).norm(), 0.0, 1e-12);
  can.time = slides->until;
  can.centre = slides->centreAt(slides->until);
  const auto tips = lastingOnFace(can, table);
  ASSERT_TRUE(tips.ok()) << errorOf(tips);
  EXPECT_EQ(tips->ends, "resumes");
  expectSound(can, *tips, 1e-8);
  // Energy kept both ways (frictionless): within the integration's tolerance.
  const double start = energy(can, *tips, tips->start), end = energy(can, *tips, tips->until);
  EXPECT_NEAR(end, start, 1e-8 * 0.35 * kG * 0.07);
}

TEST(ShapedEdgeTip, WhatIsNotModelledIsRefusedByName) {
  const FlatFace table = tableTop(0.3);
  const auto refused = [](const Expected<LastingMotion>& motion, const std::string& what) {
    ASSERT_FALSE(motion.ok());
    EXPECT_NE(motion.error().reason.find(what), std::string::npos) << motion.error().message();
  };
  // Sliding off at an angle to the edge (along it too).
  LastingBody cube = box(V(0.05, 0.05, 0.05), 1, V(1.0, 0, 0.75));
  cube.velocity = V(0.5, 0.2, 0);
  refused(lastingOnFace(cube, table), "not yet: sliding off the face's edge along it too");
  const FlatFace smooth = tableTop(0);
  refused(lastingOnFace(cube, smooth), "not yet: sliding off the face's edge along it too");
  // Over the table's corner.
  cube.velocity = V(0.5, 0, 0);
  cube.centre = V(0.99, 0.49, 0.75);
  refused(lastingOnFace(cube, table), "not yet: the body overhangs two of the face's edges");
  // A box with three different sides turned about z: the edge's line is not a principal axis.
  LastingBody block =
      box(V(0.1, 0.05, 0.03), 1, V(1.0, 0, 0.73), Q(Eigen::AngleAxisd(0.3, V::UnitZ())));
  refused(lastingOnFace(block, smooth), "not yet: tipping over the face's edge about an axis");
  // A can on its side, its end just at the edge (within the band), rests: a side over the edge
  // is refused only once it is past it.
  LastingBody lying =
      cylinder(0.033, 0.06, 0.35, 0.35 * 0.033 * 0.033 / 2, V(1.0 - 0.06 + 5e-10, 0, 0.733),
               Q(Eigen::AngleAxisd(M_PI / 2, V::UnitY())));
  const auto rests = lastingOnFace(lying, table);
  ASSERT_TRUE(rests.ok()) << errorOf(rests);
  EXPECT_EQ(rests->state, ContactState::kResting);
  lying.centre.x() += 1e-6;
  refused(lastingOnFace(lying, table), "not yet: the body overhangs the face's edge");
}

}  // namespace
}  // namespace collision_response::core
