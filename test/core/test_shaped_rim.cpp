// A cylinder leaning on its rim and a capsule on one end (contact/shaped_pivot.h, pivotOnRound),
// against what holds exactly whatever the integrator: the physical pendulum's energy integral
// about a sticking rim point and the instant its cap lands flat; a frictionless rim or end whose
// centre falls straight down, its side landing at the instant the energy integral gives; random
// cans and capsules rolling and sliding on a rim or an end, whose energy a sticking or frictionless
// contact keeps and a sliding one never raises; a can on its cap that tips over its rim where
// its centre of pressure leaves the cap; a can spinning on its cap, whose four rim points'
// friction stops it at w0 r / (2 mu g) (spinOnCap). Each instant is the test's own quadrature of
// dtheta / theta' (5-point Gauss-Legendre, 400 panels), never the code's.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <random>

#include "contact/shaped_lasting.h"
#include "contact/shaped_pivot.h"
#include "lasting_bodies.h"
#include "quadrature.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using Q = Eigen::Quaterniond;

using lasting_bodies::energy;
using lasting_bodies::kG;

/// A solid cylinder of radius r and half length h (axis z), its centre and motion set by the
/// caller.
LastingBody cylinder(double r, double h, double m) {
  return lasting_bodies::cylinder(r, h, m, m * r * r / 2, V::Zero(), Q::Identity());
}

FlatFace floorOf(double mu) { return lasting_bodies::plane(V::UnitZ(), mu); }

/// The body's lowest height at t: a rim's lowest point is its centre's height less
/// r sqrt(1 - a_z^2) (a its axis), an end's its centre's less r.
double lowestAt(const LastingBody& body, const LastingMotion& motion, double t) {
  const V a = motion.orientationAt(t) * V::UnitZ();
  const V c = motion.centreAt(t);
  double lowest = INFINITY;
  if (const auto* can = std::get_if<Cylinder>(&body.shape)) {
    for (const double side : {-1.0, 1.0}) {
      lowest = std::min(lowest, (c + side * can->half_length * a).z() -
                                    can->radius * std::sqrt(std::max(0.0, 1 - a.z() * a.z())));
    }
  } else {
    const auto& capsule = std::get<Capsule>(body.shape);
    for (const double side : {-1.0, 1.0}) {
      lowest = std::min(lowest, (c + side * capsule.half_length * a).z() - capsule.radius);
    }
  }
  return lowest;
}

/// The integral of dtheta / rate(theta) from theta0 to theta1 (rate > 0 over it).
double instant(const std::function<double(double)>& rate, double theta0, double theta1) {
  return std::abs(
      quadrature::gaussLegendre([&](double q) { return 1 / rate(q); }, theta0, theta1, 400));
}

/// Over [start, until] at 201 instants: no point below the floor (1e-12 m), the energy never
/// above the start's by `gain` of the scale m g reach + the kinetic energy, and, where `kept`,
/// never below it by that either; every normal force >= 0 and every friction within mu of it
/// (the events' resolution: 1e-12 and 1e-9 of m g).
void expectSound(const LastingBody& body, const FlatFace& face, const LastingMotion& motion,
                 double gain, bool kept) {
  const double reach = 0.2;
  const double start = energy(body, motion, motion.start);
  const double scale =
      body.mass * kG * reach + start - body.mass * kG * motion.centreAt(motion.start).z();
  for (int k = 0; k <= 200; ++k) {
    const double t = motion.start + (motion.until - motion.start) * k / 200.0;
    EXPECT_GE(lowestAt(body, motion, t), -1e-12) << "at t = " << t;
    const double now = energy(body, motion, t);
    EXPECT_LE(now, start + gain * scale) << "at t = " << t;
    if (kept) {
      EXPECT_GE(now, start - gain * scale) << "at t = " << t;
    }
    for (const SupportForce& force : motion.forcesAt(t)) {
      EXPECT_GE(force.normal_force, -1e-12 * body.mass * kG) << "at t = " << t;
      EXPECT_LE(force.friction_force.norm(),
                face.friction * force.normal_force + 1e-9 * body.mass * kG)
          << "at t = " << t;
    }
  }
}

/// A can (r, h) turned by `tilt` about x, its rim's point at -y (body) on the floor at the
/// origin: that point is -(0, cos, sin) r from the cap's centre, so the centre is at
/// (0, r cos - h sin, r sin + h cos); turning at `rate` about x, its rim's point still.
LastingBody leaning(double r, double h, double m, double tilt, double rate) {
  LastingBody body = cylinder(r, h, m);
  body.orientation = Q(Eigen::AngleAxisd(tilt, V::UnitX()));
  body.centre =
      V(0, r * std::cos(tilt) - h * std::sin(tilt), r * std::sin(tilt) + h * std::cos(tilt));
  body.angular_velocity = V(rate, 0, 0);
  body.velocity = body.angular_velocity.cross(body.centre);
  return body;
}

}  // namespace

TEST(ShapedRim, ACanLeaningOnAStickingRimFallsBackOntoItsCapAtThePendulumsInstant) {
  // r = 0.05, h = 0.1 (0.2 m tall), 1 kg, tilted 0.3 rad and turning back at 0.5 rad/s, mu = 5
  // (it sticks). Its centre is l = sqrt(r^2 + h^2) from the rim's point, psi = atan(r / h) -
  // theta from the vertical; about the rim's point (I_x + m l^2) psi'^2 / 2 + m g l cos psi is
  // kept, and the cap lands flat at psi = atan(r / h), the integral of dpsi / psi' later. Its
  // centre stays on the circle of radius l about the point (1e-9 m), psi' is the integral's at
  // the psi its centre shows (1e-8 rad/s), the point touching stays where it was (1e-9 m).
  const double r = 0.05, h = 0.1, m = 1.0, tilt = 0.3, rate0 = 0.5;
  const LastingBody body = leaning(r, h, m, tilt, -rate0);
  const FlatFace floor = floorOf(5.0);
  const auto motion = lastingOnFace(body, floor, 1e-11);
  ASSERT_TRUE(motion.ok()) << motion.error().message();
  ASSERT_TRUE(motion->pivot);
  EXPECT_EQ(motion->ends, "resumes");
  const double l = std::hypot(r, h), pivot = body.moments.x() + m * l * l;
  const double psi0 = std::atan2(r, h) - tilt;
  const auto psiRate = [&](double psi) {
    return std::sqrt(rate0 * rate0 + 2 * m * kG * l * (std::cos(psi0) - std::cos(psi)) / pivot);
  };
  EXPECT_NEAR(motion->until - motion->start, instant(psiRate, psi0, std::atan2(r, h)), 1e-9);
  EXPECT_NEAR((motion->orientationAt(motion->until) * V::UnitZ()).z(), 1.0, 1e-12) << "flat";
  for (int k = 0; k <= 50; ++k) {
    const double t = motion->start + (motion->until - motion->start) * k / 50.0;
    const V c = motion->centreAt(t);
    EXPECT_NEAR(c.norm(), l, 1e-9) << t;
    EXPECT_NEAR(c.x(), 0.0, 1e-12) << t;
    const double psi = std::atan2(c.y(), c.z());
    EXPECT_NEAR(-motion->angularVelocityAt(t).x(), psiRate(psi), 1e-8) << t;
    const auto forces = motion->forcesAt(t);
    ASSERT_EQ(forces.size(), 1u) << t;
    EXPECT_LE(forces[0].point.norm(), 1e-9) << t;
    EXPECT_EQ(motion->stateAt(t), ContactState::kRolling) << t;
  }
  expectSound(body, floor, *motion, 1e-9, true);
}

TEST(ShapedRim, AFrictionlessRimSlidesItsCentreFallingStraightDownUntilTheSideLands) {
  // The same can tilted 0.6 rad (past atan(r / h) = 0.4636: it falls outwards) turning on at
  // 0.5 rad/s, frictionless: no force along the floor, so its centre's x and y are kept, and its
  // height z = r sin theta + h cos theta. Kept: m z'^2 theta'^2 / 2 + I_x theta'^2 / 2 + m g z;
  // its side lands (the other rim's lowest point reaches the floor) at theta = pi/2, the
  // integral of dtheta / theta' later.
  const double r = 0.05, h = 0.1, m = 1.0, tilt = 0.6, rate0 = 0.5;
  LastingBody body = leaning(r, h, m, tilt, rate0);
  // Its centre moving straight down: z' theta', its rim's point sliding along y.
  body.velocity = V(0, 0, (r * std::cos(tilt) - h * std::sin(tilt)) * rate0);
  const FlatFace floor = floorOf(0.0);
  const auto motion = lastingOnFace(body, floor, 1e-11);
  ASSERT_TRUE(motion.ok()) << motion.error().message();
  ASSERT_TRUE(motion->pivot);
  EXPECT_EQ(motion->ends, "resumes");
  const double ix = body.moments.x();
  const auto z = [&](double q) { return r * std::sin(q) + h * std::cos(q); };
  const auto dz = [&](double q) { return r * std::cos(q) - h * std::sin(q); };
  const auto rate = [&](double q) {
    const double kinetic = 0.5 * (m * dz(tilt) * dz(tilt) + ix) * rate0 * rate0;
    return std::sqrt(2 * (kinetic + m * kG * (z(tilt) - z(q))) / (m * dz(q) * dz(q) + ix));
  };
  EXPECT_NEAR(motion->until - motion->start, instant(rate, tilt, M_PI / 2), 1e-9);
  EXPECT_NEAR((motion->orientationAt(motion->until) * V::UnitZ()).z(), 0.0, 1e-9) << "on its side";
  for (int k = 0; k <= 50; ++k) {
    const double t = motion->start + (motion->until - motion->start) * k / 50.0;
    EXPECT_NEAR(motion->centreAt(t).x(), body.centre.x(), 1e-10) << t;
    EXPECT_NEAR(motion->centreAt(t).y(), body.centre.y(), 1e-10) << t;
    EXPECT_EQ(motion->stateAt(t), ContactState::kSliding) << t;
  }
  expectSound(body, floor, *motion, 1e-9, true);
}

TEST(ShapedRim, ACapsuleOnOneEndFallsOntoItsSideAtTheEnergyIntegralsInstant) {
  // A capsule (r = 0.04, half length h = 0.1 between its ends' centres, 1 kg, I_x = 0.005),
  // tilted 0.3 rad about x on the end at -h and turning outwards at 0.5 rad/s, frictionless: its
  // end's point touching is under the end's centre, its centre's x and y kept, its height
  // z = r + h cos theta; it lands on its side at theta = pi/2, the energy integral's instant.
  const double r = 0.04, h = 0.1, m = 1.0, tilt = 0.3, rate0 = 0.5, ix = 0.005;
  LastingBody body;
  body.shape = Capsule{r, h};
  body.mass = m;
  body.moments = V(ix, ix, 0.0008);
  body.gravity = V(0, 0, -kG);
  body.orientation = Q(Eigen::AngleAxisd(tilt, V::UnitX()));
  body.centre = V(0, -h * std::sin(tilt), r + h * std::cos(tilt));
  body.angular_velocity = V(rate0, 0, 0);
  body.velocity = V(0, 0, -h * std::sin(tilt) * rate0);
  const FlatFace floor = floorOf(0.0);
  const auto motion = lastingOnFace(body, floor, 1e-11);
  ASSERT_TRUE(motion.ok()) << motion.error().message();
  ASSERT_TRUE(motion->pivot);
  EXPECT_EQ(motion->ends, "resumes");
  const auto z = [&](double q) { return r + h * std::cos(q); };
  const auto dz = [&](double q) { return -h * std::sin(q); };
  const auto rate = [&](double q) {
    const double kinetic = 0.5 * (m * dz(tilt) * dz(tilt) + ix) * rate0 * rate0;
    return std::sqrt(2 * (kinetic + m * kG * (z(tilt) - z(q))) / (m * dz(q) * dz(q) + ix));
  };
  EXPECT_NEAR(motion->until - motion->start, instant(rate, tilt, M_PI / 2), 1e-9);
  EXPECT_NEAR(motion->centreAt(motion->until).z(), r, 1e-9);
  for (int k = 0; k <= 50; ++k) {
    const double t = motion->start + (motion->until - motion->start) * k / 50.0;
    EXPECT_NEAR(motion->centreAt(t).y(), body.centre.y(), 1e-10) << t;
    const auto forces = motion->forcesAt(t);
    ASSERT_EQ(forces.size(), 1u) << t;
    const V end = motion->centreAt(t) - h * (motion->orientationAt(t) * V::UnitZ());
    EXPECT_NEAR(forces[0].point.y(), end.y(), 1e-10) << "under the end's centre, at " << t;
  }
  expectSound(body, floor, *motion, 1e-9, true);
}

TEST(ShapedRim, RandomCansAndCapsulesOnARimOrAnEndKeepTheirEnergyWhereNothingSlides) {
  // 120 cans and capsules on a rim or an end, tilted 0.05 to 1.5 rad about a random horizontal
  // axis, turned about the vertical, spinning at up to 8 rad/s any way, the point touching
  // still or slipping, on floors of mu 0, 0.3 or 5, over their motion or 1 s: never below the
  // floor, never gaining energy past 1e-8 of the scale; where the floor is frictionless or the
  // point never slips (rolling on its rim: the constraint does no work), the energy kept to 1e-8
  // too, which it is only where the point's motion over the body enters its acceleration.
  std::mt19937 random(20261207);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int kept = 0, lost = 0;
  for (int trial = 0; trial < 120; ++trial) {
    const bool can = trial % 2 == 0;
    const double r = 0.02 + 0.05 * unit(random), h = 0.03 + 0.1 * unit(random), m = 0.5;
    LastingBody body;
    if (can) {
      body = cylinder(r, h, m);
    } else {
      body.shape = Capsule{r, h};
      body.mass = m;
      body.moments = V(0.004, 0.004, 0.0006) * (0.5 + unit(random));
      body.gravity = V(0, 0, -kG);
    }
    const double tilt = 0.05 + 1.45 * unit(random), heading = 2 * M_PI * unit(random);
    body.orientation =
        Q(Eigen::AngleAxisd(heading, V::UnitZ()) * Eigen::AngleAxisd(tilt, V::UnitX()));
    const V a = body.orientation * V::UnitZ();
    const V end = -h * a;  // the end at -h touches (its axis points up)
    const V across = a.cross(V::UnitZ().cross(a));
    const V point = can ? V(end - r * across.normalized()) : V(end - r * V::UnitZ());
    body.centre = -point;  // the point touching at the origin
    body.angular_velocity = 8 * V(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5);
    // The point's normal motion 0; its slip 0 or up to 0.5 m/s.
    V v = -body.angular_velocity.cross(point);
    if (trial % 3 != 0) v += 0.5 * V(unit(random) - 0.5, unit(random) - 0.5, 0);
    body.velocity = v;
    const double mu = trial % 3 == 0 ? 5.0 : (trial % 3 == 1 ? 0.0 : 0.3);
    const FlatFace floor = floorOf(mu);
    const auto motion = pivotOnRound(body, floor, {-1}, V::UnitX(), 1e-10, 1.0);
    ASSERT_TRUE(motion.ok()) << trial << ": " << motion.error().message();
    bool slid = false, touched = true;
    for (int k = 0; k <= 200; ++k) {
      const double t = motion->start + (motion->until - motion->start) * k / 200.0;
      slid = slid || motion->stateAt(t) == ContactState::kSliding;
      touched = touched && !motion->forcesAt(t).empty();
    }
    const bool conserving = mu == 0.0 || !slid;
    (conserving ? kept : lost) += 1;
    SCOPED_TRACE(::testing::Message() << "trial " << trial << (can ? " can" : " capsule") << " mu "
                                      << mu << " ends " << motion->ends << " touched " << touched);
    expectSound(body, floor, *motion, 1e-8, conserving);
  }
  EXPECT_GE(kept, 40);
  EXPECT_GE(lost, 10);
}

TEST(ShapedRim, ATallCanSlidingOnItsCapTipsOverItsFrontRim) {
  // r = 0.03, h = 0.1, sliding at 2 m/s along x on a floor of mu 0.5: its centre of pressure
  // would be h mu = 0.05 m ahead of its centre, past the rim (0.03): it tips over the rim's
  // point ahead, (r, 0, 0) from the cap's centre, which alone carries it (its normal force
  // from the tipping's law, > 0), sound over its motion.
  const double r = 0.03, h = 0.1, m = 0.4;
  LastingBody body = cylinder(r, h, m);
  body.centre = V(0, 0, h);
  body.velocity = V(2, 0, 0);
  const FlatFace floor = floorOf(0.5);
  const auto motion = lastingOnFace(body, floor, 1e-10);
  ASSERT_TRUE(motion.ok()) << motion.error().message();
  ASSERT_TRUE(motion->pivot);
  const auto forces = motion->forcesAt(motion->start);
  ASSERT_EQ(forces.size(), 1u);
  EXPECT_NEAR((forces[0].point - V(r, 0, 0)).norm(), 0.0, 1e-10);
  EXPECT_GT(forces[0].normal_force, 0.0);
  EXPECT_GT(motion->angularVelocityAt(motion->until).y(), 0.0) << "turning forwards";
  expectSound(body, floor, *motion, 1e-8, false);
  // Not sliding, with its centre of pressure at its centre, it rests on its cap (a closed form).
  body.velocity = V::Zero();
  const auto rests = lastingOnFace(body, floor, 1e-10);
  ASSERT_TRUE(rests.ok()) << rests.error().message();
  EXPECT_EQ(rests->state, ContactState::kResting);
  EXPECT_FALSE(rests->pivot);
}

TEST(ShapedRim, ACanSpinningOnItsCapStopsTurningAtItsRimsFrictionsInstant) {
  // r = 0.05, h = 0.1, 1 kg, standing on its cap spinning at 3 rad/s about the normal, mu = 0.5:
  // by symmetry each of the cap's four rim points carries m g / 4 and slides along the rim, its
  // friction mu m g / 4 against it: the moment mu m g r about the normal, J = m r^2 / 2, so
  // w' = -2 mu g / r while the centre stays put, until the rim's slip w r falls to
  // kPivotSlipStops, at (3 - 1e-6 / r) r / (2 mu g); there it rests (asked again: the closed
  // forms, at rest). Before, a can spinning on its cap was refused (`not yet: spin about the
  // face's normal`).
  const double r = 0.05, h = 0.1, m = 1.0, w0 = 3.0, mu = 0.5;
  LastingBody body = cylinder(r, h, m);
  body.centre = V(0.2, -0.1, h);
  body.angular_velocity = V(0, 0, w0);
  const FlatFace floor = floorOf(mu);
  const auto motion = lastingOnFace(body, floor, 1e-11);
  ASSERT_TRUE(motion.ok()) << motion.error().message();
  ASSERT_TRUE(motion->pivot);
  EXPECT_EQ(motion->ends, "stops");
  const double alpha = 2 * mu * kG / r;
  EXPECT_NEAR(motion->until - motion->start, (w0 - kPivotSlipStops / r) / alpha, 1e-9);
  for (int k = 0; k <= 50; ++k) {
    const double t = motion->start + 0.999 * (motion->until - motion->start) * k / 50.0;
    EXPECT_NEAR(motion->angularVelocityAt(t).z(), w0 - alpha * (t - motion->start), 1e-8) << t;
    EXPECT_LE((motion->centreAt(t) - body.centre).norm(), 1e-10) << t;
    EXPECT_EQ(motion->stateAt(t), ContactState::kSliding) << t;
    const auto forces = motion->forcesAt(t);
    ASSERT_EQ(forces.size(), 4u) << t;
    for (const SupportForce& f : forces) {
      EXPECT_NEAR((f.point - V(body.centre.x(), body.centre.y(), 0)).norm(), r, 1e-12) << t;
      EXPECT_NEAR(f.normal_force, m * kG / 4, 1e-9) << t;
      EXPECT_NEAR(f.friction_force.norm(), mu * m * kG / 4, 1e-9) << t;
    }
  }
  expectSound(body, floor, *motion, 1e-9, false);
  const LastingBody there = lasting_bodies::bodyAt(body, *motion, motion->until);
  const auto rest = lastingOnFace(there, floor);
  ASSERT_TRUE(rest.ok()) << rest.error().message();
  EXPECT_EQ(rest->state, ContactState::kResting);
  EXPECT_FALSE(rest->pivot);
}

}  // namespace collision_response::core
