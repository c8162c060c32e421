// Predictions ahead of time (prediction.h): gravity-only ones equal the monitor's own motion to
// the bit and the closed forms; budgets and every bad request named.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "collision_response/core/prediction.h"
#include "reference/serve_reference.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using scene_builders::ball;
using scene_builders::box;
using scene_builders::plane;

constexpr double kG = 9.81;
constexpr double kEps = std::numeric_limits<double>::epsilon();

/// A ball (the seed's hollow hard plastic ball, e = 0.688 on concrete) over a concrete floor and
/// a concrete table 0.76 m high.
Scene tableScene() {
  Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -kG);
  scene.bodies = {ball("ball", 0.0027, 0.02, "hollow_hard_plastic_ball")};
  scene.obstacles = {plane("floor", V::UnitZ(), 0.0, "concrete"),
                     box("table", V(0, 0, 0.745), V(2.74, 1.525, 0.03), "concrete")};
  return scene;
}

PredictionRequest requestFor(const Scene& scene, const V& position, const V& velocity,
                             double horizon, std::size_t max_impacts) {
  PredictionRequest request;
  request.body = scene.bodies[0];
  request.state.position = position;
  request.state.velocity = velocity;
  request.horizon = horizon;
  request.max_impacts = max_impacts;
  request.effects = scene.effects;
  return request;
}

/// A monitor given `request`'s state at 0 and advanced by its own motion (no further states) at
/// the updates `period` apart up to `horizon`: its impacts, and the state at `horizon`.
std::pair<std::vector<ImpactRecord>, std::pair<V, V>> played(const Scene& scene,
                                                             const PredictionRequest& request,
                                                             double period, double horizon) {
  MonitorSettings settings;
  settings.body_timeout = INFINITY;  // no further states: the motion is the monitor's own
  ImpactMonitor monitor(scene, settings);
  BodyStateSample state;
  state.position = request.state.position;
  state.velocity = request.state.velocity;
  monitor.step(0.0, {state});
  std::vector<ImpactRecord> impacts;
  const int updates = static_cast<int>(std::lround(horizon / period));
  for (int k = 1; k <= updates; ++k) {
    const auto report = monitor.advance(k == updates ? horizon : k * period, {});
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
  }
  return {impacts, *monitor.predictedState(0, horizon)};
}

// The prediction is the monitor's own motion. Advanced over the horizon at once, the monitor
// finds the same impacts and ends in the same state, bit for bit. Advanced at the node's updates
// (1 kHz) it finds them to a few ulps: each root is taken from its update's start, so its last
// bits depend on where the updates fall.
TEST(Prediction, GravityOnlyEqualsTheMonitorToTheBit) {
  const Scene scene = tableScene();
  const auto request = requestFor(scene, V(-1.2, 0.1, 1.0), V(4.0, 0.2, 1.0), 2.0, 50);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_GE(prediction->impacts.size(), 3u);

  const auto [at_once, end] = played(scene, request, 2.0, 2.0);
  ASSERT_EQ(at_once.size(), prediction->impacts.size());
  for (std::size_t i = 0; i < at_once.size(); ++i) {
    EXPECT_EQ(at_once[i].time, prediction->impacts[i].time) << i;
    EXPECT_EQ(at_once[i].contact_point, prediction->impacts[i].contact_point) << i;
    EXPECT_EQ(at_once[i].velocity_a_before, prediction->impacts[i].velocity_a_before) << i;
    EXPECT_EQ(at_once[i].velocity_a_after, prediction->impacts[i].velocity_a_after) << i;
  }
  EXPECT_EQ(prediction->final_state.position, end.first);
  EXPECT_EQ(prediction->final_state.velocity, end.second);
  EXPECT_EQ(prediction->final_state.time, 2.0);

  const auto [updated, updated_end] = played(scene, request, 1e-3, 2.0);
  ASSERT_EQ(updated.size(), prediction->impacts.size());
  for (std::size_t i = 0; i < updated.size(); ++i) {
    EXPECT_NEAR(updated[i].time, prediction->impacts[i].time, 8 * kEps) << i;
    EXPECT_EQ(updated[i].other, prediction->impacts[i].other) << i;  // the same obstacles
    EXPECT_LE((updated[i].velocity_a_after - prediction->impacts[i].velocity_a_after).norm(),
              8 * kEps * prediction->impacts[i].velocity_a_after.norm())
        << i;
  }
  EXPECT_LE((updated_end.first - prediction->final_state.position).norm(), 8 * kEps * 8);
}

// Dropped from rest at H over the table's top (0.76 m): it falls h = H - 0.76 - r in
// t1 = sqrt(2 h / g), arrives at -sqrt(2 g h) and leaves at e sqrt(2 g h); each later flight
// lasts 2 u / g for the speed u it left at, each bounce multiplies u by e.
TEST(Prediction, BouncesOnTheTableAtTheClosedForms) {
  const Scene scene = tableScene();
  const double e = *scene.materials.restitution("hollow_hard_plastic_ball", "concrete");
  const double h = 1.2 - 0.76 - 0.02;
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{},
                                         requestFor(scene, V(0.3, 0.2, 1.2), V::Zero(), 2.0, 4));
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_EQ(prediction->impacts.size(), 4u);
  double time = std::sqrt(2 * h / kG), speed = std::sqrt(2 * kG * h);
  for (std::size_t i = 0; i < 4; ++i) {
    const ImpactRecord& impact = prediction->impacts[i];
    EXPECT_EQ(prediction->model->obstacle(impact.other).id, "table");
    EXPECT_NEAR(impact.time, time, 16 * kEps * time) << i;
    EXPECT_NEAR(impact.velocity_a_before.z(), -speed, 16 * kEps * speed) << i;
    EXPECT_NEAR(impact.velocity_a_after.z(), e * speed, 16 * kEps * speed) << i;
    speed *= e;
    time += 2 * speed / kG;
  }
  // max_impacts reached: the prediction ends at the fourth impact (a hair after it: 1e-12 of the
  // 2 s horizon, 16 ulps), not at the horizon, the ball leaving the table.
  const double fourth = prediction->impacts[3].time;
  EXPECT_GT(prediction->final_state.time, fourth);
  EXPECT_LE(prediction->final_state.time, fourth + 2e-12 + 16 * kEps * fourth);
  EXPECT_GT(prediction->final_state.velocity.z(), 0.0);
  EXPECT_FALSE(prediction->cut_short);
}

// Thrown along x at 3 m/s from x = -1: it crosses the plane x = 1 at t = 2/3 s whatever gravity
// does, at z = z0 + vz t - g t^2 / 2 (no impact before: it starts 30 m up).
TEST(Prediction, FirstCrossingOfAPlaneIsTheClosedForm) {
  Scene scene = tableScene();
  scene.obstacles.pop_back();
  auto request = requestFor(scene, V(-1, 0, 30), V(3, 0, 1), 1.0, 10);
  request.crossing = Plane{V::UnitX(), 1.0};
  request.sample_period = 0.1;
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_TRUE(prediction->crossing);
  const double t = 2.0 / 3.0;
  EXPECT_NEAR(prediction->crossing->time, t, 4 * kEps);
  EXPECT_NEAR(prediction->crossing->position.x(), 1.0, 8 * kEps);
  EXPECT_NEAR(prediction->crossing->position.z(), 30 + t - 0.5 * kG * t * t, 64 * kEps);
  // Samples every 0.1 s from 0 to 1 s, on the parabola.
  ASSERT_EQ(prediction->samples.size(), 11u);
  for (const BodyStateSample& sample : prediction->samples) {
    const double s = sample.time;
    EXPECT_NEAR(sample.position.x(), -1 + 3 * s, 16 * kEps);
    EXPECT_NEAR(sample.position.z(), 30 + s - 0.5 * kG * s * s, 64 * kEps);
  }
}

// A ball at rest on the floor is held where the live monitor has it: thrown along x at 2 m/s
// (no gravity) from 1 m away, the thrown ball meets it when the gap of 1 - 2 r closes, at
// t = (1 - 2 r) / 2.
TEST(Prediction, OtherBodiesAreHeldWhereTheLiveMonitorHasThem) {
  Scene scene;
  scene.bodies = {ball("ball", 1, 0.1, "steel_ball_bearing"),
                  ball("target", 1, 0.1, "steel_ball_bearing")};
  ImpactMonitor live(scene, MonitorSettings{});
  BodyStateSample target;
  target.body = *live.bodyIndex("target");
  target.position = V(1, 0, 0);
  live.step(0.0, {target});
  auto request = requestFor(scene, V::Zero(), V(2, 0, 0), 1.0, 1);
  const auto prediction = predictImpacts(scene, &live, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_EQ(prediction->impacts.size(), 1u);
  EXPECT_EQ(prediction->model->obstacle(prediction->impacts[0].other).id, "target");
  EXPECT_NEAR(prediction->impacts[0].time, 0.4, 4 * kEps);
}

// A ball predicted in a scene with a box body (0.2 x 0.4 x 0.2 m, turned a quarter about z) that
// the live monitor has at rest at x = 1: the box is held as an immovable box at its pose, its
// half extent along x 0.2 m (its y edge, turned), so the ball thrown along x at 2 m/s from the
// origin (r = 0.1, no gravity, e = 1/2) meets its face when its centre is at 1 - 0.2 - 0.1, at
// t = 0.35 s, and leaves at -e 2 m/s. Before, the box was held as a sphere of its radius (0).
TEST(Prediction, AShapedBodyIsHeldAsItsShapeAtItsPose) {
  Scene scene;
  ASSERT_TRUE(scene.materials.addMaterial("hard", Material{0.5, {}}, "m").ok());
  BodySpec crate;
  crate.id = "crate";
  crate.mass = 2.0;
  crate.material = "hard";
  crate.shape = BodyShape::kBox;
  crate.size = V(0.2, 0.4, 0.2);
  scene.bodies = {ball("ball", 1, 0.1, "hard"), crate};
  ImpactMonitor live(scene, MonitorSettings{});
  BodyStateSample at_rest;
  at_rest.body = *live.bodyIndex("crate");
  at_rest.position = V(1, 0, 0);
  at_rest.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, V::UnitZ()));
  live.step(0.0, {at_rest});
  auto request = requestFor(scene, V::Zero(), V(2, 0, 0), 1.0, 1);
  const auto prediction = predictImpacts(scene, &live, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_EQ(prediction->impacts.size(), 1u);
  EXPECT_EQ(prediction->model->obstacle(prediction->impacts[0].other).id, "crate");
  EXPECT_NEAR(prediction->impacts[0].time, 0.35, 1e-12);
  EXPECT_NEAR((prediction->impacts[0].velocity_a_after - V(-1, 0, 0)).norm(), 0.0, 1e-12);
}

/// The serve's reference (bench/accuracy/reference/serve_reference.py, 40-digit mpmath).
bench::ServeReference serveReference() {
  return bench::ServeReference::read(COLLISION_RESPONSE_SERVE_REFERENCE);
}

// A table-tennis serve with topspin (gravity, drag, Magnus; frictionless bounces, e = 0.9): its
// two bounces on the table and its crossing of the plane x = 1.6 behind the table, against an
// independent 40-digit solution of the same equations (mpmath's Taylor-series integrator and
// root finder). At the integrator's tolerance 1e-12 every instant is within 1e-9 s and every
// position within 1e-9 m.
TEST(Prediction, ServeWithDragAndMagnusMatchesTheHighPrecisionReference) {
  const auto reference = serveReference();
  Scene scene = tableScene();
  ASSERT_TRUE(scene.materials.addMaterial("celluloid", Material{0.9, {}}, "m").ok());
  scene.effects.spin = scene.effects.drag = scene.effects.magnus = true;
  scene.air_density = 1.2;
  scene.flight_integration_tolerance = 1e-12;
  BodySpec& body = scene.bodies[0];
  body.material = "celluloid";
  body.inertia = Inertia::kHollow;
  body.drag_coefficient = 0.5;
  body.lift_coefficient = 0.2;
  auto request = requestFor(scene, reference.vector("initial_position"),
                            reference.vector("initial_velocity"), 1.0, 10);
  request.state.angular_velocity = reference.vector("angular_velocity");
  request.crossing = Plane{V::UnitX(), 1.6};
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_GE(prediction->impacts.size(), 2u);
  for (const int bounce : {1, 2}) {
    const std::string name = "bounce" + std::to_string(bounce);
    const ImpactRecord& impact = prediction->impacts[static_cast<std::size_t>(bounce - 1)];
    EXPECT_EQ(prediction->model->obstacle(impact.other).id, "table");
    EXPECT_NEAR(impact.time, reference.value(name + "_time"), 1e-9) << name;
    const V centre = impact.contact_point - body.radius * impact.normal;
    EXPECT_LE((centre - reference.vector(name + "_position")).norm(), 1e-9) << name;
    EXPECT_LE((impact.velocity_a_before - reference.vector(name + "_velocity_before")).norm(), 1e-9)
        << name;
    EXPECT_LE((impact.velocity_a_after - reference.vector(name + "_velocity_after")).norm(), 1e-9)
        << name;
  }
  ASSERT_TRUE(prediction->crossing);
  EXPECT_NEAR(prediction->crossing->time, reference.value("crossing_time"), 1e-9);
  EXPECT_LE((prediction->crossing->position - reference.vector("crossing_position")).norm(), 1e-9);
  EXPECT_LE((prediction->crossing->velocity - reference.vector("crossing_velocity")).norm(), 1e-9);
}

// The serve asked for its first two impacts with a plane's crossing (the search's 20 ms pieces):
// the prediction ends at the second bounce, found again over a shorter span from its piece's
// start, and both are there (once one went missing: found again a bisection's resolution later).
TEST(Prediction, MaxImpactsThroughAirEndsAtTheLastOne) {
  const auto reference = serveReference();
  Scene scene = tableScene();
  ASSERT_TRUE(scene.materials.addMaterial("celluloid", Material{0.9, {}}, "m").ok());
  scene.effects.spin = scene.effects.drag = scene.effects.magnus = true;
  scene.air_density = 1.2;
  BodySpec& body = scene.bodies[0];
  body.material = "celluloid";
  body.drag_coefficient = 0.5;
  body.lift_coefficient = 0.2;
  for (const std::size_t count : {1u, 2u}) {
    auto request = requestFor(scene, reference.vector("initial_position"),
                              reference.vector("initial_velocity"), 1.2, count);
    request.state.angular_velocity = reference.vector("angular_velocity");
    request.crossing = Plane{V::UnitX(), 1.6};
    const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
    ASSERT_TRUE(prediction.ok()) << prediction.error().message();
    ASSERT_EQ(prediction->impacts.size(), count);
    const double last = prediction->impacts.back().time;
    EXPECT_NEAR(last, reference.value("bounce" + std::to_string(count) + "_time"), 1e-7);
    EXPECT_GT(prediction->final_state.time, last);
    EXPECT_LT(prediction->final_state.time, last + 1e-12);
    EXPECT_FALSE(prediction->crossing);  // the plane is behind the table, after both
  }
}

TEST(Prediction, BudgetsAnswerWithWhatWasFoundAndSaySo) {
  const Scene scene = tableScene();
  auto request = requestFor(scene, V(5, 0, 1.0), V::Zero(), 100.0, 5000);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_TRUE(prediction->cut_short);
  EXPECT_NE(prediction->message.find("horizon is cut to 60 s"), std::string::npos);
  EXPECT_NE(prediction->message.find("impacts are cut to 1000"), std::string::npos);
  EXPECT_EQ(prediction->final_state.time, 60.0);
  // At rest on the floor by then: a ball bouncing to rest, by the lasting-contact model.
  EXPECT_EQ(prediction->final_state.velocity, V::Zero());
  EXPECT_NEAR(prediction->final_state.position.z(), 0.02, 1e-12);
  EXPECT_EQ(prediction->contacts.size(), 1u);
}

// Issue 39, item 5: a ball thrown at 1e50 m/s through air answered success with the ball at its
// initial state at the horizon, and no word. Its flight stalls at once (no step the integrator
// can take): the answer says so, and that the ball is held there.
TEST(Prediction, Issue39_Item5_AFlightThatStallsIsSaidInTheMessage) {
  Scene scene = tableScene();
  scene.effects.drag = true;
  auto request = requestFor(scene, V(5, 0, 1.0), V(1e50, 0, 0), 1.0, 3);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_TRUE(prediction->cut_short);
  EXPECT_NE(prediction->message.find("the flight through air stalled at +0 s"), std::string::npos)
      << prediction->message;
  EXPECT_EQ(prediction->final_state.position, V(5, 0, 1.0));
}

// Issue 41, item 8: a sample period of 5e-324 s gave a 0 s prediction with one sample (the
// horizon over it is infinite, and the count taken from it was none). Any period too small for
// the samples' budget gives the most samples, 10,000 over the horizon, and says so: the ball,
// dropped from rest at z = 1 beside the table, is at 1 - g t^2 / 2 at each.
TEST(Prediction, Issue41_Item8_ASamplePeriodTooSmallForAnyCountGivesTheMostSamples) {
  const Scene scene = tableScene();
  for (const double period : {5e-324, std::numeric_limits<double>::min(), 1e-300, 1e-10}) {
    auto request = requestFor(scene, V(5, 0, 1.0), V::Zero(), 0.1, 5);
    request.sample_period = period;
    const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
    ASSERT_TRUE(prediction.ok()) << prediction.error().message();
    EXPECT_TRUE(prediction->cut_short) << period;
    EXPECT_NE(prediction->message.find("samples are cut to 10000"), std::string::npos)
        << period << ": " << prediction->message;
    EXPECT_EQ(prediction->final_state.time, 0.1) << period;
    ASSERT_EQ(prediction->samples.size(), 10001u) << period;
    for (std::size_t k = 0; k <= 10000; k += 1250) {
      const BodyStateSample& sample = prediction->samples[k];
      const double t = 1e-5 * static_cast<double>(k);
      EXPECT_NEAR(sample.time, t, 1e-16) << period << ", sample " << k;
      EXPECT_NEAR(sample.position.z(), 1.0 - 0.5 * kG * t * t, 1e-14) << period << ", " << k;
    }
  }
}

// Issue 41, item 8: a plane's normal is any nonzero length, as the service's is: 1e-13 was taken
// for zero ("is zero: a plane needs a direction"; Eigen's isZero is approximate). The ball
// dropped from rest at z = 1 crosses z = 0.9 at t = sqrt(2 (0.1) / g).
TEST(Prediction, Issue41_Item8_ACrossingNormalOfAnyNonzeroLengthIsAPlane) {
  const Scene scene = tableScene();
  for (const double length : {1e-13, 1e-300, 1.0}) {
    auto request = requestFor(scene, V(5, 0, 1.0), V::Zero(), 0.5, 5);
    request.crossing = Plane{V(0, 0, length), 0.9 * length};
    const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
    ASSERT_TRUE(prediction.ok()) << length << ": " << prediction.error().message();
    ASSERT_TRUE(prediction->crossing) << length;
    EXPECT_NEAR(prediction->crossing->time, std::sqrt(2 * 0.1 / kG), 1e-15) << length;
    EXPECT_NEAR(prediction->crossing->position.z(), 0.9, 1e-15) << length;
  }
}

TEST(Prediction, EveryBadRequestIsNamed) {
  const Scene scene = tableScene();
  const auto good = requestFor(scene, V(0, 0, 1.2), V::Zero(), 1.0, 2);
  const auto refused = [&](PredictionRequest request) {
    const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
    return prediction.ok() ? std::string("accepted") : prediction.error().field;
  };
  auto request = good;
  request.state.position.x() = NAN;
  EXPECT_EQ(refused(request), "body.position.x");
  request = good;
  request.state.velocity.z() = INFINITY;
  EXPECT_EQ(refused(request), "body.velocity.z");
  request = good;
  request.horizon = 0;
  EXPECT_EQ(refused(request), "horizon");
  request.horizon = NAN;
  EXPECT_EQ(refused(request), "horizon");
  request = good;
  request.max_impacts = 0;
  EXPECT_EQ(refused(request), "max_impacts");
  request = good;
  request.state.position = V(0, 0, 0.75);  // inside the table
  EXPECT_EQ(refused(request), "body.position");
  request = good;
  request.body.mass = -1;
  EXPECT_EQ(refused(request), "body.mass");
  request = good;
  request.body.material = "unobtainium";
  EXPECT_EQ(refused(request), "body.material");
  request = good;
  request.effects.magnus = true;
  EXPECT_EQ(refused(request), "effects");
  request = good;
  request.state.angular_velocity = V(0, 1, 0);
  EXPECT_EQ(refused(request), "body.angular_velocity");
  request = good;
  request.sample_period = -1;
  EXPECT_EQ(refused(request), "sample_period");
  request = good;
  request.crossing = Plane{V::Zero(), 0.0};
  EXPECT_EQ(refused(request), "crossing_normal");
  request = good;
  request.body.drag_coefficient = -0.1;
  EXPECT_EQ(refused(request), "drag_coefficient");
  EXPECT_EQ(refused(good), "accepted");
}

}  // namespace
}  // namespace collision_response::core
