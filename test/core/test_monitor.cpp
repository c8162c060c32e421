// The impact monitor without ROS: states in, impacts out, against closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/playback.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
using V = Eigen::Vector3d;

Scene sceneWithRestitution(double restitution) {
  Scene scene;
  EXPECT_TRUE(
      scene.materials.addMaterial("test", Material{restitution, {}}, "materials/test").ok());
  return scene;
}

BodySpec ball(const std::string& id, double mass, double radius) {
  return scene_builders::ball(id, mass, radius, "test");
}

BodyStateSample state(const ImpactMonitor& monitor, const std::string& id, double time,
                      const V& position, const V& velocity) {
  BodyStateSample sample;
  sample.body = *monitor.bodyIndex(id);
  sample.time = time;
  sample.position = position;
  sample.velocity = velocity;
  return sample;
}

// States of bodies moving in straight lines, as a source that ignores collisions publishes them.
std::vector<BodyStateSample> straight(const ImpactMonitor& monitor,
                                      const std::vector<std::string>& ids,
                                      const std::vector<V>& start, const std::vector<V>& velocity,
                                      double time) {
  std::vector<BodyStateSample> states;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    states.push_back(state(monitor, ids[i], time, start[i] + velocity[i] * time, velocity[i]));
  }
  return states;
}

TEST(Monitor, HitBetweenTwoStatesIsFoundAtItsExactInstant) {
  // A at x = 0 moving +1 m/s, B at x = 1 moving -1 m/s, radii 0.1: the gap 0.8 m closes at
  // 2 m/s, contact at t = 0.4 s, at x = 0.5. Equal masses, e = 0.5: v_a' = -0.5, v_b' = 0.5.
  Scene scene = sceneWithRestitution(0.5);
  scene.bodies = {ball("a", 1.0, 0.1), ball("b", 1.0, 0.1)};
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::vector<std::string> ids = {"a", "b"};
  const std::vector<V> start = {V(0, 0, 0), V(1, 0, 0)};
  const std::vector<V> velocity = {V(1, 0, 0), V(-1, 0, 0)};
  EXPECT_TRUE(monitor.step(0.0, straight(monitor, ids, start, velocity, 0.0)).impacts.empty());
  const StepReport report = monitor.step(1.0, straight(monitor, ids, start, velocity, 1.0));
  ASSERT_EQ(report.impacts.size(), 1u);
  const ImpactRecord& impact = report.impacts[0];
  EXPECT_NEAR(impact.time, 0.4, 4 * kEps);
  EXPECT_EQ(monitor.body(impact.body_a).id, "a");
  EXPECT_EQ(monitor.body(impact.other).id, "b");
  EXPECT_NEAR(impact.contact_point.x(), 0.5, 4 * kEps);
  EXPECT_EQ(impact.normal, V(1, 0, 0));
  EXPECT_EQ(impact.velocity_a_after, V(-0.5, 0, 0));
  EXPECT_EQ(impact.velocity_b_after, V(0.5, 0, 0));
  EXPECT_EQ(impact.restitution, 0.5);
  // J = (1 + e) mu |d| = 1.5 * 0.5 * 2 = 1.5; lost (1/2) mu (1 - e^2) d^2 = 0.25 * 0.75 * 4 = 0.75.
  EXPECT_NEAR(impact.impulse, 1.5, 4 * kEps);
  EXPECT_NEAR(impact.energy_lost, 0.75, 4 * kEps);
}

TEST(Monitor, SourceThatIgnoresCollisionsGetsTheImpactOnce) {
  Scene scene = sceneWithRestitution(0.5);
  scene.bodies = {ball("a", 1.0, 0.1), ball("b", 1.0, 0.1)};
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::vector<std::string> ids = {"a", "b"};
  const std::vector<V> start = {V(0, 0, 0), V(1, 0, 0)};
  const std::vector<V> velocity = {V(1, 0, 0), V(-1, 0, 0)};
  std::size_t impacts = 0;
  for (int k = 0; k <= 20; ++k) {  // 0.1 s apart, the balls pass through each other
    impacts +=
        monitor.step(0.1 * k, straight(monitor, ids, start, velocity, 0.1 * k)).impacts.size();
  }
  EXPECT_EQ(impacts, 1u);
}

/// A ball "ball" (0.1 kg, r = 0.05 m) and the plane "floor" z = 0, of restitution e.
Scene ballOnFloorScene(double restitution) {
  Scene scene = sceneWithRestitution(restitution);
  scene.bodies = {ball("ball", 0.1, 0.05)};
  ObstacleSpec floor;
  floor.id = "floor";
  floor.material = "test";
  scene.obstacles = {floor};
  return scene;
}

TEST(Monitor, ImpactAlreadyAppliedBySourceIsFound) {
  // The source bounced the ball itself: the state after the wall already moves away.
  ImpactMonitor monitor(ballOnFloorScene(0.8), MonitorSettings{});
  // At t = 0: 0.25 m up (surface 0.2 m above the floor), falling at 1 m/s: contact at t = 0.2.
  monitor.step(0.0, {state(monitor, "ball", 0.0, V(0, 0, 0.25), V(0, 0, -1))});
  const StepReport report =
      monitor.step(0.3, {state(monitor, "ball", 0.3, V(0, 0, 0.13), V(0, 0, 0.8))});
  ASSERT_EQ(report.impacts.size(), 1u);
  EXPECT_NEAR(report.impacts[0].time, 0.2, 4 * kEps);
  EXPECT_TRUE(report.impacts[0].other_is_obstacle);
  EXPECT_EQ(report.impacts[0].normal, V(0, 0, -1));
  EXPECT_EQ(report.impacts[0].velocity_a_after, V(0, 0, 0.8));  // -e v, exactly
  EXPECT_NEAR(report.impacts[0].contact_point.z(), 0.0, 4 * kEps);
}

TEST(Monitor, ImpactAtTheStepsStartStaysReportedAndTheStateLackingItIsSaid) {
  // The source puts the ball on the floor, falling at 1 m/s, at t = 0.1 (say a stepped cluster
  // let it go there). Its impact is at that instant, found by the step that starts there, after
  // the source sampled its state at 0.2 from the ball's unbounced motion (0.05 m into the floor,
  // still falling). The impact is reported (e = 0.5: leaving at 0.5 m/s); the state is taken
  // (a monitor follows its input) and said to lack it: it falls short of the velocity after
  // the impact, 0.5 m/s, by 1.5 m/s, all of the impact's change (more than half of it).
  ImpactMonitor monitor(ballOnFloorScene(0.5), MonitorSettings{});
  monitor.step(0.0, {state(monitor, "ball", 0.0, V(0, 0, 1), V(0, 0, 0))});
  EXPECT_TRUE(
      monitor.step(0.1, {state(monitor, "ball", 0.1, V(0, 0, 0.05), V(0, 0, -1))}).impacts.empty());
  const StepReport report =
      monitor.step(0.2, {state(monitor, "ball", 0.2, V(0, 0, -0.05), V(0, 0, -1))});
  ASSERT_EQ(report.impacts.size(), 1u);
  EXPECT_EQ(report.impacts[0].time, 0.1);
  EXPECT_EQ(report.impacts[0].velocity_a_after, V(0, 0, 0.5));
  ASSERT_EQ(report.contradicted.size(), 1u);
  EXPECT_EQ(report.contradicted[0].body, *monitor.bodyIndex("ball"));
  EXPECT_EQ(report.contradicted[0].impact_time, 0.1);
  EXPECT_EQ(report.contradicted[0].state_time, 0.2);
  EXPECT_EQ(report.contradicted[0].missing, 1.5);
  const auto predicted = monitor.predictedState(*monitor.bodyIndex("ball"), 0.2);
  ASSERT_TRUE(predicted);
  EXPECT_EQ(predicted->first, V(0, 0, -0.05));
  EXPECT_EQ(predicted->second, V(0, 0, -1));
  // The source, told of the impact, sends its bounced state next: taken, nothing to say, and
  // no impact again (the ball overlapped the floor).
  const StepReport next =
      monitor.step(0.3, {state(monitor, "ball", 0.3, V(0, 0, 0.15), V(0, 0, 0.5))});
  EXPECT_TRUE(next.impacts.empty());
  EXPECT_TRUE(next.contradicted.empty());
  EXPECT_NEAR(monitor.predictedState(*monitor.bodyIndex("ball"), 0.4)->first.z(), 0.2, 4 * kEps);
}

// Issue 39, item 4: a ball (r = 0.05 m, e = 0.5, gravity g = 9.81, the floor z = 0) thrown from
// (0, 0, 1) at (5, 0, -5) m/s every 0.7 s, its states at 100 Hz. The state after a bounce of the
// monitor's ball was not used: the monitor's ball bounced on where no ball was. Each throw
// meets the floor s = (sqrt(25 + 2 g (1 - r)) - 5) / g after it, at x = 5 s (closed form), and
// its impact is reported once; every state is the ball's track from its instant. A source whose
// ball bounces (e = 0.5, as the monitor's) says nothing more; one whose ball passes through
// the floor (a tracker that never saw the bounce) lacks each impact, said once a throw.
TEST(Monitor, Issue39_Item4_EveryThrowIsFollowedAndAStateLackingTheBounceIsSaid) {
  const double g = 9.81, r = 0.05, e = 0.5, period = 0.7;
  const int throws = 6, per_throw = 70;
  const double s = (std::sqrt(25 + 2 * g * (1 - r)) - 5) / g;  // the floor, after each throw
  const double up = e * (5 + g * s);                           // leaving it
  for (const bool bounces : {true, false}) {
    SCOPED_TRACE(bounces ? "the source's ball bounces" : "the source's ball passes through");
    Scene scene = ballOnFloorScene(e);
    scene.effects.gravity = true;
    scene.gravity = V(0, 0, -g);
    ImpactMonitor monitor(scene, MonitorSettings{});
    std::vector<ImpactRecord> impacts;
    std::size_t contradicted = 0;
    for (int k = 0; k < throws * per_throw; ++k) {
      const double t = 0.01 * k, since = 0.01 * (k % per_throw);
      V position(5 * since, 0, 1 - 5 * since - 0.5 * g * since * since);
      V velocity(5, 0, -5 - g * since);
      if (bounces && since > s) {
        const double u = since - s;
        position.z() = r + up * u - 0.5 * g * u * u;
        velocity.z() = up - g * u;
      }
      const StepReport report = monitor.step(t, {state(monitor, "ball", t, position, velocity)});
      impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
      contradicted += report.contradicted.size();
      EXPECT_EQ(report.states_set_aside, 0u);
      // The monitor follows its input: the track is the state.
      const auto predicted = monitor.predictedState(0, t);
      ASSERT_TRUE(predicted);
      EXPECT_EQ(predicted->first, position) << "t = " << t;
      EXPECT_EQ(predicted->second, velocity) << "t = " << t;
    }
    ASSERT_EQ(impacts.size(), static_cast<std::size_t>(throws));
    for (int i = 0; i < throws; ++i) {
      const ImpactRecord& impact = impacts[static_cast<std::size_t>(i)];
      EXPECT_NEAR(impact.time, period * i + s, 1e-12) << "throw " << i;
      EXPECT_NEAR(impact.contact_point.x(), 5 * s, 1e-11) << "throw " << i;
      EXPECT_NEAR(impact.velocity_a_after.z(), up, 1e-12) << "throw " << i;
    }
    EXPECT_EQ(contradicted, bounces ? 0u : static_cast<std::size_t>(throws));
  }
}

// Issue 39, item 4: whatever the monitor sets aside is counted. A ball 0.25 m up (0.2 m above the
// floor) falling at 1 m/s from t = 0 meets the floor at 0.2; an update to 0.3 whose state is
// stamped 0.1 (earlier than that impact, found from the track before it) is set aside: the
// motion after the impact (e = 0.8: up at 0.8 m/s) is kept, and the state counted.
TEST(Monitor, Issue39_Item4_AStateOlderThanAnImpactFoundAfterItIsSetAsideAndCounted) {
  ImpactMonitor monitor(ballOnFloorScene(0.8), MonitorSettings{});
  monitor.step(0.0, {state(monitor, "ball", 0.0, V(0, 0, 0.25), V(0, 0, -1))});
  const StepReport report =
      monitor.step(0.3, {state(monitor, "ball", 0.1, V(0, 0, 0.15), V(0, 0, -1))});
  ASSERT_EQ(report.impacts.size(), 1u);
  EXPECT_NEAR(report.impacts[0].time, 0.2, 4 * kEps);
  EXPECT_EQ(report.states_set_aside, 1u);
  EXPECT_TRUE(report.contradicted.empty());
  EXPECT_EQ(monitor.predictedState(0, 0.3)->second, V(0, 0, 0.8));
}

TEST(Monitor, DiscreteFindsTheImpactAtTheSampleAfter) {
  Scene scene = sceneWithRestitution(0.5);
  scene.detection = Detection::kDiscrete;
  scene.bodies = {ball("a", 1.0, 0.1), ball("b", 1.0, 0.1)};
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::vector<std::string> ids = {"a", "b"};
  const std::vector<V> start = {V(0, 0, 0), V(1, 0, 0)};
  const std::vector<V> velocity = {V(1, 0, 0), V(-1, 0, 0)};
  std::vector<ImpactRecord> impacts;
  for (int k = 0; k <= 12; ++k) {  // samples 0.15 s apart: 0.3, then 0.45, after contact at 0.4
    for (const auto& impact :
         monitor.step(0.15 * k, straight(monitor, ids, start, velocity, 0.15 * k)).impacts) {
      impacts.push_back(impact);
    }
  }
  ASSERT_EQ(impacts.size(), 1u);         // once, though the balls overlap for several samples
  EXPECT_EQ(impacts[0].time, 0.15 * 3);  // the first sample after 0.4 s
  // Overlapping by 0.1 m at 0.45 s: the line of impact is still the line of centres.
  EXPECT_EQ(impacts[0].normal, V(1, 0, 0));
}

// A sample that catches a fast ball with its centre exactly on the other's: no line of centres,
// so the line of impact is the direction of approach (not a missed impact).
TEST(Monitor, DiscreteCoincidentCentresUseTheDirectionOfApproach) {
  Scene scene = sceneWithRestitution(1.0);
  scene.detection = Detection::kDiscrete;
  scene.bodies = {ball("fast", 1.0, 0.02), ball("still", 1.0, 0.01)};
  ImpactMonitor monitor(scene, MonitorSettings{});
  monitor.step(0.0, {state(monitor, "fast", 0.0, V(0.95, 0, 0), V(50, 0, 0)),
                     state(monitor, "still", 0.0, V(1, 0, 0), V::Zero())});
  const StepReport report =
      monitor.step(0.001, {state(monitor, "fast", 0.001, V(1, 0, 0), V(50, 0, 0))});
  ASSERT_EQ(report.impacts.size(), 1u);
  EXPECT_EQ(report.impacts[0].normal, V(1, 0, 0));
  // Equal masses, e = 1: the velocities are exchanged.
  EXPECT_EQ(report.impacts[0].velocity_a_after, V::Zero());
  EXPECT_EQ(report.impacts[0].velocity_b_after, V(50, 0, 0));
}

TEST(Monitor, DifferentStampsArePredictedToOneInstant) {
  // b's state is older (t = 0) than a's (t = 0.2): b is predicted forward; contact at t = 0.4.
  Scene scene = sceneWithRestitution(1.0);
  scene.bodies = {ball("a", 1.0, 0.1), ball("b", 1.0, 0.1)};
  ImpactMonitor monitor(scene, MonitorSettings{});
  monitor.step(0.0, {state(monitor, "a", 0.0, V(0, 0, 0), V(1, 0, 0)),
                     state(monitor, "b", 0.0, V(1, 0, 0), V(-1, 0, 0))});
  EXPECT_TRUE(
      monitor.step(0.2, {state(monitor, "a", 0.2, V(0.2, 0, 0), V(1, 0, 0))}).impacts.empty());
  const StepReport report = monitor.step(0.6, {state(monitor, "a", 0.6, V(0.6, 0, 0), V(1, 0, 0))});
  ASSERT_EQ(report.impacts.size(), 1u);
  EXPECT_NEAR(report.impacts[0].time, 0.4, 4 * kEps);
}

TEST(Monitor, StaleStatesAreDropped) {
  Scene scene = sceneWithRestitution(1.0);
  scene.bodies = {ball("a", 1.0, 0.1)};
  ImpactMonitor monitor(scene, MonitorSettings{});
  monitor.step(1.0, {state(monitor, "a", 1.0, V(0, 0, 0), V(1, 0, 0))});
  const StepReport report = monitor.step(0.5, {state(monitor, "a", 0.5, V(9, 9, 9), V(0, 0, 0))});
  EXPECT_EQ(report.stale_states, 1u);
  EXPECT_EQ(monitor.predictedState(0, 1.0)->first, V(0, 0, 0));
}

// Final velocities of every body after the steps, by id.
std::map<std::string, V> finalVelocities(const ImpactMonitor& monitor, double time) {
  std::map<std::string, V> result;
  for (std::size_t i = 0; i < monitor.bodyCount(); ++i) {
    result[monitor.body(i).id] = monitor.predictedState(i, time)->second;
  }
  return result;
}

// Newton's cradle, e = 1, equal masses: ball 1 strikes four touching balls; the impact travels
// ball by ball (each pair exchanges velocities exactly) and ball 5 leaves with ball 1's speed.
TEST(Monitor, CradleOfFiveElasticBalls) {
  Scene scene = sceneWithRestitution(1.0);
  std::vector<BodyStateSample> states;
  for (int i = 1; i <= 5; ++i)
    scene.bodies.push_back(ball("ball_" + std::to_string(i), 0.26, 0.02));
  ImpactMonitor monitor(scene, MonitorSettings{});
  std::vector<BodyStateSample> start;
  start.push_back(state(monitor, "ball_1", 0.0, V(-0.06, 0, 0), V(0.5, 0, 0)));
  for (int i = 2; i <= 5; ++i) {
    start.push_back(
        state(monitor, "ball_" + std::to_string(i), 0.0, V(0.04 * (i - 2), 0, 0), V::Zero()));
  }
  monitor.step(0.0, start);
  const StepReport report = monitor.step(0.1, {});
  ASSERT_EQ(report.impacts.size(), 4u);
  for (const ImpactRecord& impact : report.impacts) {
    EXPECT_NEAR(impact.time, 0.04, 4 * kEps);  // the 0.02 m gap closes at 0.5 m/s
    EXPECT_EQ(impact.energy_lost, 0.0);
  }
  const auto velocities = finalVelocities(monitor, 0.1);
  EXPECT_EQ(velocities.at("ball_1"), V::Zero());
  EXPECT_EQ(velocities.at("ball_2"), V::Zero());
  EXPECT_EQ(velocities.at("ball_3"), V::Zero());
  EXPECT_EQ(velocities.at("ball_4"), V::Zero());
  EXPECT_EQ(velocities.at("ball_5"), V(0.5, 0, 0));
}

// Two balls strike a resting middle one from both sides at the same instant. The joint solve
// (A J = -(1 + e) d with A = [[2, -1], [-1, 2]] for unit masses, d = (-1, -1)) gives
// J = (1 + e)(1, 1): the middle ball stays at rest and the outer ones leave at -e and +e, as
// off a wall. The answer is symmetric.
TEST(Monitor, SymmetricStrikeFromBothSides) {
  Scene scene = sceneWithRestitution(0.5);
  scene.bodies = {ball("left", 1.0, 0.1), ball("middle", 1.0, 0.1), ball("right", 1.0, 0.1)};
  ImpactMonitor monitor(scene, MonitorSettings{});
  monitor.step(0.0, {state(monitor, "left", 0.0, V(-1, 0, 0), V(1, 0, 0)),
                     state(monitor, "middle", 0.0, V(0, 0, 0), V::Zero()),
                     state(monitor, "right", 0.0, V(1, 0, 0), V(-1, 0, 0))});
  const StepReport report = monitor.step(1.0, {});
  ASSERT_EQ(report.impacts.size(), 2u);
  EXPECT_EQ(report.impacts[0].time, report.impacts[1].time);
  EXPECT_EQ(report.impacts[0].impulse, report.impacts[1].impulse);
  EXPECT_NEAR(report.impacts[0].impulse, 1.5, 4 * kEps);
  const auto velocities = finalVelocities(monitor, 1.0);
  EXPECT_EQ(velocities.at("left").x(), -velocities.at("right").x());
  EXPECT_NEAR(velocities.at("left").x(), -0.5, 4 * kEps);
  EXPECT_NEAR(velocities.at("middle").x(), 0.0, 4 * kEps);
}

// The same scene listed in every order, its states arriving in every order: the same impacts
// and velocities, bit for bit (bodies are indexed by sorted id).
TEST(Monitor, OrderOfListingAndOfStatesDoesNotMatter) {
  // A small rack struck off-centre: simultaneous, asymmetric contacts.
  struct Start {
    std::string id;
    V position, velocity;
  };
  const double r = 0.028575;
  const std::vector<Start> starts = {{"cue", V(0, 0.01, 0), V(3, 0, 0)},
                                     {"one", V(1, 0, 0), V::Zero()},
                                     {"two", V(1 + r * std::sqrt(3.0), -r, 0), V::Zero()},
                                     {"three", V(1 + r * std::sqrt(3.0), r, 0), V::Zero()},
                                     {"four", V(1 + 2 * r * std::sqrt(3.0), 0, 0), V::Zero()}};
  std::vector<std::size_t> order = {0, 1, 2, 3, 4};
  std::map<std::string, V> reference;
  std::vector<double> reference_impulses;
  int permutations = 0;
  do {
    Scene scene = sceneWithRestitution(0.8);
    for (const std::size_t i : order) scene.bodies.push_back(ball(starts[i].id, 0.17, r));
    ImpactMonitor monitor(scene, MonitorSettings{});
    std::vector<BodyStateSample> samples;
    for (const std::size_t i : order) {
      samples.push_back(state(monitor, starts[i].id, 0.0, starts[i].position, starts[i].velocity));
    }
    monitor.step(0.0, samples);
    const StepReport report = monitor.step(1.0, {});
    std::vector<double> impulses;
    for (const ImpactRecord& impact : report.impacts) impulses.push_back(impact.impulse);
    const auto velocities = finalVelocities(monitor, 1.0);
    if (permutations == 0) {
      reference = velocities;
      reference_impulses = impulses;
      EXPECT_GE(impulses.size(), 3u);
    } else {
      ASSERT_EQ(velocities, reference) << "permutation " << permutations;
      ASSERT_EQ(impulses, reference_impulses) << "permutation " << permutations;
    }
    ++permutations;
  } while (std::next_permutation(order.begin(), order.end()));
  EXPECT_EQ(permutations, 120);
}

// The monitor holds the scene it watches (the ROS layer reads it there): as given, its lists in
// the scene's order, and with what live tuning changed; a copy taken before the tuning keeps
// what it was given.
TEST(Monitor, HoldsItsSceneAsGivenAndAsTuned) {
  Scene scene = sceneWithRestitution(0.5);
  scene.bodies = {ball("b", 1.0, 0.1), ball("a", 1.0, 0.1)};
  ImpactMonitor monitor(scene, MonitorSettings{});
  EXPECT_EQ(monitor.body(0).id, "a");  // indexed by sorted id
  ASSERT_EQ(monitor.scene().bodies.size(), 2u);
  EXPECT_EQ(monitor.scene().bodies[0].id, "b");
  const ImpactMonitor before = monitor;
  MaterialTable materials = scene.materials;
  materials.setCombineRule(CombineRule::kMax);
  monitor.tune(Detection::kDiscrete, 0.25, materials);
  EXPECT_EQ(monitor.scene().detection, Detection::kDiscrete);
  EXPECT_EQ(monitor.scene().restitution_threshold, 0.25);
  EXPECT_EQ(monitor.scene().materials.combineRule(), CombineRule::kMax);
  EXPECT_EQ(before.scene().detection, Detection::kContinuous);
  EXPECT_EQ(before.scene().restitution_threshold, 0.0);
  EXPECT_EQ(before.scene().materials.combineRule(), CombineRule::kMin);
}

// The broadphase only leaves out pairs that cannot meet: a random gas (with gravity and without,
// continuous and discrete) gives the very same impacts, to the bit, with it and with every pair.
TEST(Monitor, BroadphaseGivesTheSameImpactsAsEveryPair) {
  for (const bool gravity : {false, true}) {
    for (const Detection detection : {Detection::kContinuous, Detection::kDiscrete}) {
      Scene scene = sceneWithRestitution(0.9);
      scene.effects.gravity = gravity;
      scene.detection = detection;
      std::mt19937_64 engine(17);
      std::uniform_real_distribution<double> unit(0, 1);
      for (int i = 0; i < 300; ++i) {
        BodySpec body =
            ball("gas_" + std::to_string(1000 + i), 0.1 + unit(engine), 0.02 + 0.08 * unit(engine));
        body.position = V(4 * unit(engine), 4 * unit(engine), 4 * unit(engine));
        body.velocity = V(6 * unit(engine) - 3, 6 * unit(engine) - 3, 6 * unit(engine) - 3);
        scene.bodies.push_back(body);
      }
      const V normals[] = {V(1, 0, 0),  V(-1, 0, 0), V(0, 1, 0),
                           V(0, -1, 0), V(0, 0, 1),  V(0, 0, -1)};
      for (int i = 0; i < 6; ++i) {
        ObstacleSpec wall;
        wall.id = "wall_" + std::to_string(i);
        wall.material = "test";
        wall.normal = normals[i];
        wall.offset = i % 2 ? -4.0 : 0.0;
        scene.obstacles.push_back(wall);
      }
      MonitorSettings with, without;
      without.broadphase = false;
      ImpactMonitor fast(scene, with), slow(scene, without);
      std::vector<BodyStateSample> start;
      for (const BodySpec& body : scene.bodies) {
        start.push_back(state(fast, body.id, 0.0, body.position, body.velocity));
      }
      fast.step(0.0, start);
      slow.step(0.0, start);
      std::size_t impacts = 0;
      for (int k = 1; k <= 50; ++k) {
        const StepReport a = fast.step(0.02 * k, {}), b = slow.step(0.02 * k, {});
        ASSERT_EQ(a.impacts.size(), b.impacts.size()) << "step " << k;
        for (std::size_t i = 0; i < a.impacts.size(); ++i) {
          ASSERT_EQ(a.impacts[i].time, b.impacts[i].time);
          ASSERT_EQ(a.impacts[i].body_a, b.impacts[i].body_a);
          ASSERT_EQ(a.impacts[i].other, b.impacts[i].other);
          ASSERT_EQ(a.impacts[i].velocity_a_after, b.impacts[i].velocity_a_after);
          ASSERT_EQ(a.impacts[i].velocity_b_after, b.impacts[i].velocity_b_after);
        }
        impacts += a.impacts.size();
      }
      EXPECT_GT(impacts, 100u) << "the gas must collide for the comparison to mean something";
    }
  }
}

// A state's orientation (world from body) is carried into its body's track, and read by nothing
// yet: a ball's does not matter, so the same states turned any way give the same impacts to the
// bit (issue 42 gives bodies shapes, whose orientation will matter).
TEST(Monitor, AStatesOrientationIsCarriedAndChangesNothing) {
  ImpactMonitor plain(ballOnFloorScene(0.8), MonitorSettings{});
  ImpactMonitor turned(ballOnFloorScene(0.8), MonitorSettings{});
  const std::size_t ball = *turned.bodyIndex("ball");
  EXPECT_EQ(turned.lastOrientation(ball).coeffs(), Eigen::Quaterniond::Identity().coeffs());
  const Eigen::Quaterniond first(Eigen::AngleAxisd(0.7, V(1, 2, 3).normalized()));
  const Eigen::Quaterniond second(Eigen::AngleAxisd(-2.5, V(0, 1, 0)));
  // Falling 0.2 m at 1 m/s onto the floor (contact at t = 0.2), then a state after the bounce.
  const auto states = [&](const ImpactMonitor& monitor, double time, const V& position,
                          const V& velocity, const Eigen::Quaterniond& orientation) {
    BodyStateSample sample = state(monitor, "ball", time, position, velocity);
    sample.orientation = orientation;
    return std::vector<BodyStateSample>{sample};
  };
  const Eigen::Quaterniond identity = Eigen::Quaterniond::Identity();
  std::vector<StepReport> reports[2];
  reports[0].push_back(plain.step(0.0, states(plain, 0.0, V(0, 0, 0.25), V(0, 0, -1), identity)));
  reports[1].push_back(turned.step(0.0, states(turned, 0.0, V(0, 0, 0.25), V(0, 0, -1), first)));
  EXPECT_EQ(turned.lastOrientation(ball).coeffs(), first.coeffs());
  reports[0].push_back(plain.step(0.5, {}));
  reports[1].push_back(turned.step(0.5, {}));
  reports[0].push_back(plain.step(0.6, states(plain, 0.6, V(0, 0, 0.3), V(0, 0, 0.2), identity)));
  reports[1].push_back(turned.step(0.6, states(turned, 0.6, V(0, 0, 0.3), V(0, 0, 0.2), second)));
  EXPECT_EQ(turned.lastOrientation(ball).coeffs(), second.coeffs());
  ASSERT_EQ(reports[0][1].impacts.size(), 1u);
  for (std::size_t i = 0; i < reports[0].size(); ++i) {
    ASSERT_EQ(reports[0][i].impacts.size(), reports[1][i].impacts.size()) << i;
    for (std::size_t k = 0; k < reports[0][i].impacts.size(); ++k) {
      const ImpactRecord& a = reports[0][i].impacts[k];
      const ImpactRecord& b = reports[1][i].impacts[k];
      EXPECT_EQ(a.time, b.time);
      EXPECT_EQ(a.contact_point, b.contact_point);
      EXPECT_EQ(a.velocity_a_after, b.velocity_a_after);
      EXPECT_EQ(a.angular_velocity_a_after, b.angular_velocity_a_after);
      EXPECT_EQ(a.impulse, b.impulse);
    }
  }
}

// An imposed state (an impact a scene player was told of, ImpactMonitor::advance) is the motion
// just after an impact, which turns no body at its instant: the track keeps the orientation it
// carries rather than taking the imposed state's default.
TEST(Monitor, AnImposedImpactKeepsTheOrientation) {
  ImpactMonitor monitor(ballOnFloorScene(0.8), MonitorSettings{});
  const std::size_t ball = *monitor.bodyIndex("ball");
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(0.7, V(1, 2, 3).normalized()));
  BodyStateSample start = state(monitor, "ball", 0.0, V(0, 0, 1), V(0, 0, 0));
  start.orientation = turned;
  monitor.step(0.0, {start});
  monitor.advance(0.2, {state(monitor, "ball", 0.1, V(0, 0, 0.95), V(1, 0, 0))});
  EXPECT_EQ(monitor.lastOrientation(ball).coeffs(), turned.coeffs());
  EXPECT_EQ(monitor.predictedState(ball, 0.1)->second.x(), 1.0);  // the imposed state was taken
}

// The scene's initial orientation of a body is carried by the scene player's model, through an
// impact applied to it (an impact turns no body at its instant).
TEST(Playback, TheScenesOrientationIsCarriedThroughAnImpact) {
  Scene scene = ballOnFloorScene(0.8);
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(1.1, V(0, 0, 1)));
  scene.bodies[0].orientation = turned;
  scene.bodies[0].position = V(0, 0, 0.25);
  scene.bodies[0].velocity = V(0, 0, -1);
  Playback playback(scene, 1e-9, 0.0);
  EXPECT_EQ(playback.orientation(0, 0.1).coeffs(), turned.coeffs());
  ASSERT_TRUE(playback.applyImpact(0, 0.2, V(0, 0, 0.05), V(0, 0, 0.8)));
  EXPECT_EQ(playback.orientation(0, 0.3).coeffs(), turned.coeffs());
  EXPECT_EQ(playback.velocity(0, 0.3).z(), 0.8);  // the impact was applied
}

}  // namespace
}  // namespace collision_response::core

namespace collision_response {
namespace {
// The loop a scene player runs: states from core::Playback at 100 Hz, the monitor's impacts
// applied back to it. Galperin's two-ball chain with equal masses and e = 1 against a wall: the
// heavy ball (1 m/s) meets the light one at rest at t = 0.45 s, exactly at a sample (the impact
// is found by the next step), the light one bounces off the wall at 0.95 s and gives its speed
// back at 1.45 s, again at a sample: three impacts, and the heavy ball leaves at +1 m/s, the
// light one at rest (each impact an exact exchange).
TEST(Playback, ImpactsAtTheSampleInstantsAreApplied) {
  using V = Eigen::Vector3d;
  core::Scene scene;
  ASSERT_TRUE(
      static_cast<bool>(scene.materials.addMaterial("elastic", core::Material{1.0, {}}, "m")));
  core::BodySpec light, heavy;
  light.id = "light";
  light.mass = 1.0;
  light.radius = 0.05;
  light.material = "elastic";
  light.position = V(0.55, 0, 0);
  heavy = light;
  heavy.id = "heavy";
  heavy.position = V(1.1, 0, 0);
  heavy.velocity = V(-1, 0, 0);
  scene.bodies = {light, heavy};
  core::ObstacleSpec wall;
  wall.id = "wall";
  wall.normal = V(1, 0, 0);
  wall.material = "elastic";
  scene.obstacles = {wall};
  core::MonitorSettings settings;
  settings.body_timeout = 100;
  core::ImpactMonitor monitor(scene, settings);
  core::Playback playback(scene, settings.contact_tolerance, 0.0);
  std::size_t impacts = 0;
  for (int k = 0; k <= 300; ++k) {
    const double t = 0.01 * k;
    std::vector<core::BodyStateSample> states;
    for (std::size_t i = 0; i < 2; ++i) {
      core::BodyStateSample state;
      state.body = *monitor.bodyIndex(scene.bodies[i].id);
      state.time = t;
      state.position = playback.position(i, t);
      state.velocity = playback.velocity(i, t);
      states.push_back(state);
    }
    const core::StepReport report = monitor.step(t, states);
    for (const core::ImpactRecord& impact : report.impacts)
      playback.applyImpact(monitor, impact, true);
    impacts += report.impacts.size();
  }
  EXPECT_EQ(impacts, 3u);
  EXPECT_EQ(playback.velocity(1, 3.0), V(1, 0, 0));
  EXPECT_EQ(playback.velocity(0, 3.0), V(0, 0, 0));
}

// Issue 27, item 2: a body's initial spin comes from the scene (BodySpec::angular_velocity) and
// the played states carry it. A solid ball (I = 2/5 m r^2) set down at rest on a rough floor
// spinning at omega0 about y slips backwards at omega0 r; friction mu m g pushes it forwards:
// v = mu g t, omega_y = omega0 - 5/2 mu g t / r, until it rolls at t = omega0 r / (7/2 mu g),
// from when v = 2/7 omega0 r = omega_y r.
TEST(Playback, ABallSetDownSpinningIsPulledAlongUntilItRolls) {
  using V = Eigen::Vector3d;
  constexpr double kG = 9.81, kMu = 0.2, kRadius = 0.05, kOmega0 = 40.0;
  core::Scene scene;
  scene.effects.gravity = scene.effects.friction = scene.effects.spin = true;
  scene.gravity = V(0, 0, -kG);
  ASSERT_TRUE(
      static_cast<bool>(scene.materials.addMaterial("cloth", core::Material{0.5, kMu}, "m")));
  core::BodySpec ball;
  ball.id = "ball";
  ball.mass = 0.17;
  ball.radius = kRadius;
  ball.material = "cloth";
  ball.position = V(0, 0, kRadius);
  ball.angular_velocity = V(0, kOmega0, 0);
  scene.bodies = {ball};
  core::ObstacleSpec floor;
  floor.id = "floor";
  floor.normal = V(0, 0, 1);
  floor.material = "cloth";
  scene.obstacles = {floor};
  core::Playback playback(scene, 1e-9, 0.0);
  const double rolling_from = kOmega0 * kRadius / (3.5 * kMu * kG);
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.005 * k;
    const double v = t < rolling_from ? kMu * kG * t : 2.0 / 7.0 * kOmega0 * kRadius;
    const double omega = t < rolling_from ? kOmega0 - 2.5 * kMu * kG * t / kRadius : v / kRadius;
    const V velocity = playback.velocity(0, t);
    const V spin = playback.angularVelocity(0, t);
    EXPECT_NEAR(velocity.x(), v, 1e-12) << "at " << t << " s";
    EXPECT_NEAR(velocity.z(), 0.0, 1e-12) << "at " << t << " s";
    EXPECT_NEAR(spin.y(), omega, 1e-12 / kRadius) << "at " << t << " s";
    EXPECT_NEAR(spin.x(), 0.0, 1e-12) << "at " << t << " s";
    EXPECT_NEAR(spin.z(), 0.0, 1e-12) << "at " << t << " s";
  }
}

// The contacts asked for at an instant between two played ones are that instant's, also when
// the instant was asked for before (it is kept as the view): a clay ball (e = 0) dropped from
// h = 0.2 m above contact meets the floor at sqrt(2 h / g) = 0.2019 s and rests on it from then.
// Asked at 0.1 s and 0.3 s (played), then at 0.15 s, 0.3 s and 0.15 s again: no contact at
// 0.15 s, one at 0.3 s. The view's early return left the contacts of the instant asked before.
TEST(Playback, TheContactsOfAnInstantAskedAgainAreItsOwn) {
  using V = Eigen::Vector3d;
  constexpr double kG = 9.81, kRadius = 0.05, kDrop = 0.2;
  core::Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -kG);
  ASSERT_TRUE(
      static_cast<bool>(scene.materials.addMaterial("clay", core::Material{0.0, 0.0}, "m")));
  core::BodySpec ball;
  ball.id = "ball";
  ball.mass = 0.1;
  ball.radius = kRadius;
  ball.material = "clay";
  ball.position = V(0, 0, kRadius + kDrop);
  scene.bodies = {ball};
  core::ObstacleSpec floor;
  floor.id = "floor";
  floor.normal = V(0, 0, 1);
  floor.material = "clay";
  scene.obstacles = {floor};
  core::Playback playback(scene, 1e-9, 0.0);
  ASSERT_LT(0.15, std::sqrt(2 * kDrop / kG));
  ASSERT_GT(0.3, std::sqrt(2 * kDrop / kG));
  EXPECT_TRUE(playback.contacts(0.1).empty());
  EXPECT_EQ(playback.contacts(0.3).size(), 1u);
  EXPECT_TRUE(playback.contacts(0.15).empty());
  EXPECT_EQ(playback.contacts(0.3).size(), 1u);
  EXPECT_TRUE(playback.contacts(0.15).empty()) << "the contacts of 0.3 s, asked for before";
}

// An impact heard after its instant was made final (a node answering more than a period late)
// cannot be played: the body goes on without it. The caller is told (false), so that the scene
// player can say so instead of showing bodies inside each other without a word.
TEST(Playback, AnImpactOlderThanWhatIsFinalIsRefusedAndSaysSo) {
  using V = Eigen::Vector3d;
  core::Scene scene;
  core::BodySpec ball;
  ball.id = "ball";
  ball.radius = 0.05;
  ball.material = "tennis_ball";
  ball.velocity = V(1, 0, 0);
  scene.bodies = {ball};
  core::ObstacleSpec wall;
  wall.id = "wall";
  wall.normal = V(-1, 0, 0);
  wall.offset = -10.0;
  wall.material = "concrete";
  scene.obstacles = {wall};
  const core::ImpactMonitor monitor(scene, core::MonitorSettings{});
  core::Playback playback(scene, 1e-9, 0.0);
  EXPECT_EQ(playback.position(0, 0.1), V(0.1, 0, 0));
  EXPECT_EQ(playback.position(0, 0.2), V(0.2, 0, 0));  // asking for 0.2 makes 0.1 final
  core::ImpactRecord late;
  late.time = 0.05;
  late.body_a = 0;
  late.other = 0;
  late.other_is_obstacle = true;
  late.normal = V(1, 0, 0);
  late.contact_point = V(0.1, 0, 0);
  late.velocity_a_after = V(-1, 0, 0);
  EXPECT_FALSE(playback.applyImpact(monitor, late, true));
  EXPECT_EQ(playback.velocity(0, 0.2), V(1, 0, 0)) << "a refused impact changes nothing";
  core::ImpactRecord in_time = late;
  in_time.time = 0.15;
  in_time.contact_point = V(0.2, 0, 0);
  EXPECT_TRUE(playback.applyImpact(monitor, in_time, true));
  EXPECT_EQ(playback.velocity(0, 0.2), V(-1, 0, 0));
  EXPECT_NEAR(playback.position(0, 0.2).x(), 0.15 - 0.05, 1e-15);  // from the centre at 0.15 s

  // The batch (one step's records, as the scene player applies them) names the refused one in
  // either detection, and applies the other.
  for (const bool exact_contact : {true, false}) {
    core::Playback batch(scene, 1e-9, 0.0);
    EXPECT_EQ(batch.position(0, 0.1), V(0.1, 0, 0));
    EXPECT_EQ(batch.position(0, 0.2), V(0.2, 0, 0));
    const std::vector<std::size_t> refused =
        batch.applyImpacts(monitor, {late, in_time}, exact_contact);
    EXPECT_EQ(refused, std::vector<std::size_t>{0}) << "exact_contact " << exact_contact;
    EXPECT_EQ(batch.velocity(0, 0.2), V(-1, 0, 0)) << "exact_contact " << exact_contact;
  }
}

// Before the watcher's impact is heard (over ROS, a period or more after its instant), the played
// motion under continuous detection bounces the body itself by the same model, so no state shows
// it inside the floor; under discrete detection it falls on into the floor, where the watcher
// finds the overlap at its sample. A ball of e = 1/2 dropped from h = 1 m onto the floor: it
// meets the floor at t1 = sqrt(2 h / g) at v1 = g t1 and leaves at v1 / 2, so its apex is at
// t1 + v1 / (2 g) = 1.5 t1, at r + h / 4; falling on instead, it is at r + h - g (1.5 t1)^2 / 2 =
// r - 1.25 h then.
TEST(Playback, BodiesBounceBeforeTheImpactIsHeardUnderContinuousDetectionOnly) {
  using V = Eigen::Vector3d;
  constexpr double kH = 1.0, kR = 0.05, kG = 9.81;
  core::Scene scene = core::ballOnFloorScene(0.5);
  ASSERT_EQ(scene.bodies[0].radius, kR);
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -kG);
  scene.bodies[0].position = V(0, 0, kR + kH);
  const double t1 = std::sqrt(2 * kH / kG);
  const double apex = 1.5 * t1;

  scene.detection = core::Detection::kContinuous;
  const core::Playback played(scene, 1e-9, 0.0);
  for (int k = 1; k <= 100; ++k) {  // no state inside the floor on the way
    EXPECT_GE(played.position(0, apex * k / 100).z(), kR - 1e-12) << apex * k / 100 << " s";
  }
  EXPECT_NEAR(played.position(0, apex).z(), kR + kH / 4, 1e-12);
  EXPECT_NEAR(played.velocity(0, apex).z(), 0.0, 1e-12);

  scene.detection = core::Detection::kDiscrete;
  const core::Playback falling(scene, 1e-9, 0.0);
  EXPECT_NEAR(falling.position(0, apex).z(), kR - 1.25 * kH, 1e-12);
  EXPECT_NEAR(falling.velocity(0, apex).z(), -1.5 * kG * t1, 1e-12);
}

}  // namespace
}  // namespace collision_response

namespace collision_response {
namespace {
// Issue 41, item 10: an impact heard late (the node busy) but within the replay window is played
// from its instant, through the same instants, as if it had been heard at once; older than the
// window, it is refused. A ball thrown at v0 = (-1.5, 0, 4.05) m/s under g = 9.81 m/s^2, asked for
// every 10 ms, meets an obstacle the played motion does not know (a paddle on a tf frame) at
// tau = 0.255 s, heard 45 ms later (after the instant 0.30 s was played; window 0.1 s): from
// tau it moves from c = p(tau) at v' = (1.2, 0, 0.5), so at t > tau it is at
// c + v' (t - tau) + g (t - tau)^2 / 2 (closed form).
TEST(Playback, AnImpactHeardLateWithinTheReplayWindowIsPlayedFromItsInstant) {
  using V = Eigen::Vector3d;
  constexpr double kG = 9.81, kTau = 0.255, kWindow = 0.1;
  core::Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -kG);
  core::BodySpec ball;
  ball.id = "ball";
  ball.radius = 0.02;
  ball.material = "tennis_ball";
  ball.position = V(2.0, 0, 0.6);
  ball.velocity = V(-1.5, 0, 4.05);
  scene.bodies = {ball};
  const auto lob = [&](double t) { return V(2.0 - 1.5 * t, 0, 0.6 + 4.05 * t - 0.5 * kG * t * t); };
  const V centre = lob(kTau), after(1.2, 0, 0.5);
  const auto bounced = [&](double t) {
    const double s = t - kTau;
    return V(centre + after * s + 0.5 * s * s * V(0, 0, -kG));
  };
  const auto grid = [](int k) { return 0.01 * k; };

  core::Playback in_time(scene, 1e-9, 0.0, kWindow);
  core::Playback late(scene, 1e-9, 0.0, kWindow);
  core::Playback too_late(scene, 1e-9, 0.0, kWindow);
  for (int k = 1; k <= 26; ++k) {
    in_time.position(0, grid(k));
    late.position(0, grid(k));
    too_late.position(0, grid(k));
  }
  EXPECT_TRUE(in_time.applyImpact(0, kTau, centre, after));  // heard at once
  for (int k = 27; k <= 30; ++k) {
    in_time.position(0, grid(k));
    EXPECT_NEAR((late.position(0, grid(k)) - lob(grid(k))).norm(), 0, 1e-12);  // not heard yet
  }
  EXPECT_TRUE(late.applyImpact(0, kTau, centre, after)) << "heard 45 ms late, within 0.1 s";
  for (int k = 27; k <= 60; ++k) {
    const double t = grid(k);
    EXPECT_NEAR((late.position(0, t) - bounced(t)).norm(), 0, 1e-12) << t << " s";
    EXPECT_NEAR((late.velocity(0, t) - (after + V(0, 0, -kG * (t - kTau)))).norm(), 0, 1e-12);
    EXPECT_EQ(late.position(0, t), in_time.position(0, t)) << "the same steps, the same motion";
  }
  // 0.255 s is more than the window before 0.40 s: what is final is at 0.29 s, after it.
  for (int k = 27; k <= 40; ++k) too_late.position(0, grid(k));
  EXPECT_FALSE(too_late.applyImpact(0, kTau, centre, after));
  EXPECT_NEAR((too_late.position(0, grid(41)) - lob(grid(41))).norm(), 0, 1e-12);
}

}  // namespace
}  // namespace collision_response
