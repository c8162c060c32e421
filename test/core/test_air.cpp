// The drag and magnus effects (flight through air, integrated) against closed forms derived in
// the comments: a vertical fall and a rise under quadratic drag, an impact found on the
// integrated flight, and Magnus's circle.
#include <gtest/gtest.h>

#include <cmath>

#include "collision_response/core/monitor.h"
#include "collision_response/core/validation.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using scene_builders::ball;
using scene_builders::plane;

constexpr double kG = 9.81;
constexpr double kPi = 3.14159265358979323846;

/// A light ball in air: m = 2.7 g, r = 20 mm (a table-tennis ball), C_d 0.5, C_L 0.2.
Scene airScene(bool gravity, bool drag, bool magnus) {
  Scene scene;
  scene.effects.gravity = gravity;
  scene.effects.drag = drag;
  scene.effects.magnus = magnus;
  scene.effects.spin = magnus;
  scene.gravity = V(0, 0, -kG);
  scene.air_density = 1.2;
  scene.flight_integration_tolerance = 1e-12;
  BodySpec body = ball("ball", 0.0027, 0.02, "hollow_hard_plastic_ball");
  body.drag_coefficient = 0.5;
  body.lift_coefficient = 0.2;
  scene.bodies = {body};
  return scene;
}

/// rho C A / (2 m): the air's factor per unit mass.
double factor(const Scene& scene, double coefficient) {
  const BodySpec& body = scene.bodies[0];
  return scene.air_density * coefficient * kPi * body.radius * body.radius / (2 * body.mass);
}

/// The monitor given one state at t = 0 and advanced by its own motion to `time`.
std::pair<V, V> flown(const Scene& scene, const V& position, const V& velocity, const V& spin,
                      double time, std::vector<ImpactRecord>* impacts = nullptr) {
  MonitorSettings settings;
  settings.body_timeout = INFINITY;  // no further states: the flight is the monitor's own
  ImpactMonitor monitor(scene, settings);
  BodyStateSample state;
  state.position = position;
  state.velocity = velocity;
  state.angular_velocity = spin;
  monitor.step(0.0, {state});
  const StepReport report = monitor.advance(time, {});
  if (impacts != nullptr) *impacts = report.impacts;
  return *monitor.predictedState(0, time);
}

// Falling from rest under gravity and drag k v^2 (k = rho C_d A / 2m): dv/dt = g - k v^2, so
// v(t) = v_t tanh(g t / v_t) with v_t = sqrt(g / k), and the distance fallen is
// (v_t^2 / g) ln cosh(g t / v_t).
TEST(Air, VerticalFallWithDragIsTheTanhLaw) {
  const Scene scene = airScene(true, true, false);
  const double vt = std::sqrt(kG / factor(scene, 0.5));
  for (const double t : {0.1, 0.5, 1.0, 3.0}) {
    const auto [position, velocity] = flown(scene, V(0, 0, 100), V::Zero(), V::Zero(), t);
    EXPECT_NEAR(velocity.z(), -vt * std::tanh(kG * t / vt), 1e-9 * vt) << t;
    EXPECT_NEAR(position.z(), 100 - vt * vt / kG * std::log(std::cosh(kG * t / vt)), 1e-9 * vt)
        << t;
    EXPECT_EQ(velocity.x(), 0.0);
    EXPECT_EQ(position.y(), 0.0);
  }
}

// Rising from v0: dv/dt = -g - k v^2, so v(t) = v_t tan(atan(v0 / v_t) - g t / v_t) until the
// apex, and the height gained is (v_t^2 / g) ln(cos(atan(v0/v_t) - g t/v_t) / cos(atan(v0/v_t))).
TEST(Air, RiseWithDragIsTheTanLaw) {
  const Scene scene = airScene(true, true, false);
  const double vt = std::sqrt(kG / factor(scene, 0.5));
  const double v0 = 20.0;
  const double phase = std::atan(v0 / vt);
  const double apex = vt / kG * phase;
  for (const double t : {0.05, 0.2, apex * 0.9, apex}) {
    const auto [position, velocity] = flown(scene, V(0, 0, 0), V(0, 0, v0), V::Zero(), t);
    const double angle = phase - kG * t / vt;
    EXPECT_NEAR(velocity.z(), vt * std::tan(angle), 1e-9 * v0) << t;
    EXPECT_NEAR(position.z(), vt * vt / kG * std::log(std::cos(angle) / std::cos(phase)), 1e-9 * v0)
        << t;
  }
}

// Dropped from rest at height H onto a floor: it meets the floor when it has fallen H - r,
// (v_t^2 / g) ln cosh(g t / v_t) = H - r, so t = (v_t / g) acosh(exp(g (H - r) / v_t^2)); it
// arrives at v_t tanh(g t / v_t) and leaves at e times that (e = 0.688 for the seed's hollow
// hard plastic ball on concrete).
TEST(Air, ImpactOnTheIntegratedFlightIsAtTheClosedFormInstant) {
  Scene scene = airScene(true, true, false);
  scene.obstacles = {plane("floor", V::UnitZ(), 0.0, "concrete")};
  const double vt = std::sqrt(kG / factor(scene, 0.5));
  const double height = 2.0, radius = 0.02;
  const double instant = vt / kG * std::acosh(std::exp(kG * (height - radius) / (vt * vt)));
  const double arrival = vt * std::tanh(kG * instant / vt);
  std::vector<ImpactRecord> impacts;
  flown(scene, V(0, 0, height), V::Zero(), V::Zero(), instant + 0.01, &impacts);
  ASSERT_EQ(impacts.size(), 1u);
  EXPECT_NEAR(impacts[0].time, instant, 1e-10);
  EXPECT_NEAR(impacts[0].velocity_a_before.z(), -arrival, 1e-9 * vt);
  const double e = *scene.materials.restitution("hollow_hard_plastic_ball", "concrete");
  EXPECT_NEAR(impacts[0].velocity_a_after.z(), e * arrival, 1e-9 * vt);
  EXPECT_DOUBLE_EQ(impacts[0].restitution, e);
}

// Magnus alone, no gravity and no drag: the force k |v| (w/|w| x v) is at right angles to v, so
// the speed stays |v| and the path bends at |v|^2 / R = k |v|^2: a circle of radius R = 1/k =
// 2 m / (rho C_L A), whatever the speed, in the plane normal to w. Moving along x, spinning about
// z: w/|w| x v points along y, the circle's centre is p0 + R y, and after t the ball is at the
// angle v t / R: p0 + R (sin(v t / R), 1 - cos(v t / R), 0).
TEST(Air, MagnusAloneMovesOnACircleOfTheClosedFormRadius) {
  const Scene scene = airScene(false, false, true);
  const double radius = 1 / factor(scene, 0.2);
  const double speed = 10.0;
  for (const double t : {0.1, 1.0, 2 * kPi * radius / speed}) {
    const auto [position, velocity] = flown(scene, V::Zero(), V(speed, 0, 0), V(0, 0, 300), t);
    const double angle = speed * t / radius;
    EXPECT_NEAR(position.x(), radius * std::sin(angle), 1e-9 * radius) << t;
    EXPECT_NEAR(position.y(), radius * (1 - std::cos(angle)), 1e-9 * radius) << t;
    EXPECT_EQ(position.z(), 0.0);
    EXPECT_NEAR(velocity.norm(), speed, 1e-9 * speed) << t;
  }
}

// Without drag and Magnus the flight is the parabola to the bit: the same scene with the effects
// named but their coefficients at 0 is integrated, and still lands within the integrator's
// tolerance; with the effects off no integration happens at all, and the impact is the ballistic
// root's: t = sqrt(2 (H - r) / g) to a few ulps.
TEST(Air, WithTheEffectsOffTheFlightIsTheParabola) {
  Scene scene = airScene(true, false, false);
  scene.obstacles = {plane("floor", V::UnitZ(), 0.0, "concrete")};
  const double exact = std::sqrt(2 * (2.0 - 0.02) / kG);
  std::vector<ImpactRecord> impacts;
  flown(scene, V(0, 0, 2.0), V::Zero(), V::Zero(), 1.0, &impacts);
  ASSERT_GE(impacts.size(), 1u);
  EXPECT_NEAR(impacts[0].time, exact, 4 * std::numeric_limits<double>::epsilon() * exact);

  scene.effects.drag = true;
  scene.bodies[0].drag_coefficient = 0.0;
  std::vector<ImpactRecord> integrated;
  flown(scene, V(0, 0, 2.0), V::Zero(), V::Zero(), 1.0, &integrated);
  ASSERT_GE(integrated.size(), 1u);
  EXPECT_NEAR(integrated[0].time, exact, 1e-10);
}

// A ball bouncing to rest through air, e = 0.688 on the floor: over one 60 s step (as a long
// prediction advances) and over 6,000 updates of 10 ms alike, it bounces down to rest on the
// floor (its centre r above it), never below the touching band: each bounce starts no deeper
// than the last (a drift to the band's edge once took it through the floor after six bounces).
TEST(Air, BouncesToRestWithoutDriftingIntoTheFloor) {
  Scene scene = airScene(true, true, false);
  scene.obstacles = {plane("floor", V::UnitZ(), 0.0, "concrete")};
  const double radius = scene.bodies[0].radius;
  std::vector<std::size_t> counts;
  for (const double period : {60.0, 0.01}) {
    MonitorSettings settings;
    settings.body_timeout = INFINITY;
    ImpactMonitor monitor(scene, settings);
    BodyStateSample state;
    state.position = V(0, 0, 3);
    state.velocity = V(0.3, 0, 5);
    monitor.step(0.0, {state});
    std::size_t impacts = 0;
    const int updates = static_cast<int>(std::lround(60.0 / period));
    for (int k = 1; k <= updates; ++k) {
      const double time = k * period;
      impacts += monitor.advance(time, {}).impacts.size();
      EXPECT_GE(monitor.predictedState(0, time)->first.z(), radius * (1 - 1e-9)) << time;
    }
    const auto end = monitor.predictedState(0, 60.0);
    EXPECT_NEAR(end->first.z(), radius, 1e-9 * radius) << period;
    EXPECT_EQ(end->second.z(), 0.0) << period;
    EXPECT_GT(impacts, 20u) << period;
    counts.push_back(impacts);
  }
  EXPECT_EQ(counts[0], counts[1]);
}

// Hostile speeds: at 1e200 m/s drag's acceleration overflows the doubles. The flight stalls (it
// holds its last finite state: doc/model.md, "Effects in detail") rather than integrating
// without end or giving NaN; at 1e-300 m/s the air does nothing measurable. Either way every
// number out is finite and the ball is never below the floor.
TEST(Air, HugeAndTinySpeedsStayFinite) {
  Scene scene = airScene(true, true, true);
  scene.obstacles = {plane("floor", V::UnitZ(), 0.0, "concrete")};
  for (const double speed : {1e200, 1e150, 1e-300}) {
    std::vector<ImpactRecord> impacts;
    const auto [position, velocity] =
        flown(scene, V(0, 0, 1), V(speed, 0, -speed), V(0, 300, 0), 0.5, &impacts);
    EXPECT_TRUE(position.allFinite()) << speed;
    EXPECT_TRUE(velocity.allFinite()) << speed;
    EXPECT_GE(position.z(), 0.02 * (1 - 1e-9)) << speed;
    for (const ImpactRecord& impact : impacts) {
      EXPECT_TRUE(impact.velocity_a_after.allFinite()) << speed;
      EXPECT_TRUE(std::isfinite(impact.time)) << speed;
    }
  }
}

// Issue 39, item 5: a throw at 1e50 m/s (drag's acceleration k v^2 = 1e100 m/s^2 and more: the
// integrator finds no step it can take) froze the ball without a word. The flight stalls at its
// start and holds the state there (doc/model.md, "Effects in detail"), and the monitor says so
// once, naming the body and the instant, whatever the steps after.
TEST(Air, Issue39_Item5_AFlightThatStallsIsReportedOnce) {
  Scene scene = airScene(true, true, false);
  MonitorSettings settings;
  settings.body_timeout = INFINITY;
  ImpactMonitor monitor(scene, settings);
  BodyStateSample state;
  state.position = V(0, 0, 1);
  state.velocity = V(1e50, 0, 0);
  monitor.step(0.0, {state});
  std::vector<StalledFlight> stalled;
  for (int k = 1; k <= 10; ++k) {
    const StepReport report = monitor.advance(0.01 * k, {});
    stalled.insert(stalled.end(), report.stalled.begin(), report.stalled.end());
  }
  ASSERT_EQ(stalled.size(), 1u);
  EXPECT_EQ(stalled[0].body, 0u);
  EXPECT_EQ(stalled[0].stalled, 0.0);
  EXPECT_EQ(monitor.predictedState(0, 0.1)->first, V(0, 0, 1));
  // A new state starts a new flight, which goes on (and says nothing).
  state.time = 0.2;
  state.velocity = V(1, 0, 0);
  EXPECT_TRUE(monitor.step(0.2, {state}).stalled.empty());
  EXPECT_TRUE(monitor.advance(0.3, {}).stalled.empty());
}

// Issue 39, item 5: a C_d, a C_L or an air density of 1e300 froze the body at its first step
// (the scene accepted them). Each is refused at its key, with the reason. At the bound itself,
// an air factor k = rho C_d A / (2 m) of kMaxAirFactor = 1e3 1/m, a ball thrown at 30 m/s flies
// the prediction's whole 60 s horizon without stalling and falls at its terminal speed
// sqrt(g / k) (dv/dt = g - k v^2 = 0).
TEST(Air, Issue39_Item5_AirTooStiffToIntegrateIsRefusedAtItsKey) {
  Scene drag = airScene(true, true, false);
  drag.bodies[0].drag_coefficient = 1e300;
  const Status by_drag = validateScene(drag, "scene");
  ASSERT_FALSE(by_drag.ok());
  EXPECT_EQ(by_drag.error().field, "scene/bodies[0]/drag_coefficient");
  EXPECT_NE(by_drag.error().reason.find("could not be integrated"), std::string::npos)
      << by_drag.error().reason;
  Scene lift = airScene(true, true, true);
  lift.bodies[0].lift_coefficient = 1e300;
  const Status by_lift = validateScene(lift, "scene");
  ASSERT_FALSE(by_lift.ok());
  EXPECT_EQ(by_lift.error().field, "scene/bodies[0]/lift_coefficient");
  Scene dense = airScene(true, true, false);
  dense.air_density = 1e300;
  const Status by_density = validateScene(dense, "scene");
  ASSERT_FALSE(by_density.ok());
  EXPECT_EQ(by_density.error().field, "scene/air_density");
  // Without the effect the coefficient is not used: nothing to refuse.
  Scene off = airScene(true, false, false);
  off.bodies[0].drag_coefficient = 1e300;
  EXPECT_TRUE(validateScene(off, "scene").ok());

  Scene bound = airScene(true, true, false);
  bound.flight_integration_tolerance = 1e-9;
  bound.bodies[0].drag_coefficient = kMaxAirFactor / factor(bound, 1.0);
  ASSERT_TRUE(validateScene(bound, "scene").ok());
  MonitorSettings settings;
  settings.body_timeout = INFINITY;
  ImpactMonitor monitor(bound, settings);
  BodyStateSample state;
  state.velocity = V(30, 0, 0);
  monitor.step(0.0, {state});
  EXPECT_TRUE(monitor.advance(60.0, {}).stalled.empty());
  EXPECT_NEAR(monitor.predictedState(0, 60.0)->second.z(), -std::sqrt(kG / kMaxAirFactor), 1e-9);
}

}  // namespace
}  // namespace collision_response::core
