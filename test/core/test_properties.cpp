// Property tests over thousands of seeded random impacts: the laws every answer must obey.
// Reference quantities are computed in long double (64-bit mantissa, 2^11 times finer than
// double), so a check "within k ulps of double" measures the core's rounding, not the test's.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "collision_response/core/impact.h"

namespace collision_response::core {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr int kCases = 20000;

struct RandomImpact {
  double mass_a, mass_b, restitution;
  Eigen::Vector3d velocity_a, velocity_b, normal;
};

class ImpactGenerator {
 public:
  explicit ImpactGenerator(std::uint64_t seed) : engine_(seed) {}

  RandomImpact next() {
    RandomImpact impact;
    impact.mass_a = logUniform(1e-3, 1e3);
    impact.mass_b = logUniform(1e-3, 1e3);
    impact.velocity_a = vector(10.0);
    impact.velocity_b = vector(10.0);
    impact.normal = vector(1.0).normalized();
    // Approaching along n most of the time: flip n so that (v_b - v_a).n < 0.
    if ((impact.velocity_b - impact.velocity_a).dot(impact.normal) > 0 && uniform(0, 1) < 0.9) {
      impact.normal = -impact.normal;
    }
    const double pick = uniform(0, 1);
    impact.restitution = pick < 0.1 ? 0.0 : pick < 0.2 ? 1.0 : uniform(0, 1);
    return impact;
  }

 private:
  double uniform(double low, double high) {
    return std::uniform_real_distribution<double>(low, high)(engine_);
  }
  double logUniform(double low, double high) {
    return std::exp(uniform(std::log(low), std::log(high)));
  }
  Eigen::Vector3d vector(double scale) {
    return Eigen::Vector3d(uniform(-scale, scale), uniform(-scale, scale), uniform(-scale, scale));
  }
  std::mt19937_64 engine_;
};

ImpactResponse<double> resolve(const RandomImpact& c) {
  return resolveImpact(1.0 / c.mass_a, c.velocity_a, 1.0 / c.mass_b, c.velocity_b, c.normal,
                       c.restitution);
}

long double kineticEnergy(double mass, const Eigen::Vector3d& v) {
  const Eigen::Matrix<long double, 3, 1> w = v.cast<long double>();
  return 0.5L * mass * w.squaredNorm();
}

// The scale is sum m |v| over both bodies before and after, |v| the vector's norm: a vector's
// rounding in any frame is relative to its norm (a rotated frame mixes the components), so a
// component's error is bounded by ulps of the norms, not of that component alone.
TEST(ImpactProperties, MomentumConservedWithinFourUlpsOfSumAbsMomentum) {
  ImpactGenerator generator(1);
  for (int i = 0; i < kCases; ++i) {
    const RandomImpact c = generator.next();
    const ImpactResponse<double> r = resolve(c);
    for (int axis = 0; axis < 3; ++axis) {
      const long double before =
          (long double)c.mass_a * c.velocity_a[axis] + (long double)c.mass_b * c.velocity_b[axis];
      const long double after =
          (long double)c.mass_a * r.velocity_a[axis] + (long double)c.mass_b * r.velocity_b[axis];
      const double sum_abs = c.mass_a * (c.velocity_a.norm() + r.velocity_a.norm()) +
                             c.mass_b * (c.velocity_b.norm() + r.velocity_b.norm());
      ASSERT_LE(std::abs(double(after - before)), 4 * kEps * sum_abs) << "case " << i;
    }
  }
}

// Energy lost is (1/2) mu (1 - e^2) d^2 (the closed form, evaluated here in long double), never
// negative, and is what the kinetic energy of the answer actually lost. The core's d comes from
// two rounded dot products, off by up to ~4 eps (|v_a| + |v_b|); the energy, quadratic in d,
// may differ by twice that relative to |d|, plus its own few roundings.
TEST(ImpactProperties, EnergyLostIsNonNegativeAndMatchesClosedForm) {
  ImpactGenerator generator(2);
  for (int i = 0; i < kCases; ++i) {
    const RandomImpact c = generator.next();
    const ImpactResponse<double> r = resolve(c);
    ASSERT_GE(r.energy_lost, 0.0) << "case " << i;
    const long double d = (c.velocity_b.cast<long double>() - c.velocity_a.cast<long double>())
                              .dot(c.normal.cast<long double>());
    const long double mu = 1.0L / (1.0L / c.mass_a + 1.0L / c.mass_b);
    const long double e = c.restitution;
    const long double closed_form = d < 0 ? 0.5L * mu * (1 - e * e) * d * d : 0.0L;
    const double d_error = 4 * kEps * (c.velocity_a.norm() + c.velocity_b.norm());
    const double tolerance =
        double(closed_form) * (8 * kEps + 2 * d_error / std::abs(double(d))) + 1e-300;
    ASSERT_NEAR(r.energy_lost, double(closed_form), tolerance) << "case " << i;
    const long double before =
        kineticEnergy(c.mass_a, c.velocity_a) + kineticEnergy(c.mass_b, c.velocity_b);
    const long double after =
        kineticEnergy(c.mass_a, r.velocity_a) + kineticEnergy(c.mass_b, r.velocity_b);
    ASSERT_NEAR(double(before - after), r.energy_lost, 16 * kEps * double(before)) << "case " << i;
  }
}

TEST(ImpactProperties, ElasticImpactConservesEnergy) {
  ImpactGenerator generator(3);
  for (int i = 0; i < kCases; ++i) {
    RandomImpact c = generator.next();
    c.restitution = 1.0;
    const ImpactResponse<double> r = resolve(c);
    ASSERT_EQ(r.energy_lost, 0.0);
    const long double before =
        kineticEnergy(c.mass_a, c.velocity_a) + kineticEnergy(c.mass_b, c.velocity_b);
    const long double after =
        kineticEnergy(c.mass_a, r.velocity_a) + kineticEnergy(c.mass_b, r.velocity_b);
    ASSERT_LE(std::abs(double(after - before)), 16 * kEps * double(before)) << "case " << i;
  }
}

// Naming the bodies the other way round (and so turning the line of impact round) gives the
// same answer, swapped, to the last bit.
TEST(ImpactProperties, SwappingTheBodiesMirrorsTheAnswerExactly) {
  ImpactGenerator generator(4);
  for (int i = 0; i < kCases; ++i) {
    const RandomImpact c = generator.next();
    const ImpactResponse<double> r = resolve(c);
    const ImpactResponse<double> s =
        resolveImpact(1.0 / c.mass_b, c.velocity_b, 1.0 / c.mass_a, c.velocity_a,
                      Eigen::Vector3d(-c.normal), c.restitution);
    ASSERT_EQ(s.velocity_a, r.velocity_b) << "case " << i;
    ASSERT_EQ(s.velocity_b, r.velocity_a) << "case " << i;
    ASSERT_EQ(s.normal_impulse, r.normal_impulse) << "case " << i;
    ASSERT_EQ(s.energy_lost, r.energy_lost) << "case " << i;
    ASSERT_EQ(s.approaching, r.approaching) << "case " << i;
  }
}

// Physics has no preferred direction: rotating every input vector rotates the answer (within
// the rounding of the rotation itself).
TEST(ImpactProperties, RotatingEveryVectorRotatesTheAnswer) {
  ImpactGenerator generator(5);
  std::mt19937_64 engine(6);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  for (int i = 0; i < kCases; ++i) {
    const RandomImpact c = generator.next();
    const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(angle(engine), Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(angle(engine), Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(angle(engine), Eigen::Vector3d::UnitX()))
                                         .toRotationMatrix();
    const ImpactResponse<double> r = resolve(c);
    const ImpactResponse<double> q =
        resolveImpact(1.0 / c.mass_a, Eigen::Vector3d(rotation * c.velocity_a), 1.0 / c.mass_b,
                      Eigen::Vector3d(rotation * c.velocity_b),
                      Eigen::Vector3d(rotation * c.normal), c.restitution);
    if (std::abs(r.approach_speed) < 1e-9) continue;  // approach/separate is decided by a sign
    const double scale = std::max(c.velocity_a.norm(), c.velocity_b.norm());
    ASSERT_EQ(q.approaching, r.approaching) << "case " << i;
    ASSERT_LE((q.velocity_a - rotation * r.velocity_a).norm(), 64 * kEps * scale) << "case " << i;
    ASSERT_LE((q.velocity_b - rotation * r.velocity_b).norm(), 64 * kEps * scale) << "case " << i;
    // J = (1 + e) mu (-d): d in either frame is off by rounding of order eps (|v_a| + |v_b|).
    const double mu = 1.0 / (1.0 / c.mass_a + 1.0 / c.mass_b);
    ASSERT_NEAR(q.normal_impulse, r.normal_impulse,
                2 * mu * 16 * kEps * (c.velocity_a.norm() + c.velocity_b.norm()))
        << "case " << i;
  }
}

TEST(ImpactProperties, SeparatingBodiesAreLeftUntouched) {
  ImpactGenerator generator(7);
  int separating = 0;
  for (int i = 0; i < kCases; ++i) {
    const RandomImpact c = generator.next();
    if ((c.velocity_b - c.velocity_a).dot(c.normal) < 0) continue;
    ++separating;
    const ImpactResponse<double> r = resolve(c);
    ASSERT_FALSE(r.approaching);
    ASSERT_EQ(r.velocity_a, c.velocity_a);
    ASSERT_EQ(r.velocity_b, c.velocity_b);
    ASSERT_EQ(r.normal_impulse, 0.0);
    ASSERT_EQ(r.energy_lost, 0.0);
  }
  EXPECT_GT(separating, kCases / 50) << "the generator must produce separating cases too";
}

}  // namespace
}  // namespace collision_response::core
