// A shaped body against several obstacles at once (lastingOnFaces, pivotOnFaces in
// shaped_pivot.h; doc/model.md, "Against several obstacles at once"): a plank leaning on a wall,
// a box sliding down a gutter, a box in a corner. Before, held where it touched the second
// ("not yet: a shaped body's lasting contact with 2 obstacles at once").
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "contact/shaped_lasting.h"
#include "contact/shaped_pivot.h"
#include "lasting_bodies.h"

namespace collision_response::core {
namespace {

using lasting_bodies::box;
using lasting_bodies::errorOf;
using lasting_bodies::kG;
using lasting_bodies::plane;
using lasting_bodies::Q;
using lasting_bodies::V;

/// A plank of half sizes (a, w, b) leaning at theta above the floor z = 0 on the wall x = 0, its
/// long axis u = (-cos theta, 0, sin theta) from its foot up to the wall, v = (sin theta, 0,
/// cos theta) across it: its corner -a u - b v on the floor, +a u - b v on the wall, so its
/// centre is at f(theta) = (a cos theta + b sin theta, 0, a sin theta + b cos theta) while it
/// touches both. Turned by theta + pi about y: its x axis is u.
struct Plank {
  double a = 0.5, w = 0.1, b = 0.02, mass = 2.0;
  double theta0 = M_PI / 3;
  LastingBody at(double theta) const {
    return box(V(a, w, b), mass, centre(theta), Q(Eigen::AngleAxisd(theta + M_PI, V::UnitY())));
  }
  V centre(double theta) const {
    return V(a * std::cos(theta) + b * std::sin(theta), 0,
             a * std::sin(theta) + b * std::cos(theta));
  }
  /// Its angle from its orientation (x axis u).
  static double angleOf(const Q& orientation) {
    const Eigen::Matrix3d r = orientation.toRotationMatrix();
    return std::atan2(r(2, 0), -r(0, 0));
  }
  // The energy integral of the frictionless slide from rest at theta0, with both corners on:
  // m |f'|^2 theta'^2 / 2 + I theta'^2 / 2 + m g z(theta) = m g z(theta0), |f'|^2 = a^2 + b^2 -
  // 2 a b sin 2 theta, I = m (a^2 + b^2) / 3: theta'^2 = F(theta) = 2 g (z0 - z) / D.
  long double d(long double t) const {
    const long double aa = a, bb = b;
    return (aa * aa + bb * bb) * 4 / 3 - 2 * aa * bb * std::sin(2 * t);
  }
  long double f(long double t) const {
    const long double z0 = a * std::sin((long double)theta0) + b * std::cos((long double)theta0);
    const long double z = a * std::sin(t) + b * std::cos(t);
    return 2 * (long double)kG * (z0 - z) / d(t);
  }
  long double fRate(long double t) const {  // dF/dtheta
    const long double z0 = a * std::sin((long double)theta0) + b * std::cos((long double)theta0);
    const long double z = a * std::sin(t) + b * std::cos(t);
    const long double z_rate = a * std::cos(t) - b * std::sin(t);
    const long double d_rate = -4 * (long double)a * b * std::cos(2 * t);
    return 2 * (long double)kG * (-z_rate * d(t) - (z0 - z) * d_rate) / (d(t) * d(t));
  }
  /// The wall's force over m: x_c'' = x'' theta'^2 + x' theta'' (theta'' = F' / 2).
  long double wallForce(long double t) const {
    const long double x_rate = -a * std::sin(t) + b * std::cos(t);
    const long double x_rate2 = -a * std::cos(t) - b * std::sin(t);
    return x_rate2 * f(t) + x_rate * fRate(t) / 2;
  }
  /// Where the wall's force falls to 0 first, going down from theta0 (bisection in long double).
  double leaves() const {
    long double hi = theta0 - 1e-9L, lo = hi;
    while (wallForce(lo) > 0) lo -= 1e-3L;
    for (int i = 0; i < 200; ++i) {
      const long double mid = (lo + hi) / 2;
      (wallForce(mid) > 0 ? hi : lo) = mid;
    }
    return static_cast<double>((lo + hi) / 2);
  }
};

std::vector<FlatFace> floorAndWall(double mu_floor, double mu_wall) {
  return {plane(V::UnitZ(), mu_floor), plane(V::UnitX(), mu_wall)};
}

bool onWall(const LastingMotion& motion, double t) {
  for (const SupportForce& force : motion.forcesAt(t)) {
    if (force.face == 1) return true;
  }
  return false;
}

TEST(ShapedFaces, TheLadderReferenceLeavesAtTwoThirdsOfItsHeightWhenThin) {
  // The reference's own check: a thin rod (b = 0) leaves the wall where sin theta = 2/3 sin
  // theta0 (the classic result of the same energy integral).
  Plank rod;
  rod.b = 0.0;
  EXPECT_NEAR(std::sin(rod.leaves()), 2.0 / 3.0 * std::sin(rod.theta0), 1e-12);
}

TEST(ShapedFaces, AFrictionlessPlankLeaningOnAWallLeavesItWhereItsEnergyIntegralSays) {
  const Plank plank;
  const LastingBody body = plank.at(plank.theta0);
  const auto motion = lastingOnFaces(body, floorAndWall(0, 0), 1e-11);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  ASSERT_TRUE(motion->pivot);
  EXPECT_EQ(motion->ends, "resumes") << "it falls flat onto the floor";
  // The wall's points leave where their force is 0: bisected on the forces the motion gives.
  double lo = 0, hi = motion->until;
  ASSERT_TRUE(onWall(*motion, lo));
  ASSERT_FALSE(onWall(*motion, hi));
  while (hi - lo > 1e-13) {
    const double mid = (lo + hi) / 2;
    (onWall(*motion, mid) ? lo : hi) = mid;
  }
  const double leave_angle = plank.leaves();
  EXPECT_NEAR(Plank::angleOf(motion->orientationAt(hi)), leave_angle, 1e-8);
  // While on both: the centre on f(theta), theta'^2 = F(theta); throughout, the energy kept.
  const double e0 = lasting_bodies::energy(body, *motion, 0);
  double worst_centre = 0, worst_rate = 0, worst_energy = 0;
  for (int k = 0; k <= 400; ++k) {
    const double t = motion->until * k / 400;
    const double theta = Plank::angleOf(motion->orientationAt(t));
    worst_energy = std::max(worst_energy,
                            std::abs(lasting_bodies::energy(body, *motion, t) - e0) / std::abs(e0));
    if (t >= lo) continue;
    worst_centre = std::max(worst_centre, (motion->centreAt(t) - plank.centre(theta)).norm());
    const double rate = motion->angularVelocityAt(t).y();
    worst_rate = std::max(worst_rate, std::abs(rate * rate - static_cast<double>(plank.f(theta))));
  }
  EXPECT_LT(worst_centre, 1e-9);
  EXPECT_LT(worst_rate, 1e-8);
  EXPECT_LT(worst_energy, 1e-9);
  std::printf(
      "leaves the wall at %.9f rad (energy integral %.9f), centre %.3g m, rate^2 %.3g, "
      "energy %.3g\n",
      Plank::angleOf(motion->orientationAt(hi)), leave_angle, worst_centre, worst_rate,
      worst_energy);
}

TEST(ShapedFaces, APlankWhoseFloorFrictionHoldsItRestsOnTheWallWithTheStaticForces) {
  // Moments about its foot (2a cos theta, 0, 0): the wall's force N = m g (a cos theta - b sin
  // theta) / (2 a sin theta) at its top (0, 0, 2 a sin theta), the floor's friction N towards
  // the wall, its normal force m g: it rests where mu >= N / (m g).
  const Plank plank;
  const double t = plank.theta0;
  const double ratio =
      (plank.a * std::cos(t) - plank.b * std::sin(t)) / (2 * plank.a * std::sin(t));
  const double weight = plank.mass * kG;
  const LastingBody body = plank.at(t);
  const auto held = lastingOnFaces(body, floorAndWall(1.01 * ratio, 0), 1e-11);
  ASSERT_TRUE(held.ok()) << errorOf(held);
  EXPECT_EQ(held->state, ContactState::kResting);
  EXPECT_FALSE(held->pivot);
  EXPECT_EQ(held->until, std::numeric_limits<double>::infinity());
  EXPECT_EQ(held->velocityAt(5.0), V::Zero());
  V floor_force = V::Zero(), wall_force = V::Zero();
  for (const SupportForce& force : held->forcesAt(5.0)) {
    const V on_body =
        force.normal_force * (force.face == 0 ? V::UnitZ() : V::UnitX()) + force.friction_force;
    (force.face == 0 ? floor_force : wall_force) += on_body;
  }
  EXPECT_NEAR(floor_force.z(), weight, 1e-12 * weight);
  EXPECT_NEAR(floor_force.x(), -ratio * weight, 1e-12 * weight);
  EXPECT_NEAR(wall_force.x(), ratio * weight, 1e-12 * weight);
  EXPECT_NEAR(wall_force.z(), 0.0, 1e-12 * weight);
  // Just below the friction it needs, its foot slides away from the wall.
  const auto slides = lastingOnFaces(body, floorAndWall(0.99 * ratio, 0), 1e-11);
  ASSERT_TRUE(slides.ok()) << errorOf(slides);
  EXPECT_NE(slides->state, ContactState::kResting);
  EXPECT_GT(slides->velocityAt(std::min(0.05, slides->until)).x(), 1e-6);
}

TEST(ShapedFaces, ABoxSlidingDownAGutterDeceleratesByBothFrictionsAndRestsWhereItStops) {
  // The floor z = 0 and the wall y = 0 form a gutter along x; gravity tilted: beta down along x,
  // gamma rolled towards the wall. The normal forces m g cos beta cos gamma and m g cos beta sin
  // gamma hold it across; each face's friction mu N against the slide: a = g sin beta - mu1 g
  // cos beta cos gamma - mu2 g cos beta sin gamma.
  const double beta = 20 * M_PI / 180, gamma = 30 * M_PI / 180, mu1 = 0.4, mu2 = 0.3;
  const double v0 = 0.6, half = 0.05;
  LastingBody body = box(V(half, half, half), 0.5, V(0, half, half));
  body.gravity =
      kG * V(std::sin(beta), -std::cos(beta) * std::sin(gamma), -std::cos(beta) * std::cos(gamma));
  body.velocity = V(v0, 0, 0);
  const std::vector<FlatFace> faces = {plane(V::UnitZ(), mu1), plane(V::UnitY(), mu2)};
  const double a = kG * (std::sin(beta) - mu1 * std::cos(beta) * std::cos(gamma) -
                         mu2 * std::cos(beta) * std::sin(gamma));
  ASSERT_LT(a, 0.0);
  const double stops = -v0 / a;
  const auto motion = lastingOnFaces(body, faces, 1e-11);
  ASSERT_TRUE(motion.ok()) << errorOf(motion);
  EXPECT_EQ(motion->ends, "stops");
  EXPECT_NEAR(motion->until, stops, 2e-6) << "the slip stops at kPivotSlipStops";
  double worst_centre = 0, worst_velocity = 0, worst_spin = 0;
  for (int k = 0; k <= 200; ++k) {
    const double t = std::min(motion->until, stops) * k / 200;
    const V centre(v0 * t + a * t * t / 2, half, half);
    worst_centre = std::max(worst_centre, (motion->centreAt(t) - centre).norm());
    if (t < motion->until) {  // (at it, at rest: the slip's last 1e-6 m/s taken out)
      worst_velocity =
          std::max(worst_velocity, (motion->velocityAt(t) - V(v0 + a * t, 0, 0)).norm());
    }
    worst_spin = std::max(worst_spin, motion->angularVelocityAt(t).norm());
  }
  EXPECT_LT(worst_centre, 1e-9);
  EXPECT_LT(worst_velocity, 1e-8);
  EXPECT_LT(worst_spin, 1e-9);
  // Asked again where it stopped: at rest there for ever, its friction within both cones.
  const auto rest =
      lastingOnFaces(lasting_bodies::bodyAt(body, *motion, motion->until), faces, 1e-11);
  ASSERT_TRUE(rest.ok()) << errorOf(rest);
  EXPECT_EQ(rest->state, ContactState::kResting);
  EXPECT_EQ(rest->until, std::numeric_limits<double>::infinity());
  EXPECT_NEAR(rest->centreAt(9.0).x(), v0 * v0 / (-2 * a), 1e-9);
}

TEST(ShapedFaces, WhatIsNotModelledOrWrongIsNamed) {
  const Plank plank;
  const LastingBody body = plank.at(plank.theta0);
  EXPECT_EQ(errorOf(lastingOnFaces(body, {})), "faces: must hold at least one face");
  // Not touching the second face: named.
  std::vector<FlatFace> far = floorAndWall(0, 0);
  far[1].point = V(-0.1, 0, 0);
  EXPECT_NE(errorOf(lastingOnFaces(body, far)).find("faces[1]: the body's lowest corner"),
            std::string::npos)
      << errorOf(lastingOnFaces(body, far));
  std::vector<FlatFace> zero = floorAndWall(0, 0);
  zero[1].normal = V::Zero();
  EXPECT_EQ(errorOf(lastingOnFaces(body, zero)).rfind("faces[1].normal", 0), 0u)
      << errorOf(lastingOnFaces(body, zero));
  LastingBody can = lasting_bodies::cylinder(0.05, 0.1, 0.3, 0.5 * 0.3 * 0.05 * 0.05,
                                             V(0.05, 0, 0.1), Q::Identity());
  EXPECT_EQ(errorOf(lastingOnFaces(can, floorAndWall(0.5, 0.5))),
            "contact: not yet: a cylinder or a capsule against several obstacles at once");
}

}  // namespace
}  // namespace collision_response::core
