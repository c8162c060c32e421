// The monitor's shaped bodies (src/core/monitor/shaped_tracks.h): their impacts with obstacles
// against the closed forms, through the monitor and through Playback as the scene player drives
// them; what is not modelled yet reported (StepReport::unmodelled), never passed through.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/playback.h"
#include "collision_response/core/triangle_mesh.h"
#include "collision_response/core/validation.h"
#include "monitor/shaped_motion.h"
#include "quadrature.h"
#include "scene_builders.h"
#include "shaped_scenes.h"

namespace collision_response::core {
namespace {

/// The played body 0's state at `t`, as the scene player publishes it, for the monitor's `body`.
BodyStateSample playedState(const Playback& playback, std::size_t body, double t) {
  BodyStateSample state;
  state.body = body;
  state.time = t;
  state.position = playback.position(0, t);
  state.velocity = playback.velocity(0, t);
  state.angular_velocity = playback.angularVelocity(0, t);
  state.orientation = playback.orientation(0, t);
  return state;
}

using V = Eigen::Vector3d;
using shaped_scenes::AcrossSlope;
using shaped_scenes::EdgeLanding;
using shaped_scenes::floorScene;
using shaped_scenes::impactsOf;
using shaped_scenes::kG;
using shaped_scenes::RimFall;
using shaped_scenes::tableScene;

/// The body dropped from rest with its centre at `height`, turned by `turn`, as a state at `t`
/// on its parabola (before it lands).
BodyStateSample fallingState(const ImpactMonitor& monitor, double height,
                             const Eigen::Quaterniond& turn, double t) {
  BodyStateSample state;
  state.body = *monitor.bodyIndex("block");
  state.time = t;
  state.position = V(0, 0, height - 0.5 * kG * t * t);
  state.velocity = V(0, 0, -kG * t);
  state.orientation = turn;
  return state;
}

/// Every step's report of the monitor fed `states` at their instants, then stepped every `dt`
/// without states up to `until`.
std::vector<StepReport> run(ImpactMonitor& monitor, const std::vector<BodyStateSample>& states,
                            double dt, double until) {
  std::vector<StepReport> reports;
  for (const BodyStateSample& state : states) reports.push_back(monitor.step(state.time, {state}));
  for (double t = states.back().time + dt; t <= until + 1e-12; t += dt) {
    reports.push_back(monitor.step(t, {}));
  }
  return reports;
}

/// floorScene's body (e = 1/2, `mass`) as a mesh body of `vertices` and `triangles` (its hull).
Scene meshScene(const std::vector<V>& vertices,
                const std::vector<TriangleMesh::Triangle>& triangles, double mass) {
  Scene scene = floorScene(0.5, V(0.05, 0.05, 0.05), mass);
  scene.bodies[0].shape = BodyShape::kMesh;
  scene.bodies[0].size = V::Zero();
  scene.bodies[0].mesh = scene_builders::facingOut(vertices, triangles, V::Zero());
  return scene;
}

/// A can: a cylinder body "can" of aluminium (the scene's material of that name).
BodySpec canOf(double mass, double radius, double length) {
  BodySpec can;
  can.id = "can";
  can.mass = mass;
  can.material = "aluminium";
  can.shape = BodyShape::kCylinder;
  can.radius = radius;
  can.length = length;
  return can;
}

/// The impacts at the first instant of impact (the box's landing; its other edge lands later).
std::vector<ImpactRecord> firstInstant(const std::vector<ImpactRecord>& impacts) {
  std::vector<ImpactRecord> first;
  for (const ImpactRecord& impact : impacts) {
    if (impact.time == impacts.front().time) first.push_back(impact);
  }
  return first;
}

// A box of e = 1/2 dropped flat from rest, frictionless, fed to the monitor by two states on its
// parabola before it lands: its four corners strike the floor at once at t = sqrt(2 h / g), h the
// drop of its lowest face (one record per corner, each with the whole body's velocities before
// and after), and it leaves at e v without turning. The instant to the first contact's
// certification (1e-12 s, tumbling_contact.h), the velocities to what that leaves (g 1e-12).
TEST(ShapedMonitor, ABoxDroppedFlatBouncesAtTheParabolasInstant) {
  const V half(0.05, 0.04, 0.03);
  const double e = 0.5, height = 0.5;
  const Scene scene = floorScene(e, half);
  ASSERT_TRUE(validateScene(scene, "scene").ok())
      << validateScene(scene, "scene").error().message();
  ImpactMonitor monitor(scene, MonitorSettings{});
  const Eigen::Quaterniond flat = Eigen::Quaterniond::Identity();
  const auto reports = run(
      monitor, {fallingState(monitor, height, flat, 0.0), fallingState(monitor, height, flat, 0.1)},
      0.02, 0.36);
  const std::vector<ImpactRecord> impacts = impactsOf(reports);
  const double fall = std::sqrt(2 * (height - half.z()) / kG), v = kG * fall;
  ASSERT_GE(impacts.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    const ImpactRecord& impact = impacts[k];
    EXPECT_NEAR(impact.time, fall, 1e-11);
    EXPECT_TRUE(impact.other_is_obstacle);
    EXPECT_EQ(monitor.obstacle(impact.other).id, "floor");
    EXPECT_NEAR(impact.contact_point.z(), 0.0, 1e-9);
    EXPECT_NEAR(std::abs(impact.contact_point.x()), half.x(), 1e-12);
    EXPECT_NEAR(std::abs(impact.contact_point.y()), half.y(), 1e-12);
    EXPECT_NEAR(impact.velocity_a_before.z(), -v, 1e-10);
    EXPECT_NEAR(impact.velocity_a_after.z(), e * v, 1e-10);
    EXPECT_NEAR(impact.impulse, 2.0 * (1 + e) * v / 4, 1e-10);  // (1 + e) m v over four corners
    EXPECT_LE(impact.angular_velocity_a_after.norm(), 1e-12);
  }
  // The apex after it: e v / g later, e^2 (h - c) above the floor, the orientation the same.
  const double apex = fall + e * v / kG;
  const auto state = monitor.predictedState(*monitor.bodyIndex("block"), apex);
  ASSERT_TRUE(state);
  EXPECT_NEAR(state->first.z(), half.z() + e * e * (height - half.z()), 1e-10);
  EXPECT_NEAR(state->second.z(), 0.0, 1e-10);
  EXPECT_LE(monitor.predictedOrientation(*monitor.bodyIndex("block"), apex).angularDistance(flat),
            1e-12);
}

// A shaped body's states are taken by the balls' rules: one not newer than its body's last is
// stale; one after the landing that still falls at the parabola's speed lacks the impact the
// monitor found (more than half its velocity change, (1 + e) v): reported as contradicting it, at
// the impact's instant, and taken as the track.
TEST(ShapedMonitor, StatesAreStaleOrContradictAnImpactAsABallsDo) {
  const V half(0.05, 0.04, 0.03);
  const double e = 0.5, height = 0.5;
  const Scene scene = floorScene(e, half);
  ImpactMonitor monitor(scene, MonitorSettings{});
  const Eigen::Quaterniond flat = Eigen::Quaterniond::Identity();
  monitor.step(0.0, {fallingState(monitor, height, flat, 0.0)});
  const StepReport stale = monitor.step(0.1, {fallingState(monitor, height, flat, 0.0)});
  EXPECT_EQ(stale.stale_states, 1u);
  const double fall = std::sqrt(2 * (height - half.z()) / kG), v = kG * fall;
  // After the landing, a state still falling (a source that did not see it), 5 mm above the
  // floor, at the parabola's velocity past the landing.
  const double t = fall + 0.001;
  BodyStateSample falling = fallingState(monitor, height, flat, t);
  falling.position.z() = half.z() + 0.005;
  const StepReport report = monitor.step(t, {falling});
  ASSERT_EQ(report.impacts.size(), 4u);
  ASSERT_EQ(report.contradicted.size(), 1u);
  EXPECT_EQ(report.contradicted[0].body, *monitor.bodyIndex("block"));
  EXPECT_NEAR(report.contradicted[0].impact_time, fall, 1e-11);
  EXPECT_EQ(report.contradicted[0].state_time, t);
  // It lacks the impact's change, (1 + e) v (both fell g 0.001 s since: that cancels).
  EXPECT_NEAR(report.contradicted[0].missing, (1 + e) * v, 1e-9);
  const auto predicted = monitor.predictedState(*monitor.bodyIndex("block"), t);
  ASSERT_TRUE(predicted);
  EXPECT_EQ(predicted->first, falling.position);  // the state is the track
}

// The box landing on an edge (shaped_scenes::EdgeLanding's closed form), over the monitor: two
// corners at the parabola's instant, their impulses summing to J, v_z' and w_y' as it says, and
// the monitor's orientation after it turning at w_y' (until its other edge lands, 11 ms later).
TEST(ShapedMonitor, ABoxLandingOnAnEdgeTurnsAsTheClosedFormSays) {
  const EdgeLanding edge;
  const Scene scene = floorScene(edge.e, V(edge.a, edge.b, edge.c), edge.m);
  ImpactMonitor monitor(scene, MonitorSettings{});
  std::vector<StepReport> reports =
      run(monitor, {fallingState(monitor, edge.height, edge.turn(), 0.0)}, 0.05, 0.3);
  const double later = edge.fall() + 0.004;
  reports.push_back(monitor.step(later, {}));
  const std::vector<ImpactRecord> all = impactsOf(reports);
  ASSERT_FALSE(all.empty());
  const std::vector<ImpactRecord> impacts = firstInstant(all);
  ASSERT_EQ(impacts.size(), 2u);
  expectTheEdgeLanding(edge, impacts);
  // A cuboid's turn about its principal y is at a constant rate: theta + w_y' dt after it.
  const std::size_t block = *monitor.bodyIndex("block");
  const Eigen::Quaterniond expected(
      Eigen::AngleAxisd(edge.theta + edge.spinAfter() * (later - edge.fall()), V::UnitY()));
  EXPECT_LE(monitor.predictedOrientation(block, later).angularDistance(expected), 1e-9);
  EXPECT_NEAR(monitor.predictedAngularVelocity(block, later).y(), edge.spinAfter(), 1e-9);
}

// The same box played as the scene player plays it: Playback's states every 10 ms into the
// monitor, whose impacts Playback applies (the watcher's replacing its own). The monitor's
// impacts are the closed form's, and the played box follows them: its orientation turning at
// w_y' after the landing, its centre never below the lowest corner's height above the floor.
TEST(ShapedMonitor, PlaybackAndTheMonitorGiveTheEdgeLandingsImpacts) {
  const EdgeLanding edge;
  Scene scene = floorScene(edge.e, V(edge.a, edge.b, edge.c), edge.m);
  scene.bodies[0].position = V(0, 0, edge.height);
  scene.bodies[0].orientation = edge.turn();
  ImpactMonitor monitor(scene, MonitorSettings{});
  Playback playback(scene, MonitorSettings{}.contact_tolerance, 0.0);
  std::vector<ImpactRecord> impacts;
  const double dt = 0.01;
  bool checked = false;
  for (int k = 0; k * dt <= edge.fall() + 0.05; ++k) {
    const double t = k * dt;
    const BodyStateSample state = playedState(playback, *monitor.bodyIndex("block"), t);
    const StepReport report = monitor.step(t, {state});
    EXPECT_TRUE(playback.applyImpacts(monitor, report.impacts, true).empty());
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
    if (t > edge.fall() && !checked) {
      // The first instant played after the landing (its other edge lands 11 ms after it): the
      // played box turns and rises as the closed form's impact sent it.
      checked = true;
      const Eigen::Quaterniond expected(
          Eigen::AngleAxisd(edge.theta + edge.spinAfter() * (t - edge.fall()), V::UnitY()));
      EXPECT_LE(playback.orientation(0, t).angularDistance(expected), 1e-9);
      EXPECT_NEAR(playback.velocity(0, t).z(), edge.velocityAfter() - kG * (t - edge.fall()), 1e-9);
    }
  }
  EXPECT_TRUE(checked);
  ASSERT_FALSE(impacts.empty());
  ASSERT_EQ(firstInstant(impacts).size(), 2u);
  for (const ImpactRecord& impact : firstInstant(impacts)) {
    EXPECT_NEAR(impact.time, edge.fall(), 1e-11);
    EXPECT_NEAR(impact.velocity_a_after.z(), edge.velocityAfter(), 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.y(), edge.spinAfter(), 1e-9);
  }
  // The impacts after (its other edge landing) once each: none found again at its instant.
  for (std::size_t k = 2; k < impacts.size(); ++k) EXPECT_GT(impacts[k].time, edge.fall() + 1e-3);
}

// A floor on a tf frame placed only after the box's state was taken (the node hears tf later):
// the box's motion goes on among the obstacles as placed now, and lands on it at the parabola's
// instant as on a fixed floor.
TEST(ShapedMonitor, AnObstaclePlacedAfterTheStateIsMetAllTheSame) {
  const V half(0.05, 0.04, 0.03);
  const double height = 0.4;
  Scene scene = floorScene(0.5, half);
  scene.obstacles[0].frame = "floor_frame";
  ImpactMonitor monitor(scene, MonitorSettings{});
  const Eigen::Quaterniond flat = Eigen::Quaterniond::Identity();
  monitor.step(0.0, {fallingState(monitor, height, flat, 0.0)});
  std::vector<StepReport> reports{monitor.step(0.05, {})};
  monitor.setObstaclePose(0, RigidPose{});
  for (int k = 2; k <= 8; ++k) reports.push_back(monitor.step(0.05 * k, {}));
  const std::vector<ImpactRecord> impacts = impactsOf(reports);
  ASSERT_GE(impacts.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(impacts[k].time, std::sqrt(2 * (height - half.z()) / kG), 1e-11);
  }
}

// A box at rest beside which a ball moves into it, in a scene with friction but without spin: the
// ball stays a ball (a shaped body turns, and its ball would not: doc/model.md, "Balls among
// shaped bodies"), and the monitor does not carry a shaped body's contact with a ball, so at the
// first step's end where they touch or overlap it is reported (once, naming both), not passed
// through silently; the steps after, while they still touch, do not report it again. (With spin,
// or without friction, they strike: ShapedBalls.*.)
TEST(ShapedMonitor, ABoxTouchingABallThatStaysABallIsReportedAsUnmodelled) {
  const V half(0.05, 0.05, 0.05);
  Scene scene = floorScene(0.5, half);
  scene.effects.gravity = false;
  scene.effects.friction = true;
  scene.bodies.push_back(scene_builders::ball("ball", 0.1, 0.02, "block"));
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t block = *monitor.bodyIndex("block"), ball = *monitor.bodyIndex("ball");
  BodyStateSample box_state;
  box_state.body = block;
  box_state.position = V(0, 0, 0.5);
  BodyStateSample ball_state;
  ball_state.body = ball;
  ball_state.position = V(0.2, 0, 0.5);
  ball_state.velocity = V(-1, 0, 0);  // touches the box's face at (0.2 - 0.07) / 1 = 0.13 s
  monitor.step(0.0, {box_state, ball_state});
  std::vector<UnmodelledContact> unmodelled;
  double first_report = -1;
  for (int k = 1; k <= 20; ++k) {
    const double t = 0.01 * k;
    const StepReport report = monitor.step(t, {});
    if (!report.unmodelled.empty() && first_report < 0) first_report = t;
    unmodelled.insert(unmodelled.end(), report.unmodelled.begin(), report.unmodelled.end());
  }
  ASSERT_EQ(unmodelled.size(), 1u);
  EXPECT_EQ(unmodelled[0].body, block);
  EXPECT_EQ(unmodelled[0].other, ball);
  EXPECT_FALSE(unmodelled[0].other_is_obstacle);
  EXPECT_NE(unmodelled[0].what.find("not modelled yet"), std::string::npos) << unmodelled[0].what;
  // The first step ending at or after the touch (0.13 s) reports it.
  EXPECT_NEAR(first_report, 0.13, 1e-9);
  EXPECT_NEAR(unmodelled[0].time, 0.13, 1e-9);
}

// A state whose orientation is not a rotation (zero, or not finite) cannot start a shaped body's
// motion: the core drops it and counts it (StepReport::refused_states), keeping the track. (The
// node's intake refuses it first, naming the field: checkOrientation.) A scene body's orientation
// is validated with the scene (validateScene: checkBodyShape).
TEST(ShapedMonitor, ABadOrientationStateIsRefusedAndTheTrackKept) {
  const V half(0.05, 0.05, 0.05);
  Scene scene = floorScene(0.5, half);
  scene.effects.gravity = false;
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t block = *monitor.bodyIndex("block");
  BodyStateSample state;
  state.body = block;
  state.position = V(0, 0, 0.5);
  state.velocity = V(1, 0, 0);
  monitor.step(0.0, {state});
  for (const Eigen::Quaterniond& bad :
       {Eigen::Quaterniond(0, 0, 0, 0), Eigen::Quaterniond(NAN, 0, 0, 1)}) {
    BodyStateSample wrong = state;
    wrong.time = monitor.now() + 0.1;
    wrong.position = V(5, 5, 5);
    wrong.orientation = bad;
    const StepReport report = monitor.step(wrong.time, {wrong});
    EXPECT_EQ(report.refused_states, 1u);
    const auto predicted = monitor.predictedState(block, wrong.time);
    ASSERT_TRUE(predicted);
    EXPECT_NEAR(predicted->first.x(), wrong.time, 1e-12);  // the track from the first state
  }
  Scene bad_scene = scene;
  bad_scene.bodies[0].orientation = Eigen::Quaterniond(0, 0, 0, 0);
  const Status refused = validateScene(bad_scene, "scene");
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().field.rfind("scene/bodies[0]/orientation", 0), 0u)
      << refused.error().message();
}

// The monitor takes a box, cylinder, capsule and mesh body, through air too; an immovable shaped
// body is refused, by name ("not yet").
TEST(ShapedMonitor, ValidateSceneTakesTheShapesTheMonitorMoves) {
  for (const BodyShape shape : {BodyShape::kBox, BodyShape::kCylinder, BodyShape::kCapsule}) {
    Scene scene = floorScene(0.5, V(0.05, 0.05, 0.05));
    scene.bodies[0].shape = shape;
    scene.bodies[0].radius = 0.05;
    scene.bodies[0].length = 0.1;
    EXPECT_TRUE(validateScene(scene, "s").ok()) << validateScene(scene, "s").error().message();
  }
  Scene mesh = floorScene(0.5, V(0.05, 0.05, 0.05));
  mesh.bodies[0].shape = BodyShape::kMesh;
  mesh.bodies[0].size = V::Zero();
  mesh.bodies[0].mesh = scene_builders::cubeMesh(V(0.05, 0.05, 0.05));
  EXPECT_TRUE(validateScene(mesh, "s").ok()) << validateScene(mesh, "s").error().message();
  Scene immovable = floorScene(0.5, V(0.05, 0.05, 0.05));
  immovable.bodies[0].mass = INFINITY;
  const Status immovable_refused = validateScene(immovable, "s");
  ASSERT_FALSE(immovable_refused.ok());
  EXPECT_EQ(immovable_refused.error().field, "s/bodies[0]/mass");
  Scene air = floorScene(0.5, V(0.05, 0.05, 0.05));
  air.effects.drag = air.effects.magnus = air.effects.spin = true;
  EXPECT_TRUE(validateScene(air, "s").ok()) << validateScene(air, "s").error().message();
}

// A box given at rest on the floor, flat: lastingOnFace's resting motion, reported as one contact
// record per corner, each carrying m g / 4 (statics: four equal supports symmetric about the
// centre), `since` the instant given, nothing unmodelled, the box where it was given.
TEST(ShapedMonitor, ABoxRestingOnTheFloorCarriesAQuarterOfItsWeightPerCorner) {
  const V half(0.05, 0.04, 0.03);
  const double m = 2.0;
  const Scene scene = floorScene(0.5, half, m);
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t block = *monitor.bodyIndex("block");
  BodyStateSample state;
  state.body = block;
  state.position = V(0.1, 0.2, half.z());
  std::vector<StepReport> reports{monitor.step(0.0, {state})};
  for (int k = 1; k <= 5; ++k) reports.push_back(monitor.step(0.01 * k, {}));
  for (const StepReport& report : reports) EXPECT_TRUE(report.unmodelled.empty());
  const auto predicted = monitor.predictedState(block, 0.05);
  ASSERT_TRUE(predicted);
  EXPECT_EQ(predicted->first, state.position);
  EXPECT_EQ(predicted->second, V::Zero());
  EXPECT_EQ(monitor.restingOn(block), std::optional<std::size_t>(0));
  ASSERT_EQ(reports.back().contacts.size(), 4u);
  for (const ContactRecord& contact : reports.back().contacts) {
    EXPECT_EQ(contact.body_a, block);
    EXPECT_TRUE(contact.other_is_obstacle);
    EXPECT_NEAR(contact.normal_force, m * kG / 4, 1e-12);
    EXPECT_EQ(contact.state, ContactState::kResting);
    EXPECT_NEAR(contact.contact_point.z(), 0.0, 1e-12);
    EXPECT_EQ(contact.normal, V(0, 0, -1));
    EXPECT_EQ(contact.since, 0.0);
  }
}

// A box of e = 1/2 dropped flat bounces at the geometric series' instants until its bounces
// accumulate, and rests from their end, fall + 2 e v / (g (1 - e)) (flatBouncesEnd, as a ball's:
// doc/model.md, "Coming to rest"): the monitor reports each bounce's four corners, then the four
// contacts at m g / 4 each, `since` that instant, the box on the floor.
TEST(ShapedMonitor, ABoxBouncingFlatComesToRestAtTheSeriesEnd) {
  const V half(0.05, 0.05, 0.05);
  const double e = 0.5, m = 2.0, height = 0.3;
  const Scene scene = floorScene(e, half, m);
  ImpactMonitor monitor(scene, MonitorSettings{});
  const Eigen::Quaterniond flat = Eigen::Quaterniond::Identity();
  const auto reports = run(monitor, {fallingState(monitor, height, flat, 0.0)}, 0.02, 0.9);
  const std::vector<ImpactRecord> impacts = impactsOf(reports);
  const double fall = std::sqrt(2 * (height - half.z()) / kG), v = kG * fall;
  double t = fall, speed = v;
  ASSERT_GE(impacts.size(), 12u);
  for (std::size_t k = 0; k < 12; k += 4) {
    EXPECT_NEAR(impacts[k].time, t, 1e-10) << k;
    speed *= e;
    t += 2 * speed / kG;
  }
  for (const StepReport& report : reports) EXPECT_TRUE(report.unmodelled.empty());
  const double rests = fall + 2 * e * v / (kG * (1 - e));
  ASSERT_EQ(reports.back().contacts.size(), 4u);
  for (const ContactRecord& contact : reports.back().contacts) {
    EXPECT_NEAR(contact.normal_force, m * kG / 4, 1e-9);
    EXPECT_NEAR(contact.since, rests, 1e-9);
  }
  const auto predicted = monitor.predictedState(*monitor.bodyIndex("block"), monitor.now());
  ASSERT_TRUE(predicted);
  EXPECT_NEAR(predicted->first.z(), half.z(), 1e-9);
}

// A box bouncing flat to rest, played as the scene player plays it (Playback's states every 10 ms
// into the monitor, its impacts applied back): the monitor reports the bounces and then the four
// resting contacts, m g / 4 each, nothing unmodelled (a played state on the floor is touching it,
// not inside), and the played box rests on the floor.
TEST(ShapedMonitor, PlaybackAndTheMonitorBringABoxBouncingFlatToRest) {
  const V half(0.05, 0.05, 0.05);
  const double e = 0.5, m = 2.0, height = 0.3;
  Scene scene = floorScene(e, half, m);
  scene.bodies[0].position = V(0, 0, height);
  ImpactMonitor monitor(scene, MonitorSettings{});
  Playback playback(scene, MonitorSettings{}.contact_tolerance, 0.0);
  StepReport last;
  std::size_t impacts = 0, unmodelled = 0;
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.01 * k;
    const BodyStateSample state = playedState(playback, *monitor.bodyIndex("block"), t);
    last = monitor.step(t, {state});
    EXPECT_TRUE(playback.applyImpacts(monitor, last.impacts, true).empty());
    impacts += last.impacts.size();
    unmodelled += last.unmodelled.size();
    for (const UnmodelledContact& contact : last.unmodelled) ADD_FAILURE() << contact.what;
  }
  EXPECT_GE(impacts, 12u);
  EXPECT_EQ(unmodelled, 0u);
  ASSERT_EQ(last.contacts.size(), 4u);
  for (const ContactRecord& contact : last.contacts) {
    EXPECT_NEAR(contact.normal_force, m * kG / 4, 1e-9);
  }
  EXPECT_NEAR(playback.position(0, 1.0).z(), half.z(), 1e-9);
  EXPECT_EQ(playback.contacts(1.0).size(), 4u);
}

// The tipping's hand-overs: one at an instant, at most 50 within 1 ms (the 51st refused, saying it
// chatters), and counted afresh after the window.
TEST(ShapedMonitor, ATippingsHandOversAreBoundedAsResumeGuardSays) {
  ResumeGuard guard;
  EXPECT_FALSE(guard.refuse(1.0));
  ASSERT_TRUE(guard.refuse(1.0));
  EXPECT_NE(guard.refuse(1.0)->find("ends where it starts"), std::string::npos);
  for (int k = 1; k < 50; ++k) EXPECT_FALSE(guard.refuse(1.0 + 1e-5 * k)) << k;
  const auto refused = guard.refuse(1.0 + 5e-4);
  ASSERT_TRUE(refused);
  EXPECT_NE(refused->find("chatters between supports"), std::string::npos);
  EXPECT_FALSE(guard.refuse(1.0 + 2e-3));  // a new window
}

// A cube slid across an incline (AcrossSlope): before, held where it was and reported, "not yet:
// sliding across the slope". Now its corners slide on the incline (pivotOnFace) and it moves as
// the closed form says: at each step t, its velocity v(phi(t)) along phi(t) from straight down
// (1e-8 m/s) and its centre where the path's integral puts it (1e-8 m), never turning (1e-9
// rad/s); it stops at t(0) = 0.46335 s and rests there (mu >= tan theta), nothing unmodelled.
TEST(ShapedMonitor, ACubeSlidingAcrossAnInclineTurnsDownItAndStopsAsTheClosedFormSays) {
  const AcrossSlope slope;
  ImpactMonitor monitor(slope.scene(), MonitorSettings{});
  const std::size_t block = *monitor.bodyIndex("block");
  const BodyStateSample start = slope.state(block, 0.0);
  const double stops = AcrossSlope::instant(0.0);
  std::size_t moving = 0;
  for (int k = 0; k <= 60; ++k) {
    const double t = 0.01 * k;
    const StepReport report = k == 0 ? monitor.step(t, {start}) : monitor.step(t, {});
    for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << c.what;
    const auto at = monitor.predictedState(block, t);
    ASSERT_TRUE(at);
    EXPECT_LT(monitor.predictedAngularVelocity(block, t).norm(), 1e-9) << t;
    const V& v = at->second;
    if (t >= stops) {
      EXPECT_EQ(v, V::Zero()) << t;
      EXPECT_LT((at->first - start.position - AcrossSlope::moved(0.0)).norm(), 1e-8) << t;
      continue;
    }
    EXPECT_NEAR(v.dot(AcrossSlope::normal()), 0.0, 1e-12) << t;
    const double phi = AcrossSlope::angleAt(t);
    const V closed = AcrossSlope::speed(phi) *
                     (std::cos(phi) * AcrossSlope::down() + std::sin(phi) * AcrossSlope::across());
    EXPECT_LT((v - closed).norm(), 1e-8) << t;
    EXPECT_LT((at->first - start.position - AcrossSlope::moved(phi)).norm(), 1e-8) << t;
    ++moving;
  }
  EXPECT_GT(moving, 40u);
  EXPECT_NEAR(stops, 0.46335, 1e-5);
}

// A box sliding across a table's top towards its corner, along the diagonal (e = 1/2, mu 0.5
// against the table: the scene's default): where its support reaches the table's two edges at
// once (at 0.3 s: its corner (0.35, 0.35) reaches x = y = 0.5 after 0.15 / 0.5 s; the scene has
// no friction) it slides on over the corner, tips over it and falls to the floor: nothing
// reported unmodelled, never inside the table (its corners, 1e-9 m). Before, it was held at
// 0.3 s ("not yet: the body overhangs two of the face's edges"); over the corner in full:
// test_shaped_corner.cpp.
TEST(ShapedMonitor, ABoxSlidingOntoATablesCornerGoesOverItAndFalls) {
  Scene scene = tableScene(0.5, V(0.05, 0.05, 0.05), 1.0);
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t block = *monitor.bodyIndex("block");
  BodyStateSample state;
  state.body = block;
  state.position = V(0.3, 0.3, 0.55);
  state.velocity = V(0.5, 0.5, 0);
  std::vector<UnmodelledContact> unmodelled;
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.01 * k;
    const StepReport report = k == 0 ? monitor.step(0.0, {state}) : monitor.step(t, {});
    unmodelled.insert(unmodelled.end(), report.unmodelled.begin(), report.unmodelled.end());
    const auto at = monitor.predictedState(block, t);
    ASSERT_TRUE(at);
    const Eigen::Matrix3d r = monitor.predictedOrientation(block, t).toRotationMatrix();
    for (int c = 0; c < 8; ++c) {
      const V corner =
          at->first + r * V((c & 1) ? 0.05 : -0.05, (c & 2) ? 0.05 : -0.05, (c & 4) ? 0.05 : -0.05);
      EXPECT_GE(std::max({corner.x() - 0.5, corner.y() - 0.5, corner.z() - 0.5}), -1e-9) << t;
      EXPECT_GE(corner.z(), -1e-9) << t;
    }
    if (t <= 0.3) {
      EXPECT_LT((at->first - V(0.3 + 0.5 * t, 0.3 + 0.5 * t, 0.55)).norm(), 1e-12) << t;
    }
  }
  for (const UnmodelledContact& c : unmodelled) ADD_FAILURE() << c.what;
  const auto end = monitor.predictedState(block, 1.0);
  ASSERT_TRUE(end);
  EXPECT_LT(end->first.z(), 0.5) << "off the table";
}

// A can given once at rest leaning on its rim (tilted 0.3 rad) on the frictionless floor tips
// back over its rim: the monitor moves it (nothing held or reported unmodelled), its centre
// straight down, and its cap lands flat at the energy integral's instant (RimFall::landing,
// 1e-8 s). Before, the monitor held it on its rim and reported the contact as not modelled.
TEST(ShapedMonitor, ACanLeaningOnItsRimFallsBackOntoItsCapAtTheEnergyIntegralsInstant) {
  const RimFall fall;
  ImpactMonitor monitor(fall.scene(), MonitorSettings{});
  const std::size_t block = *monitor.bodyIndex("block");
  BodyStateSample state;
  state.body = block;
  state.position = fall.centre();
  state.orientation = fall.orientation();
  std::vector<ImpactRecord> impacts;
  for (int k = 0; k <= 30; ++k) {
    const StepReport report =
        monitor.step(0.01 * k, k == 0 ? std::vector{state} : std::vector<BodyStateSample>{});
    EXPECT_TRUE(report.unmodelled.empty()) << report.unmodelled.front().what;
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
    const auto now = monitor.predictedState(block, 0.01 * k);
    ASSERT_TRUE(now);
    EXPECT_NEAR(now->first.x(), 0.0, 1e-10);
    EXPECT_NEAR(now->first.y(), 0.0, 1e-10) << "straight down";
  }
  ASSERT_FALSE(impacts.empty());
  EXPECT_NEAR(impacts.front().time, fall.landing(), 1e-8);
}

// A box given once at rest on one of its edges tips over it on the frictionless floor: the monitor
// moves it (nothing is held or reported unmodelled), its centre straight down, and its face
// lands at the energy integral's instant (EdgeLanding::tipInstant, 1e-8 s). Before, the monitor
// held it on its edge and reported the contact as not modelled.
TEST(ShapedMonitor, ABoxTippingOverAnEdgeLandsOnItsFaceAtTheEnergyIntegralsInstant) {
  const EdgeLanding edge;
  const Scene scene = floorScene(edge.e, V(edge.a, edge.b, edge.c), edge.m);
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t block = *monitor.bodyIndex("block");
  BodyStateSample state;
  state.body = block;
  state.time = 0.0;
  state.position = V(0, 0, edge.low());
  state.orientation = edge.turn();
  std::vector<UnmodelledContact> unmodelled;
  std::vector<ImpactRecord> impacts;
  for (int k = 0; k <= 40; ++k) {
    const StepReport report = k == 0 ? monitor.step(0.0, {state}) : monitor.step(0.01 * k, {});
    unmodelled.insert(unmodelled.end(), report.unmodelled.begin(), report.unmodelled.end());
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
    const auto predicted = monitor.predictedState(block, 0.01 * k);
    ASSERT_TRUE(predicted);
    if (0.01 * k < edge.tipInstant()) {
      EXPECT_NEAR(predicted->first.x(), 0.0, 1e-9) << 0.01 * k;
      EXPECT_GE(predicted->first.z(), edge.c - 1e-9) << 0.01 * k;
    }
  }
  EXPECT_TRUE(unmodelled.empty()) << unmodelled.front().what;
  ASSERT_FALSE(impacts.empty());
  EXPECT_NEAR(impacts.front().time, edge.tipInstant(), 1e-8);
}

// A box at rest on the frictionless floor struck by a robot's link moving at v_o (a box obstacle
// on a tf frame, its face against the box's back face, d behind it): its lasting rest watched the
// floor alone, and the link went through it. Now the rest ends where the link reaches it, d / v_o
// (1e-11 s), the four corners of its back face struck at once by an immovable body moving at v_o
// (the joint frictionless rule): it leaves at (1 + e) v_o without turning, sliding on the floor
// ahead of the link, its contacts with the floor again m g / 4 per corner.
TEST(ShapedMonitor, ABoxAtRestStruckByAMovingLinkLeavesAtOnePlusETimesItsSpeed) {
  const V half(0.05, 0.04, 0.03);
  const double e = 0.5, m = 2.0, v_o = 0.8, d = 0.04;
  Scene scene = floorScene(e, half, m);
  scene.obstacles.push_back(
      scene_builders::box("paddle", V::Zero(), V(0.02, 0.3, 0.2), "concrete"));
  scene.obstacles.back().frame = "paddle_link";
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t block = *monitor.bodyIndex("block");
  RigidPose link;
  link.transform.translation() = V(-half.x() - d - 0.01, 0, half.z());
  link.velocity = V(v_o, 0, 0);
  monitor.setObstaclePose(1, link);
  BodyStateSample state;
  state.body = block;
  state.position = V(0, 0, half.z());
  std::vector<StepReport> reports{monitor.step(0.0, {state})};
  for (int k = 1; k <= 10; ++k) reports.push_back(monitor.step(0.01 * k, {}));
  for (const StepReport& report : reports) {
    for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << c.what;
  }
  const std::vector<ImpactRecord> impacts = impactsOf(reports);
  std::size_t by_link = 0;
  for (const ImpactRecord& impact : impacts) {
    EXPECT_NEAR(impact.time, d / v_o, 1e-11);
    EXPECT_NEAR(impact.velocity_a_after.x(), (1 + e) * v_o, 1e-9);
    EXPECT_NEAR(impact.velocity_a_after.z(), 0.0, 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.norm(), 0.0, 1e-9);
    if (impact.other_is_obstacle && impact.other == 1) ++by_link;
  }
  EXPECT_EQ(by_link, 4u);
  const auto predicted = monitor.predictedState(block, 0.1);
  ASSERT_TRUE(predicted);
  EXPECT_NEAR(predicted->first.x(), (1 + e) * v_o * (0.1 - d / v_o), 1e-9);
  EXPECT_NEAR(predicted->first.z(), half.z(), 1e-9);
  ASSERT_EQ(reports.back().contacts.size(), 4u);
  for (const ContactRecord& contact : reports.back().contacts) {
    EXPECT_EQ(contact.other, 0u);
    EXPECT_NEAR(contact.normal_force, m * kG / 4, 1e-9);
  }
}

// A box set flush on a table's top (a box obstacle): the distance of the two flush faces rounds
// below 0, and its state was refused as inside the table. Touching within the manifold's band
// (1e-9 m) is touching: it rests there, m g / 4 on each corner (1e-9 N), where it was set. Set
// 1e-6 m into the table, it is inside, named and held.
TEST(ShapedMonitor, ABoxSetFlushOnATablesTopRestsThereAndOneSetInsideIsNamed) {
  const V half(0.05, 0.04, 0.03);
  const double m = 2.0;
  Scene scene = floorScene(0.5, half, m);
  scene.obstacles.push_back(
      scene_builders::box("table", V(0.1, 0.2, 0.35), V(1.0, 1.0, 0.1), "concrete"));
  for (const double sunk : {0.0, 1e-6}) {
    ImpactMonitor monitor(scene, MonitorSettings{});
    const std::size_t block = *monitor.bodyIndex("block");
    BodyStateSample state;
    state.body = block;
    state.position = V(0.3, 0.1, 0.4 + half.z() - sunk);
    StepReport report = monitor.step(0.0, {state});
    for (int k = 1; k <= 10; ++k) {
      const StepReport later = monitor.step(0.01 * k, {});
      report.unmodelled.insert(report.unmodelled.end(), later.unmodelled.begin(),
                               later.unmodelled.end());
      report.contacts = later.contacts;
    }
    if (sunk > 0) {
      ASSERT_EQ(report.unmodelled.size(), 1u);
      EXPECT_NE(report.unmodelled.front().what.find("inside the obstacle"), std::string::npos);
      continue;
    }
    for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << c.what;
    const auto at = monitor.predictedState(block, 0.1);
    ASSERT_TRUE(at);
    EXPECT_NEAR((at->first - state.position).norm(), 0.0, 1e-9);
    ASSERT_EQ(report.contacts.size(), 4u);
    for (const ContactRecord& contact : report.contacts) {
      EXPECT_EQ(contact.other, 1u);
      EXPECT_NEAR(contact.normal_force, m * kG / 4, 1e-9);
    }
  }
}

// A box sliding off a table's edge (frictionless): before, the monitor held it where its support
// reached the edge, "not yet". Now it slides on until its centre is over the edge, at
// (0.5 - 0.25) / 0.5 = 0.5 s (its path the straight line to then, 1e-9 m), tips over the edge and
// falls to the floor, its energy kept until it strikes it (frictionless: within the tipping's
// integration, 1e-7 of m g h), never inside the table (its corners, 1e-9 m), nothing unmodelled.
TEST(ShapedMonitor, ABoxSlidingOffATablesEdgeTipsOverItAndFallsToTheFloor) {
  const V half(0.0625, 0.0625, 0.0625);
  const double m = 2.0, v = 0.5;
  Scene scene = tableScene(0.5, half, m);
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t block = *monitor.bodyIndex("block");
  BodyStateSample state;
  state.body = block;
  state.position = V(0.25, 0, 0.5 + half.z());
  state.velocity = V(v, 0, 0);
  // Its energy (1/2) m v^2 + (1/2) I w^2 + m g z, I = m (2 a)^2 / 6 for a cube, at each step.
  const double inertia = m * 4 * half.x() * half.x() / 6;
  const auto energy = [&](const V& centre, const V& velocity, const V& w) {
    return 0.5 * m * velocity.squaredNorm() + 0.5 * inertia * w.squaredNorm() + m * kG * centre.z();
  };
  const double start = energy(state.position, state.velocity, V::Zero());
  std::vector<std::pair<double, double>> energies;
  std::vector<StepReport> reports{monitor.step(0.0, {state})};
  for (int k = 1; k <= 200; ++k) {
    const double t = 0.005 * k;
    reports.push_back(monitor.step(t, {}));
    const auto at = monitor.predictedState(block, t);
    ASSERT_TRUE(at);
    energies.emplace_back(
        t, energy(at->first, at->second, monitor.predictedAngularVelocity(block, t)));
    if (t <= 0.5) {
      EXPECT_NEAR((at->first - V(0.25 + v * t, 0, 0.5625)).norm(), 0.0, 1e-9) << t;
    }
    const Eigen::Matrix3d r = monitor.predictedOrientation(block, t).toRotationMatrix();
    for (int i = 0; i < 8; ++i) {
      const V corner =
          at->first +
          r * V((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1).cwiseProduct(half);
      EXPECT_GE(std::max(corner.x() - 0.5, corner.z() - 0.5), -1e-9)
          << "corner " << i << " inside the table at " << t;
      EXPECT_GE(corner.z(), -1e-9) << "corner " << i << " below the floor at " << t;
    }
  }
  for (const StepReport& report : reports) {
    for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << c.what;
  }
  const std::vector<ImpactRecord> impacts = impactsOf(reports);
  ASSERT_FALSE(impacts.empty());
  const ImpactRecord& first = impacts.front();
  EXPECT_TRUE(first.other_is_obstacle);
  EXPECT_EQ(first.other, 0u);  // the floor
  EXPECT_GT(first.time, 0.5);
  EXPECT_NEAR(first.contact_point.z(), 0.0, 1e-9);
  std::size_t flying = 0;
  for (const auto& [t, e] : energies) {
    if (t >= first.time) break;
    EXPECT_NEAR(e, start, 1e-7 * m * kG * 0.5625) << t;
    if (t > 0.5) ++flying;
  }
  EXPECT_GT(flying, 10u);
}

// A can on its side sliding off a frictionless table's edge, its axis along the edge: before, the
// monitor held it where its side reached the edge, "not yet". Now it slides there at 0.5 s, turns
// over the edge on its side, its centre on the circle of radius r about the edge's line until
// N = m (g cos theta - r theta'^2) = 0 at cos theta = (2 g r + v^2) / (3 g r), at the integral of
// dtheta / theta' (r theta'^2 = v^2 / r + 2 g (1 - cos theta)), then flies from there at
// sqrt(g r cos theta) along the circle's tangent and lands on its side on the floor where its
// centre is r above it: the parabola's instant (1e-8 s, the roll's integration), never inside the
// table, nothing unmodelled.
TEST(ShapedMonitor, ACanRollingOnItsSideOffATablesEdgeLandsOnTheFloorAtTheClosedFormsInstant) {
  const double r = 0.05, half_length = 0.1, m = 0.5, v = 0.5, top = 0.5;
  Scene scene = tableScene(0.5, V(0.05, 0.05, 0.05), m);
  scene.bodies[0].shape = BodyShape::kCylinder;
  scene.bodies[0].size = V::Zero();
  scene.bodies[0].radius = r;
  scene.bodies[0].length = 2 * half_length;
  MonitorSettings settings;
  settings.body_timeout = INFINITY;
  ImpactMonitor monitor(scene, settings);
  const std::size_t can = *monitor.bodyIndex("block");
  BodyStateSample state;
  state.body = can;
  state.position = V(0.25, 0, top + r);
  state.velocity = V(v, 0, 0);
  state.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, V::UnitX()));
  const double leaves = std::acos((2 * kG * r + v * v) / (3 * kG * r));
  const double turning =
      0.5 + quadrature::gaussLegendre(
                [&](double theta) {
                  return 1 / std::sqrt(v * v / (r * r) + 2 * kG * (1 - std::cos(theta)) / r);
                },
                0.0, leaves, 400);
  const double speed = std::sqrt(kG * r * std::cos(leaves));
  const double height = top + r * std::cos(leaves) - r, down = speed * std::sin(leaves);
  const double lands = turning + (-down + std::sqrt(down * down + 2 * kG * height)) / kG;
  std::vector<StepReport> reports{monitor.step(0.0, {state})};
  for (int k = 1; k <= 200; ++k) {
    const double t = 0.005 * k;
    reports.push_back(monitor.step(t, {}));
    const auto at = monitor.predictedState(can, t);
    ASSERT_TRUE(at);
    // Its side (its axis along y, level) never inside the table (x <= 0.5, z <= top) nor the
    // floor: the axis at least r from both.
    const V c = at->first;
    const double out = std::max(c.x() - 0.5, 0.0), up = std::max(c.z() - top, 0.0);
    EXPECT_GE(std::hypot(out, up), r - 1e-9) << "inside the table at " << t;
    EXPECT_GE(c.z(), r - 1e-9) << "inside the floor at " << t;
  }
  for (const StepReport& report : reports) {
    for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << c.what;
  }
  const std::vector<ImpactRecord> impacts = impactsOf(reports);
  ASSERT_FALSE(impacts.empty());
  EXPECT_EQ(impacts.front().other, 0u);  // the floor
  EXPECT_NEAR(impacts.front().time, lands, 1e-8);
  EXPECT_NEAR(impacts.front().velocity_a_before.x(), speed * std::cos(leaves), 1e-8);
  EXPECT_NEAR(impacts.front().velocity_a_before.z(), -std::sqrt(down * down + 2 * kG * height),
              1e-8);
}

// A state given halfway over a table's edge (as a tracker sees a box turning over it, its face a
// hair above the edge and below the table's plane past it): the monitor goes on turning it over
// the edge from there, nothing unmodelled, its path that of the monitor that slid it there
// (1e-8 m, the tipping's integration). Before, the hair above the edge was taken for a graze
// and the flight crawled back to the edge in steps of 1e-11 s (0.4 s of CPU an update).
TEST(ShapedMonitor, AStateHalfwayOverATablesEdgeGoesOnTurningOverIt) {
  const V half(0.0625, 0.0625, 0.0625);
  Scene scene = tableScene(0.5, half, 2.0);
  ImpactMonitor slid(scene, MonitorSettings{}), given(scene, MonitorSettings{});
  BodyStateSample state;
  state.body = 0;
  state.position = V(0.25, 0, 0.5 + half.z());
  state.velocity = V(0.5, 0, 0);
  slid.step(0.0, {state});
  const double halfway = 0.52;
  slid.step(halfway, {});
  BodyStateSample there;
  there.body = 0;
  there.time = halfway;
  const auto at = slid.predictedState(0, halfway);
  ASSERT_TRUE(at);
  there.position = at->first;
  there.velocity = at->second;
  there.angular_velocity = slid.predictedAngularVelocity(0, halfway);
  there.orientation = slid.predictedOrientation(0, halfway);
  EXPECT_GT(Eigen::AngleAxisd(there.orientation).angle(), 1e-3) << "turned over the edge";
  const StepReport first = given.step(halfway, {there});
  EXPECT_TRUE(first.unmodelled.empty());
  // In lasting contact at once: the chord's two ends on the edge (x = 0.5, z = 0.5), along the
  // cube's own face's normal (turned about y), sharing its weight's part along it.
  ASSERT_EQ(first.contacts.size(), 2u);
  const V up = there.orientation * V::UnitZ();
  for (const ContactRecord& contact : first.contacts) {
    EXPECT_NEAR(contact.contact_point.x(), 0.5, 1e-12);
    EXPECT_NEAR(contact.contact_point.z(), 0.5, 1e-12);
    EXPECT_NEAR((contact.normal + up).norm(), 0.0, 1e-9);
    EXPECT_GT(contact.normal_force, 0.0);
  }
  for (int k = 1; k <= 10; ++k) {
    const double t = halfway + 0.005 * k;
    const StepReport report = given.step(t, {});
    slid.step(t, {});
    for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << c.what;
    EXPECT_NEAR((given.predictedState(0, t)->first - slid.predictedState(0, t)->first).norm(), 0.0,
                1e-8)
        << t;
  }
}

// A can (r 0.033 m, 0.12 m tall, 0.35 kg) standing flush on a table (a box, mu 0.3) struck by a
// link moving at v_o = 1 m/s (a box on a tf frame, placed every 1 ms as the node does, its face
// d = 0.045 m behind the can's side; frictionless, e = 1/2), as config/scenes/can_knock.yaml.
// Before, the link, left touching the can as it parted from it, was taken for a second obstacle
// the sliding can met: the can was held where it was struck. Now: the strike at d / v_o
// (1e-11 s), the can off at (1 + e) v_o; its slide x = 0.8 + 1.5 tau - mu g tau^2 / 2 (1e-9 m)
// until its centre of pressure, h mu ahead, reaches the table's edge (tau = (1.5 - sqrt(1.5^2 -
// 2 mu g 0.182)) / (mu g)); it turns over the edge and falls, its next impact the floor's,
// nothing unmodelled until then.
TEST(ShapedMonitor, ACanStruckOnATableByAMovingLinkSlidesToTheEdgeAndFallsOffIt) {
  const double mu = 0.3, e = 0.5, v_o = 1.0, d = 0.045;
  Scene scene;
  scene.effects.gravity = true;
  scene.effects.friction = true;
  scene.effects.spin = true;
  scene.gravity = V(0, 0, -kG);
  ASSERT_TRUE(scene.materials.addMaterial("aluminium", Material{e, mu}, "m").ok());
  ASSERT_TRUE(scene.materials.addMaterial("paddle_face", Material{e, 0.0}, "m").ok());
  scene.bodies = {canOf(0.35, 0.033, 0.12)};
  scene.obstacles = {
      scene_builders::plane("floor", V::UnitZ(), 0.0, "aluminium"),
      scene_builders::box("paddle", V::Zero(), V(0.02, 0.3, 0.2), "paddle_face"),
      scene_builders::box("table", V(0.5, 0, 0.725), V(1.0, 0.8, 0.05), "aluminium")};
  scene.obstacles[1].frame = "paddle_link";
  ImpactMonitor monitor(scene, MonitorSettings{});
  const auto place = [&](double t) {
    RigidPose link;
    link.transform.translation() = V(0.8 - 0.033 - 0.01 - d + v_o * t, 0, 0.81);
    link.velocity = V(v_o, 0, 0);
    link.time = t;
    monitor.setObstaclePose(1, link);  // the model's order: planes, then the others
  };
  BodyStateSample state;
  state.body = 0;
  state.position = V(0.8, 0, 0.81);
  place(0);
  std::vector<StepReport> reports{monitor.step(0.0, {state})};
  const double a = mu * kG, strike = d / v_o;
  const double tips = strike + (1.5 - std::sqrt(1.5 * 1.5 - 2 * a * 0.182)) / a;
  for (int k = 1; k <= 700; ++k) {
    const double t = 0.001 * k;
    place(t);
    reports.push_back(monitor.step(t, {}));
    if (t > strike && t < tips) {
      const auto at = monitor.predictedState(0, t);
      ASSERT_TRUE(at);
      const double tau = t - strike;
      EXPECT_NEAR((at->first - V(0.8 + 1.5 * tau - 0.5 * a * tau * tau, 0, 0.81)).norm(), 0.0, 1e-9)
          << t;
    }
  }
  const std::vector<ImpactRecord> impacts = impactsOf(reports);
  const ImpactRecord* landing = nullptr;
  for (const ImpactRecord& impact : impacts) {
    if (impact.other == 1 && impact.impulse > 0) {
      EXPECT_NEAR(impact.time, strike, 1e-11);
      EXPECT_NEAR((impact.velocity_a_after - V((1 + e) * v_o, 0, 0)).norm(), 0.0, 1e-9);
    }
    if (impact.time > strike + 1e-3 && landing == nullptr) landing = &impact;
  }
  ASSERT_NE(landing, nullptr);
  EXPECT_EQ(landing->other, 0u) << "the floor";
  EXPECT_GT(landing->time, tips);
  for (const StepReport& report : reports) {
    for (const UnmodelledContact& c : report.unmodelled) {
      EXPECT_GT(c.time, landing->time) << c.what;
    }
  }
}

// A mesh body is the convex hull of its vertices: a 0.1 m cube's 12 triangles with one face pushed
// in to a pyramid's dent (a vertex 0.03 m inside its top face's centre: the mesh is not convex)
// moves as the cube, its hull. Of e = 1/2, dropped flat from rest, frictionless, it strikes the
// floor with its bottom's four corners at once at sqrt(2 h / g) (1e-11 s) and leaves at e v
// without turning (1e-10 m/s), as the box's closed form
// (ABoxDroppedFlatBouncesAtTheParabolasInstant); its mass properties are the hull's (a uniform
// cube: its centre of mass at the cube's centre, not the dented solid's). Before, a mesh body was
// refused at start-up, "not yet".
TEST(ShapedMonitor, AMeshBodyMovesAsItsConvexHull) {
  const double a = 0.05, height = 0.4;
  std::vector<V> vertices;
  for (int corner = 0; corner < 8; ++corner) {
    vertices.push_back(V((corner & 1) ? a : -a, (corner & 2) ? a : -a, (corner & 4) ? a : -a));
  }
  vertices.push_back(V(0, 0, a - 0.03));  // the dent's apex, inside the cube
  const std::vector<TriangleMesh::Triangle> triangles = {
      {0, 1, 3}, {0, 3, 2},                         // bottom
      {4, 5, 8}, {5, 7, 8}, {7, 6, 8}, {6, 4, 8},   // the dented top
      {0, 1, 5}, {0, 5, 4}, {2, 3, 7}, {2, 7, 6},   // y sides
      {0, 2, 6}, {0, 6, 4}, {1, 3, 7}, {1, 7, 5}};  // x sides
  const Scene scene = meshScene(vertices, triangles, 2.0);
  ASSERT_TRUE(validateScene(scene, "s").ok()) << validateScene(scene, "s").error().message();
  ImpactMonitor monitor(scene, MonitorSettings{});
  const Eigen::Quaterniond flat = Eigen::Quaterniond::Identity();
  const std::vector<StepReport> reports = run(
      monitor, {fallingState(monitor, height, flat, 0.0), fallingState(monitor, height, flat, 0.1)},
      0.05, 0.4);
  const std::vector<ImpactRecord> impacts = firstInstant(impactsOf(reports));
  ASSERT_EQ(impacts.size(), 4u);
  const double fall = std::sqrt(2 * (height - a) / kG);
  for (const ImpactRecord& impact : impacts) {
    EXPECT_NEAR(impact.time, fall, 1e-11);
    EXPECT_NEAR(impact.velocity_a_after.z(), 0.5 * kG * fall, 1e-10);
    EXPECT_NEAR(impact.angular_velocity_a_after.norm(), 0.0, 1e-10);
    EXPECT_NEAR(impact.contact_point.z(), 0.0, 1e-12);
    EXPECT_NEAR(std::abs(impact.contact_point.x()), a, 1e-12);
    EXPECT_NEAR(std::abs(impact.contact_point.y()), a, 1e-12);
  }
}

// A tool's flat hexagonal side (a mesh body: a hexagonal prism, circumradius 0.06 m, 0.02 m
// thick, 0.8 kg, e = 1/2) dropped flat from rest, frictionless: its six bottom corners strike at
// once at sqrt(2 (z0 - h) / g) (1e-11 s), its bounces accumulate, and it rests on the six,
// m g / 6 each (1e-9 N), by the closed forms, nothing held or reported. Before, a face of more
// than four points was not modelled: the body was held where its bounces ended.
TEST(ShapedMonitor, AHexagonalToolDroppedFlatRestsOnItsSixCorners) {
  const double r = 0.06, h = 0.01, height = 0.2, m = 0.8;
  std::vector<V> vertices;
  for (const double z : {-h, h}) {
    for (int k = 0; k < 6; ++k) {
      vertices.push_back(V(r * std::cos(k * M_PI / 3), r * std::sin(k * M_PI / 3), z));
    }
  }
  std::vector<TriangleMesh::Triangle> triangles;
  for (unsigned k = 1; k + 1 < 6; ++k) {
    triangles.push_back({0, k, k + 1});
    triangles.push_back({6, 6 + k, 6 + k + 1});
  }
  for (unsigned k = 0; k < 6; ++k) {
    const unsigned next = (k + 1) % 6;
    triangles.push_back({k, next, 6 + k});
    triangles.push_back({next, 6 + next, 6 + k});
  }
  const Scene scene = meshScene(vertices, triangles, m);
  ASSERT_TRUE(validateScene(scene, "s").ok()) << validateScene(scene, "s").error().message();
  ImpactMonitor monitor(scene, MonitorSettings{});
  const Eigen::Quaterniond flat = Eigen::Quaterniond::Identity();
  // Until 0.9 s: a body 1 s past its last state is forgotten.
  const std::vector<StepReport> reports =
      run(monitor, {fallingState(monitor, height, flat, 0.0)}, 0.05, 0.9);
  const std::vector<ImpactRecord> impacts = firstInstant(impactsOf(reports));
  EXPECT_EQ(impacts.size(), 4u) << "the manifold's four of the six";
  for (const ImpactRecord& impact : impacts) {
    EXPECT_NEAR(impact.time, std::sqrt(2 * (height - h) / kG), 1e-11);
  }
  for (const StepReport& report : reports) {
    EXPECT_TRUE(report.unmodelled.empty()) << report.unmodelled.front().what;
  }
  const std::vector<ContactRecord>& contacts = reports.back().contacts;
  ASSERT_EQ(contacts.size(), 6u);
  for (const ContactRecord& contact : contacts) {
    EXPECT_EQ(contact.state, ContactState::kResting);
    EXPECT_NEAR(contact.normal_force, m * kG / 6, 1e-9);
    EXPECT_NEAR(contact.contact_point.z(), 0.0, 1e-9);
  }
}

// A can (r = 0.04 m, 0.2 m long, 0.4 kg) hanging still without gravity, struck head-on by a disc
// (a robot's paddle: a cylinder of radius 0.08 m, 1 cm thick, its axis along the arm) turning at
// a constant 1.2 rad/s about the vertical through (0, 0, 0.5), its centre 0.7 m out: the disc's
// leading rim reaches the can's side at psi = 0.3 rad, the can's axis 0.7 u + 0.12 v from the
// turning axis (u, v the radial and tangential directions at psi). Two cylinders' sides touch on
// their axes' common perpendicular: the normal is v = z x u exactly, through the can's axis at its
// middle's height, and the rim's point there moves at 1.2 (0.7 v - 0.08 u): frictionless with
// e = 1/2 the can leaves at 1.5 x 0.84 v = 1.26 v m/s, without turning. Before, GJK's normal
// between the two curved surfaces a hair apart (2.6e-5 rad off) and a contact point off its
// line gave the can 1.7e-3 rad/s about its axis.
TEST(ShapedMonitor, ATurningDiscsRimStrikesACansSideAlongTheirAxesCommonPerpendicular) {
  Scene scene;
  ASSERT_TRUE(scene.materials.addMaterial("aluminium", Material{0.5, 0.0}, "m").ok());
  scene.bodies = {canOf(0.4, 0.04, 0.2)};
  ObstacleSpec disc;
  disc.id = "paddle";
  disc.shape = ObstacleShape::kCylinder;
  disc.radius = 0.08;
  disc.length = 0.01;
  disc.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, V::UnitY()));
  disc.material = "aluminium";
  disc.frame = "paddle_link";
  scene.obstacles = {disc};
  const double rate = 1.2, psi = 0.3, strike = 0.05;
  const V u(std::cos(psi), std::sin(psi), 0), v(-std::sin(psi), std::cos(psi), 0);
  ImpactMonitor monitor(scene, MonitorSettings{});
  RigidPose link;  // the disc's frame at t = 0, turning on at a constant rate
  link.transform = Eigen::Translation3d(0, 0, 0.5) *
                   Eigen::AngleAxisd(psi - rate * strike, V::UnitZ()) *
                   Eigen::Translation3d(0.7, 0, 0);
  link.angular_velocity = V(0, 0, rate);
  link.velocity = link.angular_velocity.cross(link.transform.translation() - V(0, 0, 0.5));
  monitor.setObstaclePose(0, link);
  BodyStateSample state;
  state.body = 0;
  state.position = 0.7 * u + 0.12 * v + V(0, 0, 0.5);
  std::vector<StepReport> reports{monitor.step(0.0, {state})};
  reports.push_back(monitor.step(0.1, {}));
  const std::vector<ImpactRecord> impacts = impactsOf(reports);
  ASSERT_EQ(impacts.size(), 1u);
  const ImpactRecord& impact = impacts.front();
  // Found up to 1e-10 s before the touch (the gap left over the closing speed, 0.84 m/s), where
  // the common perpendicular is turned by the rate times that: the normal (from the can into the
  // disc) and the velocity to 1e-10; no turn at all, to 1e-12 rad/s.
  EXPECT_NEAR(impact.time, strike, 1e-10);
  EXPECT_NEAR((impact.normal + v).norm(), 0.0, 1e-10) << impact.normal.transpose();
  EXPECT_NEAR((impact.velocity_a_after - 1.5 * rate * 0.7 * v).norm(), 0.0, 1e-10);
  EXPECT_NEAR(impact.angular_velocity_a_after.norm(), 0.0, 1e-12);
}

}  // namespace
}  // namespace collision_response::core
