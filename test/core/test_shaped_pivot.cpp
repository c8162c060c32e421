// A box tipping over a corner or an edge, or spinning on its face (contact/shaped_pivot.h),
// against what holds exactly whatever the integrator: the physical pendulum's energy integral
// about a sticking edge and its landing instant (a quadrature of it, worked in the test), a
// frictionless edge whose centre falls straight down, a corner's energy and angular momentum
// about the vertical through it, and a box spinning flat whose four corners' friction stops it
// at w0 / alpha (to its slip's stop, 1e-6 m/s). Every motion is sampled: no point below the face,
// no energy gained beyond the integration's tolerance, no normal force < 0, every friction within
// mu of its normal force.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
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

FlatFace floorOf(double mu) { return lasting_bodies::plane(V::UnitZ(), mu); }

using lasting_bodies::kDown;
using lasting_bodies::kG;

LastingBody cube(double half, double mass, const V& centre, const Q& orientation) {
  LastingBody body;
  body.shape = Cuboid{V(half, half, half)};
  body.mass = mass;
  body.moments = V::Constant(2 * mass * half * half / 3);  // m s^2 / 6, s = 2 half
  body.centre = centre;
  body.orientation = orientation;
  body.gravity = kDown;
  return body;
}

double lowestCorner(const LastingBody& body, const LastingMotion& motion, double t) {
  const V half = std::get<Cuboid>(body.shape).half_size;
  const Eigen::Matrix3d r = motion.orientationAt(t).toRotationMatrix();
  double lowest = INFINITY;
  for (int c = 0; c < 8; ++c) {
    const V corner((c & 1) ? half.x() : -half.x(), (c & 2) ? half.y() : -half.y(),
                   (c & 4) ? half.z() : -half.z());
    lowest = std::min(lowest, (motion.centreAt(t) + r * corner).z());
  }
  return lowest;
}

/// Over [start, until] at 101 instants: no corner below the floor, the energy never above the
/// start's by more than `tolerance` of the scale m g reach + the kinetic energy, the forces >= 0
/// and within the cone.
void expectSound(const LastingBody& body, const FlatFace& face, const LastingMotion& motion,
                 double tolerance) {
  const double reach = std::get<Cuboid>(body.shape).half_size.norm();
  const double scale = body.mass * kG * reach + energy(body, motion, motion.start) -
                       body.mass * kG * motion.centreAt(motion.start).z();
  const double start = energy(body, motion, motion.start);
  for (int k = 0; k <= 100; ++k) {
    const double t = motion.start + (motion.until - motion.start) * k / 100.0;
    EXPECT_GE(lowestCorner(body, motion, t), 0.0) << "at t = " << t;
    EXPECT_LE(energy(body, motion, t), start + tolerance * scale) << "at t = " << t;
    for (const SupportForce& force : motion.forcesAt(t)) {
      EXPECT_GE(force.normal_force, 0.0) << "at t = " << t;
      EXPECT_LE(force.friction_force.norm(),
                face.friction * force.normal_force + 1e-9 * body.mass * kG)
          << "at t = " << t;
    }
  }
}

/// A cube of half size h standing on its edge along y through the origin, the line from the edge
/// to its centre psi from the vertical towards -x, turning at psi' away from the vertical: turned
/// by beta = pi/4 - psi about y (beta = 0: flat on its face), its centre d (-sin psi, 0, cos psi)
/// with d = h sqrt 2, w = (0, -psi', 0).
LastingBody onEdge(double half, double mass, double psi, double psi_rate) {
  const double d = half * std::sqrt(2.0);
  LastingBody body = cube(half, mass, V(-d * std::sin(psi), 0, d * std::cos(psi)),
                          Q(Eigen::AngleAxisd(M_PI / 4 - psi, V::UnitY())));
  body.angular_velocity = V(0, -psi_rate, 0);
  body.velocity = body.angular_velocity.cross(body.centre);
  return body;
}

/// The instant a sticking edge's cube turns from psi0 (at psi0') to psi1: the integral of
/// dpsi / psi'(psi) with psi'^2 = psi0'^2 + 2 m g d (cos psi0 - cos psi) / I_edge, I_edge =
/// 2/3 m s^2 = 8/3 m h^2 (the cube's m s^2 / 6 and m d^2 by the parallel axes), by 5-point
/// Gauss-Legendre over 400 panels (the integrand is smooth where psi0' > 0).
double pendulumInstant(double half, double psi0, double rate0, double psi1) {
  const double d = half * std::sqrt(2.0), inertia_per_mass = 8.0 / 3.0 * half * half;
  const auto rate = [&](double psi) {
    return std::sqrt(rate0 * rate0 +
                     2 * kG * d * (std::cos(psi0) - std::cos(psi)) / inertia_per_mass);
  };
  return quadrature::gaussLegendre([&](double psi) { return 1 / rate(psi); }, psi0, psi1, 400);
}

}  // namespace

TEST(ShapedPivot, ACubeTippingOverAStickingEdgeLandsOnItsFaceAtThePendulumsInstant) {
  // The 0.1048 m, 0.37 kg cube, 0.1 rad past balance on its edge, turning at 0.5 rad/s, mu = 5
  // (it sticks): its centre on the circle of radius d about the edge, psi' from the energy
  // integral at the psi its centre shows, and the face's far edge on the floor at
  // psi = pi/4, at the quadrature's instant (the motion ends there: the impact is the caller's).
  const double half = 0.0524, m = 0.37, psi0 = 0.1, rate0 = 0.5;
  const LastingBody body = onEdge(half, m, psi0, rate0);
  const FlatFace floor = floorOf(5.0);
  const auto motion = lastingOnFace(body, floor, 1e-11);
  ASSERT_TRUE(motion.ok()) << motion.error().message();
  ASSERT_TRUE(motion->pivot);
  EXPECT_EQ(motion->ends, "resumes");
  const double landing = pendulumInstant(half, psi0, rate0, M_PI / 4);
  EXPECT_NEAR(motion->until - motion->start, landing, 1e-9);
  const double d = half * std::sqrt(2.0), inertia_per_mass = 8.0 / 3.0 * half * half;
  for (int k = 0; k <= 50; ++k) {
    const double t = motion->start + (motion->until - motion->start) * k / 50.0;
    const V c = motion->centreAt(t);
    EXPECT_NEAR(std::hypot(c.x(), c.z()), d, 1e-9) << "at t = " << t;
    EXPECT_NEAR(c.y(), 0.0, 1e-12);
    const double psi = std::atan2(-c.x(), c.z());
    const double rate =
        std::sqrt(rate0 * rate0 + 2 * kG * d * (std::cos(psi0) - std::cos(psi)) / inertia_per_mass);
    EXPECT_NEAR(-motion->angularVelocityAt(t).y(), rate, 1e-8) << "at t = " << t;
    EXPECT_EQ(motion->stateAt(t), ContactState::kRolling);
    const auto forces = motion->forcesAt(t);
    ASSERT_EQ(forces.size(), 2u);
    for (const SupportForce& f : forces) EXPECT_NEAR(f.point.x(), 0.0, 1e-9);
  }
  expectSound(body, floor, *motion, 1e-9);
}

TEST(ShapedPivot, AFrictionlessEdgeSlidesWithTheCentreFallingStraightDown) {
  // mu = 0: no force across the floor, so the centre's x and y stay where they are (it starts
  // with no velocity across), and the energy stays what it was (no friction to take it).
  const LastingBody body = onEdge(0.05, 1.0, 0.2, 0.0);
  const FlatFace floor = floorOf(0.0);
  const auto motion = lastingOnFace(body, floor, 1e-11);
  ASSERT_TRUE(motion.ok()) << motion.error().message();
  ASSERT_TRUE(motion->pivot);
  EXPECT_EQ(motion->ends, "resumes");
  const double start = energy(body, *motion, motion->start);
  for (int k = 0; k <= 50; ++k) {
    const double t = motion->start + (motion->until - motion->start) * k / 50.0;
    EXPECT_NEAR(motion->centreAt(t).x(), body.centre.x(), 1e-10) << "at t = " << t;
    EXPECT_NEAR(motion->centreAt(t).y(), 0.0, 1e-12);
    EXPECT_NEAR(energy(body, *motion, t), start, 1e-9 * start);
    EXPECT_EQ(motion->stateAt(t), ContactState::kSliding);
  }
  expectSound(body, floor, *motion, 1e-9);
}

TEST(ShapedPivot, ACubeOnAStickingCornerKeepsItsEnergyAndItsSpinAboutTheVertical) {
  // On one corner, its diagonal 0.3 rad from the vertical, spinning about the vertical at
  // 3 rad/s, mu = 5: the corner stays where it is; gravity's moment about it is horizontal and
  // the floor's force acts at it, so the angular momentum about the vertical through the corner
  // and the energy are what they were (to the integration's tolerance) until another corner
  // lands.
  const double half = 0.05, m = 0.5;
  const Q diagonal_up = Q::FromTwoVectors(V(1, 1, 1).normalized(), V::UnitZ());
  const Q turn = Q(Eigen::AngleAxisd(0.3, V::UnitX())) * diagonal_up;
  // The corner (-h, -h, -h) lowest: the centre is its turned opposite above the origin.
  const V centre = turn * V(half, half, half);
  LastingBody body = cube(half, m, centre, turn);
  body.angular_velocity = V(0, 0, 3);
  body.velocity = body.angular_velocity.cross(centre);
  const FlatFace floor = floorOf(5.0);
  const auto motion = lastingOnFace(body, floor, 1e-11);
  ASSERT_TRUE(motion.ok()) << motion.error().message();
  ASSERT_TRUE(motion->pivot);
  EXPECT_EQ(motion->ends, "resumes");
  const auto spinAbout = [&](double t) {
    const Eigen::Matrix3d r = motion->orientationAt(t).toRotationMatrix();
    const V c = motion->centreAt(t);
    const V l = r * body.moments.asDiagonal() * r.transpose() * motion->angularVelocityAt(t) +
                m * c.cross(motion->velocityAt(t));  // about the corner at the origin
    return l.z();
  };
  const double l0 = spinAbout(motion->start), e0 = energy(body, *motion, motion->start);
  for (int k = 0; k <= 50; ++k) {
    const double t = motion->start + (motion->until - motion->start) * k / 50.0;
    EXPECT_NEAR(spinAbout(t), l0, 1e-9 * std::abs(l0)) << "at t = " << t;
    EXPECT_NEAR(energy(body, *motion, t), e0, 1e-9 * e0) << "at t = " << t;
    const auto forces = motion->forcesAt(t);
    ASSERT_EQ(forces.size(), 1u);
    EXPECT_LE(forces.front().point.norm(), 1e-9) << "at t = " << t;
  }
  expectSound(body, floor, *motion, 1e-9);
}

TEST(ShapedPivot, ABoxSpinningFlatStopsTurningAtOmegaOverAlpha) {
  // Half sizes (0.2, 0.1, 0.05), 1 kg, flat on the floor, spinning at 1 rad/s about the normal,
  // mu = 0.5: by symmetry each corner carries m g / 4 and slides along its circle of radius
  // r = sqrt(0.2^2 + 0.1^2), its friction mu m g / 4 against it: the moment mu m g r about the
  // normal, J = m (0.4^2 + 0.2^2) / 12 = m / 60, so w' = -60 mu g r while the centre stays put,
  // until w = 0 at 1 / (60 mu g r), where the motion stops (the closed forms take it: at rest).
  LastingBody body;
  body.shape = Cuboid{V(0.2, 0.1, 0.05)};
  body.mass = 1.0;
  body.moments = V(0.1 * 0.1 + 0.05 * 0.05, 0.2 * 0.2 + 0.05 * 0.05, 0.2 * 0.2 + 0.1 * 0.1) / 3;
  body.centre = V(0, 0, 0.05);
  body.gravity = kDown;
  body.angular_velocity = V(0, 0, 1);
  const FlatFace floor = floorOf(0.5);
  const auto motion = lastingOnFace(body, floor, 1e-11);
  ASSERT_TRUE(motion.ok()) << motion.error().message();
  ASSERT_TRUE(motion->pivot);
  const double r = std::hypot(0.2, 0.1), alpha = 60 * 0.5 * kG * r;
  EXPECT_EQ(motion->ends, "stops");
  // The slip stops where it falls to kPivotSlipStops: w r = 1e-6 m/s.
  EXPECT_NEAR(motion->until - motion->start, (1 - kPivotSlipStops / r) / alpha, 1e-9);
  for (int k = 0; k <= 50; ++k) {
    const double t = motion->start + 0.999 * (motion->until - motion->start) * k / 50.0;
    EXPECT_NEAR(motion->angularVelocityAt(t).z(), 1 - alpha * (t - motion->start), 1e-8);
    EXPECT_LE((motion->centreAt(t) - body.centre).norm(), 1e-10);
    EXPECT_EQ(motion->stateAt(t), ContactState::kSliding);
    const auto forces = motion->forcesAt(t);
    ASSERT_EQ(forces.size(), 4u);
    for (const SupportForce& f : forces) {
      EXPECT_NEAR(f.normal_force, kG / 4, 1e-9);
      EXPECT_NEAR(f.friction_force.norm(), 0.5 * kG / 4, 1e-9);
    }
  }
  // Asked again where it stops: at rest by the closed forms.
  const LastingBody there = lasting_bodies::bodyAt(body, *motion, motion->until);
  const auto rest = lastingOnFace(there, floor);
  ASSERT_TRUE(rest.ok()) << rest.error().message();
  EXPECT_EQ(rest->state, ContactState::kResting);
  expectSound(body, floor, *motion, 1e-9);
}

TEST(ShapedPivot, ACornerLiftedByItsTurningFliesItsParabolaUntilClearOfTheFace) {
  // On one corner, its diagonal vertical (the centre d = h sqrt 3 above the corner), turning at
  // 20 rad/s about x with the corner still: the centre's circle about the corner needs w^2 d =
  // 34.6 m/s^2 towards the corner, more than g: the floor would have to pull, so the corner
  // leaves at once and the body flies: its centre on the parabola c0 + v0 t + g t^2 / 2 and its
  // spin kept (a cube's inertia is isotropic), no force, until its lowest corner is
  // kPivotClearance of its reach (h sqrt 3) above the floor ("resumes": the certified first
  // contact takes it from there).
  const double half = 0.05, d = half * std::sqrt(3.0);
  const Q diagonal_up = Q::FromTwoVectors(V(1, 1, 1).normalized(), V::UnitZ());
  LastingBody body = cube(half, 0.4, V(0, 0, d), diagonal_up);
  body.angular_velocity = V(20, 0, 0);
  body.velocity = -body.angular_velocity.cross(V(0, 0, -d));  // the corner still
  const FlatFace floor = floorOf(0.5);
  const auto motion = lastingOnFace(body, floor, 1e-11);
  ASSERT_TRUE(motion.ok()) << motion.error().message();
  ASSERT_TRUE(motion->pivot);
  EXPECT_EQ(motion->ends, "resumes");
  for (int k = 0; k <= 50; ++k) {
    const double t = motion->start + (motion->until - motion->start) * k / 50.0;
    const double s = t - motion->start;
    EXPECT_LE(
        (motion->centreAt(t) - (body.centre + body.velocity * s + 0.5 * kDown * s * s)).norm(),
        1e-10)
        << "at t = " << t;
    EXPECT_LE((motion->angularVelocityAt(t) - body.angular_velocity).norm(), 1e-8);
    EXPECT_TRUE(motion->forcesAt(t).empty());
  }
  EXPECT_NEAR(lowestCorner(body, *motion, motion->until), kPivotClearance * d, 1e-12);
  expectSound(body, floor, *motion, 1e-9);
}

TEST(ShapedPivot, RandomCubesOnCornersAndEdgesNeverGoBelowNorGainEnergy) {
  // 200 cubes on one corner or one edge at random (turned about the vertical, tilted up to
  // 0.4 rad from balance), moving at up to 1 m/s across the floor and turning at up to 5 rad/s
  // (the touching points' normal motion taken out by the motion's start), mu in [0, 1]: sound
  // over the motion (expectSound, the integration's tolerance 1e-9).
  std::mt19937 random(20261206);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int motions = 0;
  for (int k = 0; k < 200; ++k) {
    const double half = 0.03 + 0.07 * unit(random);
    const bool corner = k % 2 == 0;
    const Q balance = corner ? Q::FromTwoVectors(V(1, 1, 1).normalized(), V::UnitZ())
                             : Q(Eigen::AngleAxisd(M_PI / 4, V::UnitY()));
    const Q turn = Q(Eigen::AngleAxisd(2 * M_PI * unit(random), V::UnitZ())) *
                   Q(Eigen::AngleAxisd(0.4 * (2 * unit(random) - 1), V::UnitX())) * balance;
    LastingBody body = cube(half, 0.2 + unit(random), V::Zero(), turn);
    V low = V::Constant(INFINITY);
    for (int c = 0; c < 8; ++c) {
      const V p = turn * V((c & 1) ? half : -half, (c & 2) ? half : -half, (c & 4) ? half : -half);
      if (p.z() < low.z()) low = p;
    }
    body.centre = V(0, 0, -low.z());
    body.angular_velocity = 5 * V(2 * unit(random) - 1, 2 * unit(random) - 1, 2 * unit(random) - 1);
    // The lowest corner neither approaching nor leaving the floor.
    body.velocity = V(2 * unit(random) - 1, 2 * unit(random) - 1, 0);
    body.velocity.z() = -body.angular_velocity.cross(low).z();
    const FlatFace floor = floorOf(unit(random));
    const auto motion = lastingOnFace(body, floor);
    if (!motion.ok()) {
      // Where its lowest points approach or leave faster than a settled body's: no lasting
      // contact (an impact, the caller's); nothing else is refused.
      EXPECT_NE(motion.error().reason.find("approaches or leaves"), std::string::npos)
          << k << ": " << motion.error().message();
      continue;
    }
    ++motions;
    ASSERT_TRUE(motion->pivot) << k;
    expectSound(body, floor, *motion, 1e-8);
  }
  EXPECT_GT(motions, 20);
}

}  // namespace collision_response::core
