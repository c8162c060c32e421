// A body's free rotation (geometry/free_rotation.h): the angular velocity and the orientation of
// a torque-free body, against closed forms written here (isotropic, axisymmetric, separatrix)
// and against test/exact/free_rotation.py's 30-digit integration of Euler's equations and the
// quaternion kinematics (the asymmetric body on both sides of the separatrix, on it and near it,
// and the intermediate axis's flip); L (world) and the kinetic energy kept over many turns.
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/math/special_functions/ellint_1.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "geometry/free_rotation.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using Q = Eigen::Quaterniond;

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

FreeRotation make(const V& moments, const Q& q0, const V& w0) {
  const Expected<FreeRotation> made = FreeRotation::create(moments, q0, w0);
  EXPECT_TRUE(made.ok()) << (made.ok() ? "" : made.error().message());
  return made.value();
}

// The angle between two orientations (a quaternion and its negative are one orientation).
double angleBetween(const Q& a, const Q& b) { return a.angularDistance(b); }

// The world-frame angular momentum and twice the kinetic energy at `t`.
V momentumAt(const FreeRotation& r, const V& moments, double t) {
  return r.orientation(t) * moments.cwiseProduct(r.bodyAngularVelocity(t));
}
double twiceEnergyAt(const FreeRotation& r, const V& moments, double t) {
  const V w = r.bodyAngularVelocity(t);
  return w.dot(moments.cwiseProduct(w));
}

// q' = q (0, w) / 2 with w in the body frame: the orientation and the angular velocity agree
// (a central difference of step h, error O(h^2)).
void expectKinematicsAgree(const FreeRotation& r, double t, double tolerance) {
  const double h = 1e-4;
  const Q before = r.orientation(t - h);
  const Q after = r.orientation(t + h);
  // The turn from before to after, in the body frame at t, divided by 2h.
  const Eigen::AngleAxisd step(before.conjugate() * after);
  const V rate = step.axis() * step.angle() / (2.0 * h);
  const V expected = r.bodyAngularVelocity(t);
  EXPECT_LT((rate - expected).norm(), tolerance * (1.0 + expected.norm()))
      << "t " << t << ": from the orientation " << rate.transpose() << ", w "
      << expected.transpose();
}

TEST(FreeRotation, EachBadInputIsNamed) {
  const Q q0 = Q::Identity();
  const V w0(1.0, 2.0, 3.0);
  const auto field = [](const Expected<FreeRotation>& made) {
    return made.ok() ? std::string("accepted") : made.error().field;
  };
  EXPECT_EQ(field(FreeRotation::create(V(0.0, 1.0, 1.0), q0, w0)), "principal_moments.x");
  EXPECT_EQ(field(FreeRotation::create(V(1.0, -1.0, 1.0), q0, w0)), "principal_moments.y");
  EXPECT_EQ(field(FreeRotation::create(V(1.0, 1.0, kNan), q0, w0)), "principal_moments.z");
  const Expected<FreeRotation> flat = FreeRotation::create(V(1.0, 1.0, 2.5), q0, w0);
  EXPECT_EQ(field(flat), "principal_moments.z");
  EXPECT_NE(flat.error().reason.find("triangle inequality"), std::string::npos);
  EXPECT_EQ(field(FreeRotation::create(V(1.0, 2.0, 3.0), Q(0.0, 0.0, 0.0, 0.0), w0)),
            "orientation");
  EXPECT_EQ(field(FreeRotation::create(V(1.0, 2.0, 3.0), q0, V(1.0, kNan, 0.0))),
            "angular_velocity.y");
  EXPECT_EQ(field(FreeRotation::create(V(1e300, 2e300, 3e300), q0, V(1e10, 0.0, 0.0))),
            "angular_velocity");
  // A flat plate's moments (J_3 = J_1 + J_2) are a body's.
  EXPECT_EQ(field(FreeRotation::create(V(1.0, 2.0, 3.0), q0, w0)), "accepted");
}

TEST(FreeRotation, AtRestItStays) {
  const Q q0(0.48, 0.64, 0.36, 0.48);
  const FreeRotation r = make(V(2.0, 3.0, 4.0), q0, V::Zero());
  EXPECT_EQ(r.kind(), FreeRotation::Kind::kResting);
  EXPECT_EQ(angleBetween(r.orientation(7.0), q0.normalized()), 0.0);
  EXPECT_EQ(r.bodyAngularVelocity(7.0), V::Zero());
}

// A cube (J_1 = J_2 = J_3) spun about the world z at 2 rad/s: q(t) = (cos t, 0, 0, sin t) q0.
TEST(FreeRotation, AnIsotropicBodyTurnsAboutItsFixedSpin) {
  const Q q0 = Q(0.48, 0.64, 0.36, 0.48).normalized();
  const FreeRotation r = make(V(0.5, 0.5, 0.5), q0, V(0.0, 0.0, 2.0));
  EXPECT_EQ(r.kind(), FreeRotation::Kind::kIsotropic);
  for (const double t : {0.25, 1.0, 10.0, 1000.0}) {
    const Q expected = Q(std::cos(t), 0.0, 0.0, std::sin(t)) * q0;
    EXPECT_LT(angleBetween(r.orientation(t), expected), 8.0 * kEps * (1.0 + 2.0 * t)) << t;
    EXPECT_LT((r.angularVelocity(t) - V(0.0, 0.0, 2.0)).norm(), 4.0 * kEps) << t;
  }
}

// A cylinder's moments (J_t = 1 about x and y, J_s = 1.5 about its axis z), body w0 = (a, 0, c):
// Euler's equations give w(t) = (a cos(lambda t), a sin(lambda t), c), lambda = (J_s - J_t) /
// J_t c; L is fixed, so the symmetry axis R e_z precesses about L at M / J_t (L . R e_z = J_s c
// constant and w = L / J_t - lambda R e_z).
TEST(FreeRotation, AnAxisymmetricBodyPrecessesRegularly) {
  const double a = 0.75;
  const double c = 2.0;
  const V moments(1.0, 1.0, 1.5);
  const Q q0 = Q(0.48, 0.64, 0.36, 0.48).normalized();
  const V w0 = q0 * V(a, 0.0, c);
  const FreeRotation r = make(moments, q0, w0);
  EXPECT_EQ(r.kind(), FreeRotation::Kind::kAxisymmetric);
  const double lambda = (1.5 - 1.0) / 1.0 * c;
  const V momentum = q0 * V(a, 0.0, 1.5 * c);
  const double precession = momentum.norm() / 1.0;
  const V axis0 = q0 * V::UnitZ();
  for (const double t : {0.25, 1.0, 10.0, 100.0}) {
    const V w = r.bodyAngularVelocity(t);
    const double scale = 16.0 * kEps * (1.0 + lambda * t);
    EXPECT_NEAR(w.x(), a * std::cos(lambda * t), scale) << t;
    EXPECT_NEAR(w.y(), a * std::sin(lambda * t), scale) << t;
    EXPECT_NEAR(w.z(), c, scale) << t;
    const V axis = r.orientation(t) * V::UnitZ();
    const V expected = Eigen::AngleAxisd(precession * t, momentum.normalized()) * axis0;
    EXPECT_LT((axis - expected).norm(), 16.0 * kEps * (1.0 + precession * t)) << t;
    expectKinematicsAgree(r, t, 1e-7);
  }
  EXPECT_DOUBLE_EQ(r.period(), 2.0 * M_PI / lambda);
}

// Reference values from test/exact/free_rotation.py (30-digit integration).
struct Sample {
  double t;
  V w_body;
  Q q;  // (w, x, y, z)
};
struct Case {
  const char* name;
  V moments;
  Q q0;
  V w0_world;
  FreeRotation::Kind kind;
  std::vector<Sample> samples;
};

std::vector<Case> referenceCases() {
  const Q q0(0.48, 0.64, 0.36, 0.48);
  const Q id = Q::Identity();
  using K = FreeRotation::Kind;
  return {
      {"round the largest axis (M^2 - 2 E J_2 = 15.82)",
       V(2.0, 3.0, 4.0),
       q0,
       V(2.004, -0.12112000000000005, -0.5561600000000001),
       K::kAsymmetric,
       {{0.5, V(0.48826656899503465, -0.22831486329720797, 2.0184652885791947),
         Q(0.1575619877005344, 0.81348652284426858, 0.0065056576209849025, 0.55979601070525366)},
        {3.0, V(-0.42499978410708113, 0.35939798461489167, 2.0112962010220009),
         Q(-0.36271535528495954, -0.64217809638593922, -0.50667114300162422, -0.44646300676771036)},
        {10.0, V(-0.19148119989855907, -0.56666856872473887, 1.993321982259087),
         Q(0.0073992168919231576, -0.74155651289164304, 0.29562972409314489,
           -0.60219785453784518)}}},
      {"round the smallest axis (M^2 - 2 E J_2 = -7.64)",
       V(2.0, 3.0, 4.0),
       q0,
       V(0.2720000000000001, 1.7838399999999999, 1.04112),
       K::kAsymmetric,
       {{0.5, V(2.0337143147663497, 0.26205873620096822, -0.39748831057375983),
         Q(0.11767041397011241, 0.70826226974337477, 0.64543785225244214, 0.26063040845960411)},
        {3.0, V(1.9552857172763311, -0.69700096969342675, 0.039637332054624312),
         Q(-0.13329751737696462, -0.69004442422477723, -0.18227861364389312, -0.68763723827719935)},
        {10.0, V(1.9731669312029799, -0.62621855780764433, -0.19155643867145983),
         Q(0.38126612859064144, -0.65326929892513109, -0.61421825628801518, 0.22496954441408795)}}},
      {"on the separatrix (M^2 = 2 E J_2 exactly)",
       V(3.0, 5.0, 6.0),
       id,
       V(1.0, 0.5, 1.0),
       K::kSeparatrix,
       {{0.5, V(0.89868731786456783, 0.77217225311254263, 0.89868731786456783),
         Q(0.9313177789355475, 0.22917485730368355, 0.15653335014642624, 0.23584611446943806)},
        {3.0, V(0.34462069590289591, 1.3550741074641367, 0.34462069590289591),
         Q(-0.49284860499849979, 0.052385167821459059, 0.60089027441080915, 0.62712592424636121)},
        {10.0, V(0.012537672092106369, 1.431683293260531, 0.012537672092106369),
         Q(0.52815917269554969, 0.52156568577666242, 0.6282152731383465, 0.23315808867286819)}}},
      {"near the separatrix (M^2 - 2 E J_2 = 1.2e-8)",
       V(3.0, 5.0, 6.0),
       id,
       V(1.0, 0.5, 1.000000001),
       K::kAsymmetric,
       {{0.5, V(0.89868731773659724, 0.77217225338063047, 0.8986873188493314),
         Q(0.93131777887558681, 0.22917485727929984, 0.15653335017512976, 0.23584611471085622)},
        {3.0, V(0.34462069445525327, 1.3550741081268294, 0.3446206973569945),
         Q(-0.49284860573064687, 0.052385166970323225, 0.60089027352451029, 0.62712592459129607)},
        {10.0, V(0.012537632193716576, 1.4316832938894535, 0.012537711953346384),
         Q(0.52815918062489431, 0.52156567076155569, 0.62821527576615028, 0.23315809721892248)}}},
      // The angle about L's closed form cancels where a -> 1 (1 - a^2 = 1e-9 here) and where a
      // is small (0.026): its factor keeps the rounding (free_rotation.h).
      {"near a spin about the largest axis (M^2 - 2 E J_2 = 16.0)",
       V(2.0, 3.0, 4.0),
       q0,
       V(1.920028, -0.53747984, -0.15686912000000008),
       K::kAsymmetric,
       {{0.5, V(0.00013105933555577461, -2.0766979035135239e-5, 2.0000000008970688),
         Q(0.19110329947954912, 0.73426578404991521, 0.0091034355140061107, 0.65134508116929491)},
        {3.0, V(-0.00012229274907345767, 5.8246413612762513e-5, 2.0000000006194396),
         Q(-0.5429046478479719, -0.58279255054747736, -0.44674212360124488, -0.40746639293527718)},
        {10.0, V(-2.1375259982498609e-5, -0.00015074525204545594, 1.9999999988071128),
         Q(-0.14163050293164441, -0.73285827848230587, 0.046115203839220495,
           -0.66387719668184689)}}},
      {"nearly across the axis of a nearly symmetric body (M^2 - 2 E J_2 = 0.0031244)",
       V(2.0, 2.0002, 3.5),
       q0,
       V(0.5888000000000001, 1.8351359999999999, 0.5352480000000001),
       K::kAsymmetric,
       {{0.5, V(1.9998734701698465, 0.022497115109208656, 0.029999357236542553),
         Q(0.1097668573627381, 0.7932094296897816, 0.5424337136547767, 0.25403878437476324)},
        {3.0, V(1.9954488799445439, 0.13484944907681424, 0.029976897527003732),
         Q(-0.58401672298097308, -0.55498856529297178, -0.31047234032464052, -0.50449884595106334)},
        {10.0, V(1.9498831664635839, 0.4449294758978413, 0.029747531905949838),
         Q(-0.068569032494654867, -0.7362796283405609, -0.64107541701098825,
           -0.20545779707185609)}}},
  };
}

TEST(FreeRotation, AnAsymmetricBodyFollowsEulersEquations) {
  for (const Case& c : referenceCases()) {
    SCOPED_TRACE(c.name);
    const FreeRotation r = make(c.moments, c.q0, c.w0_world);
    EXPECT_EQ(r.kind(), c.kind);
    for (const Sample& s : c.samples) {
      const V w = r.bodyAngularVelocity(s.t);
      const double dw = (w - s.w_body).norm() / s.w_body.norm();
      const double dq = angleBetween(r.orientation(s.t), s.q);
      // Measured: at most 2.3e-15 and 8.5e-15 (t = 10; 5.1e-15 by the quadrature before the
      // closed form).
      EXPECT_LT(dw, 8.0 * kEps * (1.0 + s.t)) << "t " << s.t << ": " << w.transpose();
      EXPECT_LT(dq, 8.0 * kEps * (1.0 + s.t)) << "t " << s.t;
      expectKinematicsAgree(r, s.t, 1e-7);
    }
  }
}

// L (world) and the kinetic energy are kept: over 1,000 s (up to ~350 turns of the body-frame
// angular velocity) within a few ulps per turn (L's direction drifts with the angle about it,
// whose error grows with the turns; the energy's error does not grow).
TEST(FreeRotation, AngularMomentumAndEnergyAreKept) {
  std::vector<Case> cases = referenceCases();
  cases.push_back({"cylinder",
                   V(1.0, 1.0, 1.5),
                   Q(0.48, 0.64, 0.36, 0.48),
                   V(0.3, -2.0, 0.5),
                   FreeRotation::Kind::kAxisymmetric,
                   {}});
  cases.push_back({"flip",
                   V(2.0, 3.0, 4.0),
                   Q::Identity(),
                   V(1e-6, 2.0, 1e-6),
                   FreeRotation::Kind::kAsymmetric,
                   {}});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const FreeRotation r = make(c.moments, c.q0, c.w0_world);
    const V momentum = momentumAt(r, c.moments, 0.0);
    const double energy = twiceEnergyAt(r, c.moments, 0.0);
    const double rate = c.w0_world.norm();
    double worst_l = 0.0;
    double worst_e = 0.0;
    for (double t = 0.0; t <= 1000.0; t += 7.25) {
      const double turns = 1.0 + rate * t / (2.0 * M_PI);
      const double dl = (momentumAt(r, c.moments, t) - momentum).norm() / momentum.norm();
      const double de = std::abs(twiceEnergyAt(r, c.moments, t) - energy) / energy;
      worst_l = std::max(worst_l, dl / (kEps * turns));
      worst_e = std::max(worst_e, de / kEps);
    }
    // Measured: L within 1.1 ulps per turn, the energy within 2.6 ulps.
    EXPECT_LT(worst_l, 4.0) << "ulps per turn";
    EXPECT_LT(worst_e, 8.0) << "ulps";
  }
}

// The same body with its axes named in another order (x' = y, y' = z, z' = x: moments (3, 4, 2),
// q0' = q0 P, P taking the new axes to the old) turns the same way: q'(t) = q(t) P.
TEST(FreeRotation, TheMomentsMayComeInAnyOrder) {
  const Case c = referenceCases()[0];
  Eigen::Matrix3d p;
  p << 0, 0, 1,  // the new x, y and z (columns) in the old body frame
      1, 0, 0,   //
      0, 1, 0;
  const Q turn(p);
  const FreeRotation r = make(V(3.0, 4.0, 2.0), c.q0 * turn, c.w0_world);
  for (const Sample& s : c.samples) {
    EXPECT_LT(angleBetween(r.orientation(s.t), s.q * turn), 8.0 * kEps * (1.0 + s.t)) << s.t;
    EXPECT_LT((p * r.bodyAngularVelocity(s.t) - s.w_body).norm(), 8.0 * kEps * (1.0 + s.t)) << s.t;
  }
}

// On the separatrix (J = (3, 5, 6), w0 = (1, 1/2, 1): 2E = 41/4, M^2 = 205/4 = 2 E J_2) the
// elliptic functions become sn = tanh, cn = dn = sech (Landau, section 37): w_1 = A_1 sech u,
// w_2 = A_2 tanh u, w_3 = A_3 sech u, u = omega t + u0, with A_1^2 = (2 E J_3 - M^2) / (J_1
// (J_3 - J_1)) = 41/36, A_3^2 = (M^2 - 2 E J_1) / (J_3 (J_3 - J_1)) = 41/36, A_2 = M / J_2,
// omega^2 = (J_3 - J_2)(M^2 - 2 E J_1) / (J_1 J_2 J_3) = 41/180 and tanh u0 = w_2(0) / A_2: the
// body tends to turning about its middle axis at M / J_2, never reaching it.
TEST(FreeRotation, OnTheSeparatrixItIsTheHyperbolicLimit) {
  const FreeRotation r = make(V(3.0, 5.0, 6.0), Q::Identity(), V(1.0, 0.5, 1.0));
  ASSERT_EQ(r.kind(), FreeRotation::Kind::kSeparatrix);
  const double a1 = std::sqrt(41.0 / 36.0);
  const double a2 = std::sqrt(205.0 / 4.0) / 5.0;
  const double omega = std::sqrt(41.0 / 180.0);
  const double u0 = std::atanh(0.5 / a2);
  for (const double t : {0.5, 3.0, 10.0, 40.0, -5.0}) {
    const double u = omega * t + u0;
    const V expected(a1 / std::cosh(u), a2 * std::tanh(u), a1 / std::cosh(u));
    EXPECT_LT((r.bodyAngularVelocity(t) - expected).norm(), 8.0 * kEps * (1.0 + std::abs(t))) << t;
  }
  EXPECT_EQ(r.period(), std::numeric_limits<double>::infinity());
}

// Spun about its middle axis exactly it turns steadily; perturbed by 1e-6 rad/s it flips
// (Dzhanibekov's effect): J = (2, 3, 4), w0 = (1e-6, 2, 1e-6). Landau's solution gives w_2 =
// A_2 sn u, whose zeros come every 2K(m) / omega, the period T = 4K(m) / omega, with m1 = 1 - m =
// (J_3 - J_1)(M^2 - 2 E J_2) / ((J_3 - J_2)(M^2 - 2 E J_1)), M^2 - 2 E J_2 = J_1 (J_1 - J_2)
// w_1^2 + J_3 (J_3 - J_2) w_3^2 = 2e-12, M^2 - 2 E J_1 = J_2 (J_2 - J_1) w_2^2 + J_3 (J_3 - J_1)
// w_3^2 = 12 + 8e-12 and omega^2 = (J_3 - J_2)(M^2 - 2 E J_1) / (J_1 J_2 J_3); K(m) =
// pi / (2 agm(1, sqrt(m1))) (the arithmetic-geometric mean, written here). The integration in
// test/exact/free_rotation.py finds w_2's zeros at 23.521885368606051 and 68.07275514525752, a
// period of 89.101739553302938.
TEST(FreeRotation, TheIntermediateAxisFlipsAtTheEllipticPeriod) {
  const V moments(2.0, 3.0, 4.0);
  EXPECT_EQ(make(moments, Q::Identity(), V(0.0, 2.0, 0.0)).kind(),
            FreeRotation::Kind::kIsotropic);  // steady
  const FreeRotation r = make(moments, Q::Identity(), V(1e-6, 2.0, 1e-6));
  ASSERT_EQ(r.kind(), FreeRotation::Kind::kAsymmetric);
  const double m1 = 2.0 * 2e-12 / (1.0 * (12.0 + 8e-12));
  double a = 1.0;
  double b = std::sqrt(m1);
  for (int i = 0; i < 10; ++i) {
    const double mean = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = mean;
  }
  const double k = M_PI / (2.0 * a);
  const double omega = std::sqrt((12.0 + 8e-12) / 24.0);
  const double period = 4.0 * k / omega;
  EXPECT_NEAR(period, 89.101739553302938, 1e-13 * period);  // the formula and the integration
  EXPECT_NEAR(r.period(), period, 4.0 * kEps * period);
  const double first = 23.521885368606051;
  const double second = 68.07275514525752;
  EXPECT_NEAR(second - first, period / 2.0, 1e-13 * period);
  // w_2 vanishes at the integration's zeros (its rate there is |J_3 - J_1| / J_2 |w_1 w_3| ~ 1.4).
  EXPECT_LT(std::abs(r.bodyAngularVelocity(first).y()), 1e-13);
  EXPECT_LT(std::abs(r.bodyAngularVelocity(second).y()), 1e-13);
  // And at the second zero the whole state agrees with the integration's.
  const V w_ref(1.732050807569166, -2.4920467681798255e-39, 1.2247448713919973);
  const Q q_ref(-0.45685250225142987, 0.061416954664585978, -0.53970887963406796,
                -0.70443457759431046);
  EXPECT_LT((r.bodyAngularVelocity(second) - w_ref).norm(), 1e-13);
  // Measured: 7e-15 and 0 for w_2, 1.9e-13 rad after 136 rad turned (the angle about L).
  EXPECT_LT(angleBetween(r.orientation(second), q_ref), 16.0 * kEps * (1.0 + 2.0 * second));
  // Half a period on, w_2 is the opposite of what it was: the flip.
  EXPECT_NEAR(r.bodyAngularVelocity(period / 2.0).y(), -2.0, 1e-9);
  EXPECT_NEAR(r.bodyAngularVelocity(period).y(), 2.0, 1e-9);
}

// The motion is the same however small or large the spin (its parameters are computed for the
// spin scaled by a power of two, exactly): w0 and w0 * 2^-600 give w(t) and q(t 2^600) that
// agree to the bit after scaling, where the squares of w0 * 2^-600 underflow.
TEST(FreeRotation, ATinySpinIsTheSameMotionSlowed) {
  const Case c = referenceCases()[0];
  const FreeRotation fast = make(c.moments, c.q0, c.w0_world);
  const FreeRotation slow = make(c.moments, c.q0, std::ldexp(1.0, -600) * c.w0_world);
  for (const Sample& s : c.samples) {
    const double t_slow = std::ldexp(s.t, 600);
    EXPECT_EQ(std::ldexp(1.0, 600) * slow.bodyAngularVelocity(t_slow),
              fast.bodyAngularVelocity(s.t));
    EXPECT_EQ(angleBetween(slow.orientation(t_slow), fast.orientation(s.t)), 0.0);
  }
}

// Started again from its state at any time (before or after), it goes on as it was: the
// motion from (q(t1), w(t1)) at t2 - t1 is the first motion's at t2. Away from the separatrix
// only: near it the motion itself magnifies the restart's rounding (nearby states part, as the
// intermediate axis's flip shows; measured 1e-10 after 34 s on and near it).
TEST(FreeRotation, StartedAgainFromItsStateItGoesOnAsItWas) {
  const std::vector<Case> all = referenceCases();
  for (const Case& c : {all[0], all[1]}) {
    SCOPED_TRACE(c.name);
    const FreeRotation r = make(c.moments, c.q0, c.w0_world);
    for (const double t1 : {-7.5, 2.0, 31.0}) {
      const FreeRotation again = make(c.moments, r.orientation(t1), r.angularVelocity(t1));
      for (const double t2 : {-3.0, 0.0, 4.5, 20.0}) {
        const double tolerance = 16.0 * kEps * (1.0 + std::abs(t1) + std::abs(t2));
        EXPECT_LT(angleBetween(again.orientation(t2 - t1), r.orientation(t2)), tolerance)
            << t1 << " " << t2;
        EXPECT_LT((again.bodyAngularVelocity(t2 - t1) - r.bodyAngularVelocity(t2)).norm(),
                  tolerance * c.w0_world.norm())
            << t1 << " " << t2;
      }
    }
  }
}

// 2,000 random bodies (moments on the triangle inequality's edge included, spins exactly along
// an axis included, a few nearly symmetric), at random times up to 100 s: every answer finite,
// L and the energy kept within 1e-14 (relative), q of unit length.
TEST(FreeRotation, RandomBodiesKeepTheirMomentumAndEnergy) {
  std::mt19937_64 random(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> positive(0.1, 1.0);
  for (int n = 0; n < 2000; ++n) {
    V moments(positive(random), positive(random), positive(random));
    if (n % 10 == 1) moments.z() = moments.x() + moments.y();         // a flat plate
    if (n % 10 == 2) moments.y() = std::nextafter(moments.x(), 2.0);  // nearly symmetric
    for (int i = 0; i < 3; ++i) {
      const double others = moments.sum() - moments[i];
      if (moments[i] > others) moments[i] = others;
    }
    V w0(unit(random), unit(random), unit(random));
    if (n % 10 == 3) w0 = V::Unit(n % 3) * 3.0;  // along a body axis (q0 = 1 below)
    if (n % 10 == 4) w0[n % 3] = 0.0;
    const Q q0 = n % 10 == 3
                     ? Q::Identity()
                     : Q(unit(random), unit(random), unit(random), unit(random)).normalized();
    const FreeRotation r = make(moments, q0, w0);
    const V momentum = momentumAt(r, moments, 0.0);
    const double energy = twiceEnergyAt(r, moments, 0.0);
    for (int k = 0; k < 3; ++k) {
      const double t = 100.0 * positive(random) * (k == 1 ? -1.0 : 1.0);
      const Q q = r.orientation(t);
      ASSERT_TRUE(q.coeffs().allFinite())
          << n << " " << moments.transpose() << " | " << w0.transpose();
      EXPECT_NEAR(q.norm(), 1.0, 4.0 * kEps);
      // Measured: at most 1.6e-15 and 7.8e-16.
      EXPECT_LT((momentumAt(r, moments, t) - momentum).norm(), 1e-14 * momentum.norm())
          << n << " " << moments.transpose() << " | " << w0.transpose() << " t " << t;
      EXPECT_LT(std::abs(twiceEnergyAt(r, moments, t) - energy), 1e-14 * energy)
          << n << " " << moments.transpose() << " | " << w0.transpose() << " t " << t;
    }
  }
}

}  // namespace
}  // namespace collision_response::core
