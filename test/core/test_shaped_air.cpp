// A shaped body through air (issue 42, step 4: "drag and Magnus as for balls where the scene
// asks"): quadratic drag and the Magnus force on a box, a cylinder, a capsule or a mesh in flight,
// on the area A of its mean cross-section (a quarter of its surface, Cauchy's formula: pi r^2 for
// a sphere, as a ball's), its turning its own torque-free rotation (the air puts no torque on
// it). Every number here is a closed form or the test's own integration of Euler's equations.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <vector>

#include "collision_response/core/mass_properties.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/prediction.h"
#include "collision_response/core/scene.h"
#include "geometry/air_flight.h"
#include "quadrature.h"
#include "scene_builders.h"
#include "shaped_scenes.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using shaped_scenes::floorScene;
using shaped_scenes::kG;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDensity = 1.204;

/// A cube of half size 0.05 m and mass `m` over floorScene's floor, with `effects` besides
/// gravity (drag, magnus with spin), C_d and C_L as given, integrated to 1e-12.
Scene airyScene(double e, double m, bool gravity, bool drag, bool magnus, double cd = 1.05,
                double cl = 0.3) {
  Scene scene = floorScene(e, V(0.05, 0.05, 0.05), m);
  scene.effects.gravity = gravity;
  scene.effects.drag = drag;
  scene.effects.magnus = magnus;
  scene.effects.spin = magnus;
  scene.air_density = kDensity;
  scene.flight_integration_tolerance = 1e-12;
  scene.bodies[0].drag_coefficient = cd;
  scene.bodies[0].lift_coefficient = cl;
  return scene;
}

PredictionRequest request(const Scene& scene, const V& position, const V& velocity,
                          const V& angular_velocity, double horizon, double period) {
  PredictionRequest made;
  made.body = scene.bodies[0];
  made.state.position = position;
  made.state.velocity = velocity;
  made.state.angular_velocity = angular_velocity;
  made.horizon = horizon;
  made.max_impacts = 8;
  made.sample_period = period;
  made.effects = scene.effects;
  return made;
}

// The area the air acts on is a quarter of the surface: pi r^2 for a sphere, 2 (x y + y z + z x)
// for a box of half sizes x, y, z, pi r (r + 2 h) / 2 for a cylinder and pi r (r + h) for a
// capsule (h its half length), a mesh's hull's surface / 4. Cauchy's formula itself is checked
// on the cylinder by the test's own quadrature of its shadow over every direction: seen at theta
// to its axis, pi r^2 |cos theta| + 4 r h sin theta, averaged over the sphere.
TEST(ShapedAir, TheAreaTheAirActsOnIsAQuarterOfTheSurface) {
  EXPECT_NEAR(meanCrossSection(Sphere{V::Zero(), 0.1}), kPi * 0.01, 1e-17);
  EXPECT_NEAR(meanCrossSection(Cuboid{V(0.05, 0.04, 0.03)}), 2 * (0.002 + 0.0012 + 0.0015), 1e-17);
  EXPECT_NEAR(meanCrossSection(Cylinder{0.05, 0.1}), kPi * (2 * 0.0025 + 2 * 0.05 * 0.2) / 4,
              1e-17);
  EXPECT_NEAR(meanCrossSection(Capsule{0.05, 0.1}), kPi * (4 * 0.0025 + 2 * 0.05 * 0.2) / 4, 1e-17);
  Mesh cube;
  cube.triangles = scene_builders::cubeMesh(V(0.05, 0.05, 0.05));
  EXPECT_NEAR(meanCrossSection(cube), 6 * 0.01 / 4, 1e-16);
  const double r = 0.05, h = 0.1;
  const double mean_shadow = quadrature::gaussLegendre(
      [&](double c) {  // c = cos theta, uniform over the sphere on [-1, 1]
        return 0.5 * (kPi * r * r * std::abs(c) + 4 * r * h * std::sqrt(1 - c * c));
      },
      -1.0, 1.0, 4000);
  EXPECT_NEAR(meanCrossSection(Cylinder{r, h}), mean_shadow, 1e-9);
}

// A cube dropped flat from rest through air (C_d = 1.05, A = 6 (2 a)^2 / 4): it falls by
// dv/dt = g - k v^2, k = rho C_d A / (2 m), so v = v_t tanh(g t / v_t), v_t = sqrt(g / k), and its
// centre has fallen (v_t^2 / g) ln cosh(g t / v_t): its lowest face meets the floor after a fall d
// at t = (v_t / g) acosh(exp(g d / v_t^2)), at v_t sqrt(1 - exp(-2 g d / v_t^2)), on its four
// corners at once, and leaves at u = e times that. Up, v' = -g - k v^2: it rises for
// (v_t / g) atan(u / v_t) by H = (v_t^2 / 2 g) ln(1 + u^2 / v_t^2), and falls H in
// (v_t / g) acosh(exp(g H / v_t^2)), landing again at v_t u / sqrt(v_t^2 + u^2). The prediction
// and the monitor both say so; before, drag with a shaped body was refused.
TEST(ShapedAir, ACubeDroppedFlatThroughAirLandsAtTheTanhLawsInstant) {
  const double m = 0.1, e = 0.5, cd = 1.05, a = 0.05, z0 = 2.0;
  const double k = kDensity * cd * (6 * 4 * a * a / 4) / (2 * m);
  const double vt = std::sqrt(kG / k), d = z0 - a;
  const double landing = vt / kG * std::acosh(std::exp(kG * d / (vt * vt)));
  const double speed = vt * std::sqrt(-std::expm1(-2 * kG * d / (vt * vt)));
  ASSERT_GT(landing, std::sqrt(2 * d / kG) + 0.01) << "drag makes a difference worth testing";
  const Scene scene = airyScene(e, m, true, true, false, cd);
  ASSERT_TRUE(validateScene(scene, "s").ok()) << validateScene(scene, "s").error().message();

  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{},
                                         request(scene, V(0, 0, z0), V::Zero(), V::Zero(), 1.5, 0));
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_GE(prediction->impacts.size(), 4u);
  for (std::size_t c = 0; c < 4; ++c) {
    const ImpactRecord& corner = prediction->impacts[c];
    EXPECT_NEAR(corner.time, landing, 1e-9) << c;
    EXPECT_NEAR(corner.velocity_a_before.z(), -speed, 1e-9) << c;
    EXPECT_NEAR(corner.velocity_a_after.z(), e * speed, 1e-9) << c;
    EXPECT_NEAR(corner.angular_velocity_a_after.norm(), 0.0, 1e-12) << c;
  }
  const double u = e * speed;
  const double rise = vt / kG * std::atan(u / vt);
  const double height = vt * vt / (2 * kG) * std::log1p(u * u / (vt * vt));
  const double again = landing + rise + vt / kG * std::acosh(std::exp(kG * height / (vt * vt)));
  ASSERT_GE(prediction->impacts.size(), 8u);
  for (std::size_t c = 4; c < 8; ++c) {
    const ImpactRecord& corner = prediction->impacts[c];
    EXPECT_NEAR(corner.time, again, 1e-9) << c;
    EXPECT_NEAR(corner.velocity_a_before.z(), -vt * u / std::hypot(vt, u), 1e-9) << c;
  }

  MonitorSettings settings;
  settings.body_timeout = INFINITY;
  ImpactMonitor monitor(scene, settings);
  BodyStateSample state;
  state.position = V(0, 0, z0);
  monitor.step(0.0, {state});
  std::vector<ImpactRecord> impacts;
  for (int step = 1; step <= 80; ++step) {
    const StepReport report = monitor.advance(0.01 * step, {});
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
    EXPECT_TRUE(report.unmodelled.empty()) << report.unmodelled.front().what;
  }
  ASSERT_GE(impacts.size(), 4u);
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_NEAR(impacts[c].time, landing, 1e-9) << c;
    EXPECT_NEAR(impacts[c].velocity_a_before.z(), -speed, 1e-9) << c;
  }
}

// A cube spinning steadily about z (an isotropic body turns at a constant w), thrown along x with
// no gravity and no drag: the Magnus force lift v^2 along w x v (lift = rho C_L A / (2 m)) bends
// it onto a circle of radius 1 / lift towards +y, at its speed, as a ball's: x = R sin(v t / R),
// y = R (1 - cos(v t / R)).
TEST(ShapedAir, ASpinningCubeCirclesByMagnusAlone) {
  const double m = 0.05, cl = 0.3, a = 0.05, v = 3.0;
  const double lift = kDensity * cl * (6 * a * a) / (2 * m), radius = 1 / lift;
  const Scene scene = airyScene(0.5, m, false, false, true, 0.0, cl);
  const auto prediction =
      predictImpacts(scene, nullptr, MonitorSettings{},
                     request(scene, V(0, 0, 5), V(v, 0, 0), V(0, 0, 20), 1.0, 0.1));
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_TRUE(prediction->impacts.empty());
  ASSERT_EQ(prediction->samples.size(), 11u);
  for (const BodyStateSample& sample : prediction->samples) {
    const double phi = v * sample.time / radius;
    EXPECT_NEAR(sample.position.x(), radius * std::sin(phi), 1e-9) << sample.time;
    EXPECT_NEAR(sample.position.y(), radius * (1 - std::cos(phi)), 1e-9) << sample.time;
    EXPECT_NEAR(sample.position.z(), 5.0, 1e-12) << sample.time;
    EXPECT_NEAR(sample.velocity.norm(), v, 1e-9) << sample.time;
  }
}

/// The test's own flight of a box tumbling through air: Euler's equations for w in the body's
/// frame (principal moments j), the orientation by q' = q (0, w) / 2, and the centre by
/// v' = g - k |v| v + l |v| (w_world / |w_world|) x v, by classical Runge-Kutta in long double.
struct TumblingReference {
  using L = long double;
  std::array<L, 3> j{};
  L k = 0, l = 0, g = 0;
  // x, y, z, vx, vy, vz, wx, wy, wz (body), qw, qx, qy, qz
  using State = std::array<L, 13>;

  State rate(const State& s) const {
    State d{};
    const L w[3] = {s[6], s[7], s[8]};
    d[6] = (j[1] - j[2]) * w[1] * w[2] / j[0];
    d[7] = (j[2] - j[0]) * w[2] * w[0] / j[1];
    d[8] = (j[0] - j[1]) * w[0] * w[1] / j[2];
    const L qw = s[9], qx = s[10], qy = s[11], qz = s[12];
    d[9] = 0.5L * (-qx * w[0] - qy * w[1] - qz * w[2]);
    d[10] = 0.5L * (qw * w[0] + qy * w[2] - qz * w[1]);
    d[11] = 0.5L * (qw * w[1] + qz * w[0] - qx * w[2]);
    d[12] = 0.5L * (qw * w[2] + qx * w[1] - qy * w[0]);
    // w in the world: R(q) w.
    const L ww[3] = {(1 - 2 * (qy * qy + qz * qz)) * w[0] + 2 * (qx * qy - qw * qz) * w[1] +
                         2 * (qx * qz + qw * qy) * w[2],
                     2 * (qx * qy + qw * qz) * w[0] + (1 - 2 * (qx * qx + qz * qz)) * w[1] +
                         2 * (qy * qz - qw * qx) * w[2],
                     2 * (qx * qz - qw * qy) * w[0] + 2 * (qy * qz + qw * qx) * w[1] +
                         (1 - 2 * (qx * qx + qy * qy)) * w[2]};
    const L spin = std::sqrt(ww[0] * ww[0] + ww[1] * ww[1] + ww[2] * ww[2]);
    const L v[3] = {s[3], s[4], s[5]};
    const L speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    const L cross[3] = {ww[1] * v[2] - ww[2] * v[1], ww[2] * v[0] - ww[0] * v[2],
                        ww[0] * v[1] - ww[1] * v[0]};
    for (int i = 0; i < 3; ++i) {
      d[i] = v[i];
      d[3 + i] = -k * speed * v[i] + l * speed * cross[i] / spin;
    }
    d[5] -= g;
    return d;
  }

  State flown(State s, L duration, int steps) const {
    const L h = duration / steps;
    for (int n = 0; n < steps; ++n) {
      const auto along = [&](const State& from, const State& slope, L by) {
        State out = from;
        for (std::size_t i = 0; i < out.size(); ++i) out[i] += by * slope[i];
        return out;
      };
      const State k1 = rate(s), k2 = rate(along(s, k1, h / 2)), k3 = rate(along(s, k2, h / 2)),
                  k4 = rate(along(s, k3, h));
      for (std::size_t i = 0; i < s.size(); ++i) {
        s[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
      }
    }
    return s;
  }
};

// A box of three different sides (no steady turn: w(t) wanders by Euler's equations) thrown up
// through air with gravity, drag and the Magnus force of its own turning: its centre, velocity
// and orientation after 0.6 s are those of the test's own integration of the whole system, to
// 1e-9. Flying it with its first w throughout (a ball's constant spin) misses by most of a
// millimetre, 1e5 times that.
TEST(ShapedAir, ATumblingBoxFliesByTheMagnusForceOfItsOwnTurning) {
  const V half(0.08, 0.04, 0.02);
  const double m = 0.2, cd = 1.05, cl = 0.4, duration = 0.6;
  Scene scene = airyScene(0.5, m, true, true, true, cd, cl);
  scene.bodies[0].size = 2 * half;
  const double area = 2 * (half.x() * half.y() + half.y() * half.z() + half.z() * half.x());
  TumblingReference reference;
  reference.j = {m * (half.y() * half.y() + half.z() * half.z()) / 3,
                 m * (half.x() * half.x() + half.z() * half.z()) / 3,
                 m * (half.x() * half.x() + half.y() * half.y()) / 3};
  reference.k = kDensity * cd * area / (2 * m);
  reference.l = kDensity * cl * area / (2 * m);
  reference.g = kG;
  const V w0(2.0, 9.0, 1.0), v0(2.0, 1.0, 4.0), c0(0, 0, 3);
  const TumblingReference::State end = reference.flown(
      {c0.x(), c0.y(), c0.z(), v0.x(), v0.y(), v0.z(), w0.x(), w0.y(), w0.z(), 1, 0, 0, 0},
      duration, 60000);
  const auto prediction =
      predictImpacts(scene, nullptr, MonitorSettings{}, request(scene, c0, v0, w0, duration, 0));
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_TRUE(prediction->impacts.empty());
  const BodyStateSample& last = prediction->final_state;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(last.position[i], static_cast<double>(end[static_cast<std::size_t>(i)]), 1e-9) << i;
    EXPECT_NEAR(last.velocity[i], static_cast<double>(end[static_cast<std::size_t>(3 + i)]), 1e-9)
        << i;
  }
  const Eigen::Quaterniond q(static_cast<double>(end[9]), static_cast<double>(end[10]),
                             static_cast<double>(end[11]), static_cast<double>(end[12]));
  EXPECT_NEAR(q.angularDistance(last.orientation), 0.0, 1e-9);
  // The same throw with w held at its first value (a ball's flight) lands elsewhere.
  TumblingReference constant = reference;
  constant.j = {1, 1, 1};  // isotropic: w keeps its first value
  const TumblingReference::State held = constant.flown(
      {c0.x(), c0.y(), c0.z(), v0.x(), v0.y(), v0.z(), w0.x(), w0.y(), w0.z(), 1, 0, 0, 0},
      duration, 60000);
  EXPECT_GT(
      std::hypot(static_cast<double>(held[0] - end[0]), static_cast<double>(held[1] - end[1])),
      5e-4);
}

// A shaped body's air is checked at its keys as a ball's, its area named: a C_d of 1e300 on a box
// is refused at bodies[0]/drag_coefficient, the message giving the mean cross-section.
// A flight given its spin as a function of time (a tumbling body's torque-free rotation) answers
// that spin at each instant, not its first: before, angularVelocity returned w(start) for ever.
TEST(ShapedAir, AFlightGivenItsSpinAsAFunctionAnswersItAtEachInstant) {
  const auto spin = [](double t) { return V(std::cos(3 * t), std::sin(3 * t), 0.5); };
  const AirFactors air{0.01, 0.002};
  const AirFlight flight(0.0, V::Zero(), V(1, 0, 0), spin, V(0, 0, -kG), air, 1e-9);
  for (const double t : {0.0, 0.1, 0.7}) EXPECT_EQ(flight.angularVelocity(0, t), spin(t)) << t;
  const AirFlight steady(0.0, V::Zero(), V(1, 0, 0), V(0, 0, 2), V(0, 0, -kG), air, 1e-9);
  EXPECT_EQ(steady.angularVelocity(0, 0.7), V(0, 0, 2));
}

TEST(ShapedAir, AirTooStiffForAShapedBodyIsRefusedAtItsKey) {
  Scene scene = airyScene(0.5, 0.1, true, true, false, 1e300);
  const Status refused = validateScene(scene, "s");
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().field, "s/bodies[0]/drag_coefficient");
  EXPECT_NE(refused.error().reason.find("mean cross-section 0.015 m^2"), std::string::npos)
      << refused.error().reason;
}

// A box thrown at 1e50 m/s through air: its flight stalls at its start and is held there, and the
// monitor says so once (StepReport::stalled), the prediction in its message, as for a ball.
TEST(ShapedAir, AShapedFlightThatStallsIsReportedOnce) {
  const Scene scene = airyScene(0.5, 0.1, true, true, false);
  MonitorSettings settings;
  settings.body_timeout = INFINITY;
  ImpactMonitor monitor(scene, settings);
  BodyStateSample state;
  state.position = V(0, 0, 1);
  state.velocity = V(1e50, 0, 0);
  std::vector<StalledFlight> stalled = monitor.step(0.0, {state}).stalled;
  for (int k = 1; k <= 10; ++k) {
    const StepReport report = monitor.advance(0.01 * k, {});
    stalled.insert(stalled.end(), report.stalled.begin(), report.stalled.end());
  }
  ASSERT_EQ(stalled.size(), 1u);
  EXPECT_EQ(stalled[0].body, 0u);
  EXPECT_EQ(stalled[0].stalled, 0.0);
  EXPECT_EQ(monitor.predictedState(0, 0.1)->first, V(0, 0, 1));
  // The prediction says so in its message, the box held where it was.
  const auto prediction =
      predictImpacts(scene, nullptr, MonitorSettings{},
                     request(scene, V(0, 0, 1), V(1e50, 0, 0), V::Zero(), 1, 0));
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_TRUE(prediction->cut_short);
  EXPECT_NE(prediction->message.find("the flight through air stalled at +0 s"), std::string::npos)
      << prediction->message;
  EXPECT_EQ(prediction->final_state.position, V(0, 0, 1));
  EXPECT_TRUE(prediction->impacts.empty());
}

}  // namespace
}  // namespace collision_response::core
