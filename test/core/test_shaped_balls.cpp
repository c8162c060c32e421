// Balls among shaped bodies (doc/model.md, "Balls among shaped bodies"): in a scene with a shaped
// body, its balls move as rigid spheres beside the shaped bodies, so that a ball and a box strike
// each other at the closed forms' instants and velocities; before, a ball went through a box,
// their touch reported as not modelled. A ball alone keeps a ball's closed forms there: its
// bounces' series, its slide that turns into a roll.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/validation.h"
#include "geometry/tumbling_contact.h"
#include "scene_builders.h"
#include "shaped_scenes.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using Q = Eigen::Quaterniond;
using shaped_scenes::kG;

/// A box `block` (edges `size`, mass `m_box`) and a ball `ball` (m_ball, radius r) of one material
/// of restitution e (frictionless), a floor at z = 0 (its e the material's too); gravity only
/// where `gravity`.
Scene boxAndBall(const V& size, double m_box, double m_ball, double r, double e, bool gravity) {
  Scene scene = shaped_scenes::floorScene(e, 0.5 * size, m_box);
  scene.effects.gravity = gravity;
  scene.bodies.push_back(scene_builders::ball("ball", m_ball, r, "block"));
  scene.obstacles = {scene_builders::plane("floor", V::UnitZ(), 0.0, "block")};
  EXPECT_TRUE(validateScene(scene, "scene").ok())
      << validateScene(scene, "scene").error().message();
  return scene;
}

BodyStateSample stateOf(const ImpactMonitor& monitor, const std::string& id, const V& position,
                        const V& velocity, const V& angular_velocity = V::Zero()) {
  BodyStateSample state;
  state.body = *monitor.bodyIndex(id);
  state.position = position;
  state.velocity = velocity;
  state.angular_velocity = angular_velocity;
  return state;
}

/// The impacts of `monitor` stepped every 10 ms up to `until`, none of its contacts unmodelled.
std::vector<ImpactRecord> impactsUpTo(ImpactMonitor& monitor, double until) {
  std::vector<ImpactRecord> impacts;
  for (int k = 1; 0.01 * k <= until + 1e-12; ++k) {
    const StepReport report = monitor.step(0.01 * k, {});
    for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << c.what;
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
  }
  return impacts;
}

// A ball (m = 1 kg, r = 0.05 m) thrown at -1 m/s along x at a box (a 0.1 m cube, M = 2 kg) at
// rest, in free space, e = 1/2, the line of impact through both centres: they touch at (0.3 -
// 0.05 - 0.05) / 1 = 0.2 s and leave by the one-dimensional closed form, the ball at (m - e M)
// v / (m + M) = 0, the box at (1 + e) m v / (m + M) = -0.5 m/s, neither turning; they lose (1/2)
// m M / (m + M) (1 - e^2) v^2. Before, the ball went through the box.
TEST(ShapedBalls, ABallMeetsABoxHeadOnAsTheLineOfImpactSays) {
  const double e = 0.5, m = 1.0, M = 2.0, v = -1.0;
  const Scene scene = boxAndBall(V(0.1, 0.1, 0.1), M, m, 0.05, e, false);
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t ball = *monitor.bodyIndex("ball");
  monitor.step(0.0, {stateOf(monitor, "block", V(0, 0, 1), V::Zero()),
                     stateOf(monitor, "ball", V(0.3, 0, 1), V(v, 0, 0))});
  const std::vector<ImpactRecord> impacts = impactsUpTo(monitor, 0.5);
  ASSERT_EQ(impacts.size(), 1u);
  const ImpactRecord& impact = impacts[0];
  EXPECT_NEAR(impact.time, 0.2, 1e-11);
  EXPECT_FALSE(impact.other_is_obstacle);
  const bool ball_first = impact.body_a == ball;
  const V ball_after = ball_first ? impact.velocity_a_after : impact.velocity_b_after;
  const V box_after = ball_first ? impact.velocity_b_after : impact.velocity_a_after;
  EXPECT_NEAR((ball_after - V((m - e * M) * v / (m + M), 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((box_after - V((1 + e) * m * v / (m + M), 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(impact.angular_velocity_a_after.norm() + impact.angular_velocity_b_after.norm(), 0.0,
              1e-12);
  EXPECT_NEAR(impact.energy_lost, 0.5 * m * M / (m + M) * (1 - e * e) * v * v, 1e-12);
  const auto box_at = monitor.predictedState(*monitor.bodyIndex("block"), 0.5);
  ASSERT_TRUE(box_at);
  EXPECT_NEAR(box_at->first.x(), (1 + e) * m * v / (m + M) * 0.3, 1e-11);
}

// Two balls in a scene with a box (so both move as rigid spheres), meeting head on in free space
// far from it, e = 1/2: m_1 = 1 kg at +1 m/s, m_2 = 3 kg at -1 m/s, radii 0.05 and 0.1, 0.6 m
// apart: they touch at (0.6 - 0.15) / 2 = 0.225 s and leave by the line of impact, v_1' = (m_1 v_1
// + m_2 v_2 - m_2 e (v_1 - v_2)) / (m_1 + m_2) = -1.25 m/s, v_2' = v_1' + e (v_1 - v_2) = -0.25
// m/s, neither turning: the balls' own closed form (a ball world gives the same).
TEST(ShapedBalls, TwoBallsBesideABoxMeetAsTheLineOfImpactSays) {
  Scene scene = boxAndBall(V(0.1, 0.1, 0.1), 2.0, 1.0, 0.05, 0.5, false);
  scene.bodies.push_back(scene_builders::ball("other", 3.0, 0.1, "block"));
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t first = *monitor.bodyIndex("ball");
  monitor.step(0.0, {stateOf(monitor, "block", V(0, 0, 5), V::Zero()),
                     stateOf(monitor, "ball", V(-0.3, 0, 1), V(1, 0, 0)),
                     stateOf(monitor, "other", V(0.3, 0, 1), V(-1, 0, 0))});
  const std::vector<ImpactRecord> impacts = impactsUpTo(monitor, 0.5);
  ASSERT_EQ(impacts.size(), 1u);
  EXPECT_NEAR(impacts[0].time, 0.225, 1e-11);
  const bool first_is_a = impacts[0].body_a == first;
  const V one = first_is_a ? impacts[0].velocity_a_after : impacts[0].velocity_b_after;
  const V two = first_is_a ? impacts[0].velocity_b_after : impacts[0].velocity_a_after;
  EXPECT_NEAR((one - V(-1.25, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((two - V(-0.25, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(
      impacts[0].angular_velocity_a_after.norm() + impacts[0].angular_velocity_b_after.norm(), 0.0,
      1e-12);
}

// The ball strikes the box's face x = a off its centre, at y = d (no gravity, e = 1/2): along the
// normal x the pair's effective mass is 1 / (1/m + 1/M + d^2 / I_zz) (the box's lever (a, d, 0)
// crossed with x; the ball's lever is along the normal), I_zz = M (a^2 + b^2) / 3 for half edges
// a, b, so the impulse is J = (1 + e) v / (1/m + 1/M + d^2 / I_zz); the ball leaves at -v + J / m,
// the box at -J / M along x, turning at w_z = d J / I_zz (its lever crossed with -J x). Instant:
// (0.3 - r - a) / v.
TEST(ShapedBalls, ABallStrikingABoxOffCentreTurnsItAsTheEffectiveMassSays) {
  const double e = 0.5, m = 0.3, M = 2.0, r = 0.02, a = 0.05, b = 0.08, d = 0.04, v = 2.0;
  const Scene scene = boxAndBall(V(2 * a, 2 * b, 0.06), M, m, r, e, false);
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t ball = *monitor.bodyIndex("ball");
  monitor.step(0.0, {stateOf(monitor, "block", V(0, 0, 1), V::Zero()),
                     stateOf(monitor, "ball", V(0.3, d, 1), V(-v, 0, 0))});
  const std::vector<ImpactRecord> impacts = impactsUpTo(monitor, 0.3);
  ASSERT_EQ(impacts.size(), 1u);
  const ImpactRecord& impact = impacts[0];
  EXPECT_NEAR(impact.time, (0.3 - r - a) / v, 1e-11);
  const double I_zz = M * (a * a + b * b) / 3;
  const double J = (1 + e) * v / (1 / m + 1 / M + d * d / I_zz);
  const bool ball_first = impact.body_a == ball;
  const V ball_after = ball_first ? impact.velocity_a_after : impact.velocity_b_after;
  const V box_after = ball_first ? impact.velocity_b_after : impact.velocity_a_after;
  const V box_turn = ball_first ? impact.angular_velocity_b_after : impact.angular_velocity_a_after;
  EXPECT_NEAR((ball_after - V(-v + J / m, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((box_after - V(-J / M, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((box_turn - V(0, 0, d * J / I_zz)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(impact.impulse, J, 1e-12);
}

// Under gravity on a frictionless floor: a ball (m = 1 kg, r = 0.05 m) sliding at -1 m/s into a
// box at rest (a 0.1 m cube, M = 2 kg), their centres at one height, e = 1/2: they touch at (0.3
// - 0.1) / 1 = 0.2 s, the ball stops (m - e M = 0) and the box slides on at -0.5 m/s; both go on
// resting and sliding on the floor (the ball's normal force m g, the box's m g / 4 a corner),
// never into it.
TEST(ShapedBalls, ABallSlidingIntoABoxAtRestOnTheFloorStopsItAndTheBoxSlidesOn) {
  const double e = 0.5, m = 1.0, M = 2.0, r = 0.05;
  const Scene scene = boxAndBall(V(0.1, 0.1, 0.1), M, m, r, e, true);
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t ball = *monitor.bodyIndex("ball"), box = *monitor.bodyIndex("block");
  monitor.step(0.0, {stateOf(monitor, "block", V(0, 0, 0.05), V::Zero()),
                     stateOf(monitor, "ball", V(0.3, 0, r), V(-1, 0, 0))});
  const std::vector<ImpactRecord> impacts = impactsUpTo(monitor, 0.5);
  ASSERT_EQ(impacts.size(), 1u);
  EXPECT_NEAR(impacts[0].time, 0.2, 1e-11);
  const auto ball_at = monitor.predictedState(ball, 0.5);
  const auto box_at = monitor.predictedState(box, 0.5);
  ASSERT_TRUE(ball_at && box_at);
  EXPECT_NEAR((ball_at->first - V(0.1, 0, r)).norm(), 0.0, 1e-11);
  EXPECT_NEAR(ball_at->second.norm(), 0.0, 1e-12);
  EXPECT_NEAR((box_at->first - V(-0.5 * 0.3, 0, 0.05)).norm(), 0.0, 1e-11);
  EXPECT_NEAR((box_at->second - V(-0.5, 0, 0)).norm(), 0.0, 1e-12);
  const StepReport report = monitor.step(0.51, {});
  double ball_force = 0.0, box_force = 0.0;
  for (const ContactRecord& contact : report.contacts) {
    EXPECT_TRUE(contact.other_is_obstacle);
    (contact.body_a == ball ? ball_force : box_force) += contact.normal_force;
  }
  EXPECT_NEAR(ball_force, m * kG, 1e-12);
  EXPECT_NEAR(box_force, M * kG, 1e-12);
}

// A ball dropped from rest h = 0.2 m above the floor beside a box, e = 1/2: its bounces land at
// t1 = sqrt(2 h / g), then 2 e v / g later each time scaled by e, and the series ends at t1 (1 + 2
// e / (1 - e)) = 3 t1 (a ball's "Coming to rest"), from where it rests on the floor carrying m g.
TEST(ShapedBalls, ABallBouncingBesideABoxComesToRestWhereItsBouncesSeriesEnds) {
  const double e = 0.5, m = 1.0, r = 0.05, h = 0.2;
  const Scene scene = boxAndBall(V(0.1, 0.1, 0.1), 2.0, m, r, e, true);
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t ball = *monitor.bodyIndex("ball");
  monitor.step(0.0, {stateOf(monitor, "block", V(0, 0, 0.05), V::Zero()),
                     stateOf(monitor, "ball", V(1, 0, r + h), V::Zero())});
  const double t1 = std::sqrt(2 * h / kG);
  std::vector<ImpactRecord> impacts;
  std::vector<ContactRecord> contacts;
  for (int k = 1; k <= 100; ++k) {
    const StepReport report = monitor.step(0.01 * k, {});
    for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << c.what;
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
    contacts = report.contacts;
  }
  ASSERT_GE(impacts.size(), 3u);
  EXPECT_NEAR(impacts[0].time, t1, 1e-11);
  EXPECT_NEAR(impacts[1].time, t1 + 2 * e * t1, 1e-11);
  EXPECT_NEAR(impacts[2].time, t1 + 2 * e * t1 + 2 * e * e * t1, 1e-11);
  bool resting = false;
  for (const ContactRecord& contact : contacts) {
    if (contact.body_a != ball) continue;
    resting = true;
    EXPECT_NEAR(contact.since, 3 * t1, 1e-11);
    EXPECT_NEAR(contact.normal_force, m * kG, 1e-12);
  }
  EXPECT_TRUE(resting);
}

// With friction and spin: a ball put on the floor sliding at v0 without turning (mu = 0.2, solid:
// I = 2/5 m r^2). Friction mu m g against the slip slows the centre at mu g and turns the ball at
// 5 mu g / (2 r); the slip v - w r closes at mu g (1 + m r^2 / I) = 7/2 mu g, so it rolls from t_r
// = 2 v0 / (7 mu g) at 5/7 v0, w = v / r, having gone v0 t_r - mu g t_r^2 / 2, and rolls on at
// that speed (no friction).
TEST(ShapedBalls, ABallSlidingOnTheFloorRollsFromTheClosedFormsInstantAtFiveSeventhsOfItsSpeed) {
  const double mu = 0.2, m = 0.5, r = 0.04, v0 = 1.4;
  Scene scene = boxAndBall(V(0.1, 0.1, 0.1), 2.0, m, r, 0.5, true);
  scene.effects.friction = true;
  scene.effects.spin = true;
  ASSERT_TRUE(scene.materials.addMaterial("rough", Material{0.5, mu}, "m").ok());
  scene.bodies.back().material = "rough";
  scene.obstacles = {scene_builders::plane("floor", V::UnitZ(), 0.0, "rough")};
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t ball = *monitor.bodyIndex("ball");
  monitor.step(0.0, {stateOf(monitor, "block", V(-1, 0, 0.05), V::Zero()),
                     stateOf(monitor, "ball", V(0, 0, r), V(v0, 0, 0))});
  const double t_r = 2 * v0 / (7 * mu * kG);
  const StepReport sliding = monitor.step(0.5 * t_r, {});
  for (const ContactRecord& contact : sliding.contacts) {
    if (contact.body_a != ball) continue;
    EXPECT_EQ(contact.state, ContactState::kSliding);
    EXPECT_NEAR(contact.friction_force.norm(), mu * m * kG, 1e-12);
  }
  const std::vector<ImpactRecord> impacts = impactsUpTo(monitor, 0.9);
  EXPECT_TRUE(impacts.empty());
  const auto at = monitor.predictedState(ball, 0.9);
  ASSERT_TRUE(at);
  const double rolled = v0 * t_r - 0.5 * mu * kG * t_r * t_r;
  EXPECT_NEAR(at->second.x(), 5.0 / 7 * v0, 1e-12);
  EXPECT_NEAR(at->first.x(), rolled + 5.0 / 7 * v0 * (0.9 - t_r), 1e-11);
  EXPECT_NEAR((monitor.predictedAngularVelocity(ball, 0.9) - V(0, 5.0 / 7 * v0 / r, 0)).norm(), 0.0,
              1e-10);
  const StepReport rolling = monitor.step(0.95, {});  // within the body timeout (1 s)
  bool found = false;
  for (const ContactRecord& contact : rolling.contacts) {
    if (contact.body_a != ball) continue;
    found = true;
    EXPECT_EQ(contact.state, ContactState::kRolling);
    EXPECT_EQ(contact.since, 0.0);  // the one contact, lasting since the state, slid then rolled
    EXPECT_NEAR(contact.friction_force.norm(), 0.0, 1e-12);
  }
  EXPECT_TRUE(found);
}

// Hostile speeds for a ball among shaped bodies, from 1e-100 to 1e8 m/s, thrown head on at a box
// at rest in free space (e = 1/2, the one-dimensional closed form: the box leaves at (1 + e) m v
// / (m + M), the ball at (m - e M) v / (m + M)), and a ball 1e200 m away: every impact and every
// state the monitor gives is finite, the box leaves at the closed form (1e-12 relative) where they
// meet within the steps, and the ball is never inside the box at a step's end (GJK); a speed
// too slow to meet in 0.5 s meets nothing. (At 1e150 m/s the ball's first contact with the far
// floor, parallel to its path, is taken for a lasting contact, held and reported: not yet; the
// ball world alone holds speeds to 1e200, HardCases.MagnitudesFrom1eMinus150To1e200.)
TEST(ShapedBalls, HostileSpeedsAndPlacesGiveFiniteAnswersAndNeverInside) {
  const double e = 0.5, m = 1.0, M = 2.0, r = 0.05;
  for (const double speed : {1e-100, 1e-9, 1.0, 1e3, 1e8}) {
    const Scene scene = boxAndBall(V(0.1, 0.1, 0.1), M, m, r, e, false);
    ImpactMonitor monitor(scene, MonitorSettings{});
    const std::size_t ball = *monitor.bodyIndex("ball"), box = *monitor.bodyIndex("block");
    monitor.step(0.0, {stateOf(monitor, "block", V(0, 0, 1), V::Zero()),
                       stateOf(monitor, "ball", V(0.3, 0, 1), V(-speed, 0, 0))});
    std::size_t met = 0;
    for (int k = 1; k <= 50; ++k) {
      const StepReport report = monitor.step(0.01 * k, {});
      for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << speed << ": " << c.what;
      for (const ImpactRecord& impact : report.impacts) {
        EXPECT_TRUE(impact.velocity_a_after.allFinite() && impact.velocity_b_after.allFinite() &&
                    std::isfinite(impact.time))
            << speed;
        met += impact.other_is_obstacle ? 0 : 1;
      }
      const auto b = monitor.predictedState(ball, 0.01 * k);
      const auto x = monitor.predictedState(box, 0.01 * k);
      ASSERT_TRUE(b && x);
      ASSERT_TRUE(b->first.allFinite() && b->second.allFinite() && x->first.allFinite() &&
                  x->second.allFinite())
          << speed;
      auto tumbling =
          TumblingBody::create(Cuboid{V(0.05, 0.05, 0.05)}, V::Ones(), 0.01 * k, x->first,
                               x->second, V::Zero(), Q::Identity(), V::Zero());
      ASSERT_TRUE(tumbling.ok());
      PlacedShape sphere;
      sphere.shape = Sphere{b->first, r};
      sphere.pose.time = 0.01 * k;
      sphere.pose.transform.translation() = b->first;
      EXPECT_FALSE(gapAt(tumbling.value(), sphere, 0.01 * k).overlapping) << speed << " at " << k;
    }
    const auto x = monitor.predictedState(box, 0.5);
    if (speed >= 1.0) {
      EXPECT_EQ(met, 1u) << speed;
      EXPECT_NEAR(x->second.x(), -(1 + e) * m * speed / (m + M), 1e-12 * speed) << speed;
    } else {
      EXPECT_EQ(met, 0u) << speed;
    }
  }
  // A ball 1e200 m away: no meeting, every answer finite.
  const Scene scene = boxAndBall(V(0.1, 0.1, 0.1), M, m, r, e, false);
  ImpactMonitor monitor(scene, MonitorSettings{});
  monitor.step(0.0, {stateOf(monitor, "block", V(0, 0, 1), V::Zero()),
                     stateOf(monitor, "ball", V(1e200, 0, 1), V(-1, 0, 0))});
  for (int k = 1; k <= 10; ++k) EXPECT_TRUE(monitor.step(0.01 * k, {}).impacts.empty());
  const auto far = monitor.predictedState(*monitor.bodyIndex("ball"), 0.1);
  ASSERT_TRUE(far);
  EXPECT_TRUE(far->first.allFinite());
}

/// Linear and angular momentum (about the origin) and kinetic energy of the scene's bodies at
/// `time`: a box's tensor m / 12 (b^2 + c^2, ...) turned into the world, a solid ball's 2/5 m r^2.
struct Momenta {
  V linear = V::Zero(), angular = V::Zero();
  double energy = 0.0;
};
Momenta momentaOf(const ImpactMonitor& monitor, const Scene& scene, double time) {
  Momenta total;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& spec = scene.bodies[i];
    const std::size_t body = *monitor.bodyIndex(spec.id);
    const auto state = monitor.predictedState(body, time);
    EXPECT_TRUE(state);
    const double m = spec.mass;
    const V w = monitor.predictedAngularVelocity(body, time);
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity() * 0.4 * m * spec.radius * spec.radius;
    if (spec.shape == BodyShape::kBox) {
      const V s = spec.size.cwiseProduct(spec.size);
      const Eigen::Matrix3d local =
          (m / 12 * V(s.y() + s.z(), s.x() + s.z(), s.x() + s.y())).asDiagonal();
      const Eigen::Matrix3d R = monitor.predictedOrientation(body, time).toRotationMatrix();
      inertia = R * local * R.transpose();
    }
    total.linear += m * state->second;
    total.angular += m * state->first.cross(state->second) + inertia * w;
    total.energy += 0.5 * m * state->second.squaredNorm() + 0.5 * w.dot(inertia * w);
  }
  return total;
}

// Thirty random throws of a ball at a tumbling box of three different sides, in free space (e in
// [0.5, 1], frictionless, random spins and aims): the linear momentum kept (1e-12 relative), the
// angular momentum kept (1e-11: the box's free rotation is elliptic functions read back), no
// energy gained (1e-12 relative), and the two apart at the end (GJK), never inside each other.
TEST(ShapedBalls, RandomThrowsAtATumblingBoxKeepMomentumAndNeverGainEnergyNorEndInside) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int met = 0;
  for (int throw_index = 0; throw_index < 30; ++throw_index) {
    const double e = 0.75 + 0.25 * unit(random);
    const Scene scene = boxAndBall(V(0.12, 0.08, 0.04), 1.5, 0.4, 0.03, e, false);
    ImpactMonitor monitor(scene, MonitorSettings{});
    const Q turn(Eigen::AngleAxisd(3 * unit(random), V::Random().normalized()));
    BodyStateSample box = stateOf(monitor, "block", V(-0.3, 0, 1), V(1 + unit(random), 0, 0),
                                  20 * V(unit(random), unit(random), unit(random)));
    box.orientation = turn;
    const V aim = 0.04 * V(0, unit(random), unit(random));
    monitor.step(0.0,
                 {box, stateOf(monitor, "ball", V(0.3, 0, 1) + aim, V(-1.5 + unit(random), 0, 0),
                               10 * V(unit(random), unit(random), unit(random)))});
    const Momenta before = momentaOf(monitor, scene, 0.0);
    const std::vector<ImpactRecord> impacts = impactsUpTo(monitor, 0.5);
    met += !impacts.empty();
    const Momenta after = momentaOf(monitor, scene, 0.5);
    EXPECT_LT((after.linear - before.linear).norm(), 1e-12 * before.linear.norm()) << throw_index;
    EXPECT_LT((after.angular - before.angular).norm(), 1e-11 * before.angular.norm())
        << throw_index;
    EXPECT_LE(after.energy, before.energy * (1 + 1e-12)) << throw_index;
    const std::size_t block = *monitor.bodyIndex("block"), ball = *monitor.bodyIndex("ball");
    auto tumbling = TumblingBody::create(
        Cuboid{V(0.06, 0.04, 0.02)}, V::Ones(), 0.5, monitor.predictedState(block, 0.5)->first,
        monitor.predictedState(block, 0.5)->second, V::Zero(),
        monitor.predictedOrientation(block, 0.5), monitor.predictedAngularVelocity(block, 0.5));
    ASSERT_TRUE(tumbling.ok());
    PlacedShape sphere;
    const V centre = monitor.predictedState(ball, 0.5)->first;
    sphere.shape = Sphere{centre, 0.03};
    sphere.pose.time = 0.5;
    sphere.pose.transform.translation() = centre;
    const SurfaceGap gap = gapAt(tumbling.value(), sphere, 0.5);
    EXPECT_FALSE(gap.overlapping) << throw_index;
    EXPECT_GE(gap.gap_upper, 0.0) << throw_index;
  }
  EXPECT_GE(met, 25);  // the throws meet
}

}  // namespace
}  // namespace collision_response::core
