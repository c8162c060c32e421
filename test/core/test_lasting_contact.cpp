// Lasting contact in the monitor: bodies that rest, slide, roll and stack under gravity, each
// against a closed form (derived in the comment above its test), and never inside anything.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "collision_response/core/body.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/validation.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using scene_builders::ball;
using scene_builders::plane;
using scene_builders::sphere;
constexpr double kG = 9.81;

/// A scene with gravity (0, 0, -g) and the given effects.
Scene gravityScene(bool friction = false, bool spin = false) {
  Scene scene;
  scene.effects.gravity = true;
  scene.effects.friction = friction;
  scene.effects.spin = spin;
  scene.gravity = V(0, 0, -kG);
  return scene;
}

void addMaterial(Scene& scene, const std::string& name, double restitution, double friction) {
  ASSERT_TRUE(scene.materials.addMaterial(name, Material{restitution, friction}, "m").ok());
}

MonitorSettings longLived() {
  MonitorSettings settings;
  settings.body_timeout = 1e9;  // the monitor moves the bodies itself: no states after the first
  return settings;
}

/// Runs the monitor on its own motion (no states after the first) at `rate` until `end`,
/// calling `check(time)` after every step; returns every impact.
template <class Check>
std::vector<ImpactRecord> run(ImpactMonitor& monitor, const std::vector<BodyStateSample>& start,
                              double rate, double end, Check check) {
  std::vector<ImpactRecord> impacts;
  monitor.step(0.0, start);
  const int steps = static_cast<int>(std::lround(end * rate));
  for (int k = 1; k <= steps; ++k) {
    const double t = k / rate;
    const StepReport report = monitor.step(t, {});
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
    check(t, report);
  }
  return impacts;
}

BodyStateSample state(const ImpactMonitor& monitor, const std::string& id, const V& position,
                      const V& velocity = V::Zero(), const V& angular = V::Zero()) {
  BodyStateSample sample;
  sample.body = *monitor.bodyIndex(id);
  sample.position = position;
  sample.velocity = velocity;
  sample.angular_velocity = angular;
  return sample;
}

/// How far a ball is inside a plane (> 0: inside).
double depthInPlane(const V& centre, double radius, const V& normal, double offset) {
  return offset + radius - normal.normalized().dot(centre);
}

// A frictionless incline at theta through the origin, descending towards +x (normal (sin t, 0,
// cos t)). A ball released at rest touching it slides down at g sin t: its centre moves by
// x(t) = 1/2 g sin t t^2 along (cos t, 0, -sin t), and it stays on the plane.
TEST(LastingContact, SlidesDownAFrictionlessIncline) {
  const double theta = 10.0 * M_PI / 180.0, r = 0.05;
  const V up(std::sin(theta), 0, std::cos(theta)), down(std::cos(theta), 0, -std::sin(theta));
  Scene scene = gravityScene();
  addMaterial(scene, "ice", 0.5, 0.0);
  scene.bodies = {ball("ball", 0.2, r, "ice")};
  scene.obstacles = {plane("incline", up, 0.0, "ice")};
  ImpactMonitor monitor(scene, longLived());
  const V start = r * up;
  double worst = 0;
  const auto impacts =
      run(monitor, {state(monitor, "ball", start)}, 100, 2.0, [&](double t, const StepReport&) {
        const V expected = start + 0.5 * kG * std::sin(theta) * t * t * down;
        worst = std::max(worst, (monitor.predictedState(0, t)->first - expected).norm());
      });
  EXPECT_TRUE(impacts.empty());
  EXPECT_LT(worst, 1e-13);
  const StepReport report = monitor.step(2.01, {});
  ASSERT_EQ(report.contacts.size(), 1u);
  EXPECT_EQ(report.contacts[0].state, ContactState::kSliding);
  EXPECT_NEAR(report.contacts[0].normal_force, 0.2 * kG * std::cos(theta), 1e-12);
  EXPECT_EQ(report.contacts[0].since, 0.0);
}

// With friction and spin a solid ball rolls: a = 5/7 g sin t (mu = 0.5 >= 2/7 tan t), and it
// turns at w = v / r about the axis up x down, the contact point at rest.
TEST(LastingContact, RollsDownARoughInclineAtFiveSevenths) {
  const double theta = 20.0 * M_PI / 180.0, r = 0.05;
  const V up(std::sin(theta), 0, std::cos(theta)), down(std::cos(theta), 0, -std::sin(theta));
  Scene scene = gravityScene(true, true);
  addMaterial(scene, "rubber", 0.5, 0.5);
  scene.bodies = {ball("ball", 0.2, r, "rubber")};
  scene.obstacles = {plane("incline", up, 0.0, "rubber")};
  ImpactMonitor monitor(scene, longLived());
  const V start = r * up;
  double worst = 0;
  run(monitor, {state(monitor, "ball", start)}, 100, 1.0, [&](double t, const StepReport& report) {
    const V expected = start + 0.5 * 5.0 / 7.0 * kG * std::sin(theta) * t * t * down;
    worst = std::max(worst, (monitor.predictedState(0, t)->first - expected).norm());
    ASSERT_EQ(report.contacts.size(), 1u);
    EXPECT_EQ(report.contacts[0].state, ContactState::kRolling);
    EXPECT_NEAR(report.contacts[0].friction_force.norm(), 2.0 / 7.0 * 0.2 * kG * std::sin(theta),
                1e-12);
  });
  EXPECT_LT(worst, 1e-12);
}

// Without spin a ball on a rough incline is a block. Launched up the slope at v0 with
// tan t < mu, it slides up decelerating at g (sin t + mu cos t), stops after
// t_s = v0 / (g (sin t + mu cos t)) at s = v0^2 / (2 g (sin t + mu cos t)) up the slope, and
// static friction holds it there.
TEST(LastingContact, StopsOnARoughInclineBelowTheFrictionAngle) {
  const double theta = 15.0 * M_PI / 180.0, r = 0.05, mu = 0.6, v0 = 2.0;
  ASSERT_LT(std::tan(theta), mu);
  const V up(std::sin(theta), 0, std::cos(theta)), down(std::cos(theta), 0, -std::sin(theta));
  Scene scene = gravityScene(true, false);
  addMaterial(scene, "felt", 0.2, mu);
  scene.bodies = {ball("ball", 0.2, r, "felt")};
  scene.obstacles = {plane("incline", up, 0.0, "felt")};
  ImpactMonitor monitor(scene, longLived());
  const V start = r * up;
  const double deceleration = kG * (std::sin(theta) + mu * std::cos(theta));
  const double stop_time = v0 / deceleration;
  const V rest = start - v0 * v0 / (2 * deceleration) * down;
  run(monitor, {state(monitor, "ball", start, -v0 * down)}, 100, 1.0,
      [&](double t, const StepReport& report) {
        const V expected =
            t < stop_time ? V(start - (v0 * t - 0.5 * deceleration * t * t) * down) : rest;
        EXPECT_LT((monitor.predictedState(0, t)->first - expected).norm(), 1e-12) << t;
        if (t > stop_time) {
          ASSERT_EQ(report.contacts.size(), 1u);
          EXPECT_EQ(report.contacts[0].state, ContactState::kResting);
          EXPECT_NEAR(report.contacts[0].friction_force.norm(), 0.2 * kG * std::sin(theta), 1e-12);
        }
      });
  EXPECT_LT(monitor.predictedState(0, 1.0)->second.norm(), 1e-15);
}

// A centred stack of three balls on the floor, released at rest touching: it stays, and each
// contact carries the weight above it: (m1 + m2 + m3) g, (m2 + m3) g, m3 g.
TEST(LastingContact, CentredStackOfThreeHolds) {
  const double r = 0.05;
  Scene scene = gravityScene();
  addMaterial(scene, "wood", 0.6, 0.0);
  scene.bodies = {ball("a", 0.3, r, "wood"), ball("b", 0.2, r, "wood"), ball("c", 0.1, r, "wood")};
  scene.obstacles = {plane("floor", V(0, 0, 1), 0.0, "wood")};
  ImpactMonitor monitor(scene, longLived());
  const std::vector<BodyStateSample> start = {state(monitor, "a", V(0, 0, r)),
                                              state(monitor, "b", V(0, 0, 3 * r)),
                                              state(monitor, "c", V(0, 0, 5 * r))};
  StepReport last;
  const auto impacts =
      run(monitor, start, 100, 2.0, [&](double, const StepReport& report) { last = report; });
  EXPECT_TRUE(impacts.empty());
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR((monitor.predictedState(i, 2.0)->first - V(0, 0, (2 * i + 1) * r)).norm(), 0.0,
                1e-15);
  }
  ASSERT_EQ(last.contacts.size(), 3u);
  // In the order of pairs: a-b, a-floor, b-c.
  EXPECT_NEAR(last.contacts[0].normal_force, 0.3 * kG, 1e-13);
  EXPECT_NEAR(last.contacts[1].normal_force, 0.6 * kG, 1e-13);
  EXPECT_NEAR(last.contacts[2].normal_force, 0.1 * kG, 1e-13);
}

// Issue 27, item 5: the same stack at x = 1.7e308 (past 2^1023, where the touching bands and
// the swept boxes' padding overflow) fell through its floor with no contact; the intake now
// refuses such states (kMaxResolvedCoordinate). Just below that bound, at the largest double
// below 2^1022, the arithmetic holds: no impact, the balls stay where they were placed, and the
// contacts are finite and carry the whole weight, (0.3 + 0.2 + 0.1) g, into the floor. (Which
// pairs touch is coarse there: the bands are 2^-48 (|a| + |b|) wide, far wider than the balls.)
TEST(LastingContact, CentredStackOfThreeStaysUpAtTheLargestResolvedX) {
  const double r = 0.05;
  const double x = std::nextafter(kMaxResolvedCoordinate, 0.0);
  Scene scene = gravityScene();
  addMaterial(scene, "wood", 0.6, 0.0);
  scene.bodies = {ball("a", 0.3, r, "wood"), ball("b", 0.2, r, "wood"), ball("c", 0.1, r, "wood")};
  scene.obstacles = {plane("floor", V(0, 0, 1), 0.0, "wood")};
  ImpactMonitor monitor(scene, longLived());
  const std::vector<BodyStateSample> start = {state(monitor, "a", V(x, 0, r)),
                                              state(monitor, "b", V(x, 0, 3 * r)),
                                              state(monitor, "c", V(x, 0, 5 * r))};
  StepReport last;
  const auto impacts =
      run(monitor, start, 100, 2.0, [&](double, const StepReport& report) { last = report; });
  EXPECT_TRUE(impacts.empty());
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(monitor.predictedState(i, 2.0)->first, V(x, 0, (2 * i + 1) * r));
  }
  ASSERT_FALSE(last.contacts.empty());
  double into_floor = 0.0;
  for (const ContactRecord& contact : last.contacts) {
    EXPECT_TRUE(std::isfinite(contact.normal_force));
    EXPECT_TRUE(contact.contact_point.allFinite());
    if (contact.other_is_obstacle) into_floor += contact.normal_force;
  }
  EXPECT_NEAR(into_floor, 0.6 * kG, 1e-13);
}

// The stack holds with the same contacts and forces as at the origin at x = 1e12: its bands,
// 2^-48 (1e12 + 1e12) = 0.0071 m for a pair, are narrower than every gap between surfaces that
// do not touch (2 r = 0.1 m and more: the middle ball and the floor, the bottom and the top
// ball). The limit of that is |x| = 2^47 r (7.04e12 m), where a pair's band is r.
TEST(LastingContact, CentredStackOfThreeHoldsAtATeraMetre) {
  const double r = 0.05;
  const double x = 1e12;
  Scene scene = gravityScene();
  addMaterial(scene, "wood", 0.6, 0.0);
  scene.bodies = {ball("a", 0.3, r, "wood"), ball("b", 0.2, r, "wood"), ball("c", 0.1, r, "wood")};
  scene.obstacles = {plane("floor", V(0, 0, 1), 0.0, "wood")};
  ImpactMonitor monitor(scene, longLived());
  const std::vector<BodyStateSample> start = {state(monitor, "a", V(x, 0, r)),
                                              state(monitor, "b", V(x, 0, 3 * r)),
                                              state(monitor, "c", V(x, 0, 5 * r))};
  StepReport last;
  run(monitor, start, 100, 2.0, [&](double, const StepReport& report) { last = report; });
  ASSERT_EQ(last.contacts.size(), 3u);
  // In the order of pairs: a-b, a-floor, b-c.
  EXPECT_NEAR(last.contacts[0].normal_force, 0.3 * kG, 1e-13);
  EXPECT_NEAR(last.contacts[1].normal_force, 0.6 * kG, 1e-13);
  EXPECT_NEAR(last.contacts[2].normal_force, 0.1 * kG, 1e-13);
}

// A putty ball (e = 0.2) dropped centred from 0.2 m onto a ball resting on the floor bounces to
// rest on it, after finitely many impacts; it never goes into it, and ends with its centre 2 r
// above the other's.
TEST(LastingContact, PuttyDroppedOnAStackRestsOnTop) {
  const double r = 0.05;
  Scene scene = gravityScene();
  addMaterial(scene, "putty", 0.2, 0.0);
  scene.bodies = {ball("lower", 0.3, r, "putty"), ball("upper", 0.1, r, "putty")};
  scene.obstacles = {plane("floor", V(0, 0, 1), 0.0, "putty")};
  ImpactMonitor monitor(scene, longLived());
  const std::vector<BodyStateSample> start = {state(monitor, "lower", V(0, 0, r)),
                                              state(monitor, "upper", V(0, 0, 3 * r + 0.2))};
  double deepest = -1;
  const auto impacts = run(monitor, start, 100, 3.0, [&](double t, const StepReport&) {
    const V lower = monitor.predictedState(0, t)->first,
            upper = monitor.predictedState(1, t)->first;
    deepest = std::max(deepest, 2 * r - (upper - lower).norm());
    deepest = std::max(deepest, r - lower.z());
  });
  EXPECT_LT(impacts.size(), 200u);
  EXPECT_LT(deepest, 1e-9 * r + 1e-15);
  EXPECT_NEAR(monitor.predictedState(1, 3.0)->first.z() - monitor.predictedState(0, 3.0)->first.z(),
              2 * r, 1e-9 * 2 * r);
  EXPECT_NEAR(monitor.predictedState(0, 3.0)->first.z(), r, 1e-9 * r);
}

// A ball dropped into a V-groove of two planes tilted by b either way ends at rest touching both,
// each pushing N = m g / (2 cos b).
TEST(LastingContact, ComesToRestInAVGroove) {
  const double b = 30.0 * M_PI / 180.0, r = 0.05, m = 0.2;
  const V left(std::sin(b), 0, std::cos(b)), right(-std::sin(b), 0, std::cos(b));
  Scene scene = gravityScene();
  addMaterial(scene, "steel", 0.5, 0.0);
  scene.bodies = {ball("ball", m, r, "steel")};
  scene.obstacles = {plane("left", left, 0.0, "steel"), plane("right", right, 0.0, "steel")};
  ImpactMonitor monitor(scene, longLived());
  double deepest = -1;
  StepReport last;
  run(monitor, {state(monitor, "ball", V(0.01, 0, 0.3))}, 100, 4.0,
      [&](double t, const StepReport& report) {
        const V centre = monitor.predictedState(0, t)->first;
        deepest = std::max(
            {deepest, depthInPlane(centre, r, left, 0), depthInPlane(centre, r, right, 0)});
        last = report;
      });
  EXPECT_LT(deepest, 1e-9 * r + 1e-15);
  const V bottom(0, 0, r / std::cos(b));
  EXPECT_LT((monitor.predictedState(0, 4.0)->first - bottom).norm(), 1e-8 * r);
  ASSERT_EQ(last.contacts.size(), 2u);
  EXPECT_NEAR(last.contacts[0].normal_force, m * kG / (2 * std::cos(b)), 1e-9);
  EXPECT_NEAR(last.contacts[1].normal_force, m * kG / (2 * std::cos(b)), 1e-9);
}

// A ball slides down a frictionless incline into a wall at its foot (normal -x): with e = 0 it
// stops in the corner at once; with e = 0.5 it bounces in the corner to rest. Either way it
// never enters either plane, and at rest the incline pushes m g / cos t, the wall m g tan t.
TEST(LastingContact, ComesToRestInTheCornerOfAnInclineAndAWall) {
  for (const double e : {0.0, 0.5}) {
    const double theta = 10.0 * M_PI / 180.0, r = 0.05, m = 0.2, wall = 0.5;
    const V up(std::sin(theta), 0, std::cos(theta));
    Scene scene = gravityScene();
    addMaterial(scene, "ice", e, 0.0);
    scene.bodies = {ball("ball", m, r, "ice")};
    scene.obstacles = {plane("incline", up, 0.0, "ice"), plane("wall", V(-1, 0, 0), -wall, "ice")};
    ImpactMonitor monitor(scene, longLived());
    double deepest = -1;
    StepReport last;
    run(monitor, {state(monitor, "ball", r * up)}, 100, 5.0,
        [&](double t, const StepReport& report) {
          const V centre = monitor.predictedState(0, t)->first;
          deepest = std::max({deepest, depthInPlane(centre, r, up, 0),
                              depthInPlane(centre, r, V(-1, 0, 0), -wall)});
          last = report;
        });
    EXPECT_LT(deepest, 1e-9 * r + 1e-15) << e;
    // The corner: x = wall - r, and on the incline: sin t x + cos t z = r.
    const double x = wall - r, z = (r - std::sin(theta) * x) / std::cos(theta);
    EXPECT_LT((monitor.predictedState(0, 5.0)->first - V(x, 0, z)).norm(), 1e-8 * r) << e;
    ASSERT_EQ(last.contacts.size(), 2u) << e;
    EXPECT_NEAR(last.contacts[0].normal_force, m * kG / std::cos(theta), 1e-9) << e;
    EXPECT_NEAR(last.contacts[1].normal_force, m * kG * std::tan(theta), 1e-9) << e;
  }
}

/// The corner scene of the accuracy benchmark (bench/accuracy/scenes.cpp, "ball into a
/// corner"): an incline at 10 degrees through the origin descending towards +x, a wall (normal
/// -x) that a ball of r = 0.05 m, 0.1 kg released at rest touching the incline at x = 0 meets
/// after sliding s = 0.2 m; e = 0.3 everywhere, mu = 1 where `rough` (with friction and spin).
struct CornerScene {
  static constexpr double kTheta = 10.0 * M_PI / 180.0, kR = 0.05, kM = 0.1, kSlide = 0.2;
  const V up{std::sin(kTheta), 0, std::cos(kTheta)};
  const V wall_normal{-1, 0, 0};
  const double wall_offset = -(kSlide * std::cos(kTheta) + kR);
  /// At rest in the corner: touching the wall, x = s cos t, and the incline, sin t x + cos t z = r.
  const V corner{kSlide * std::cos(kTheta), 0,
                 (kR - std::sin(kTheta) * kSlide * std::cos(kTheta)) / std::cos(kTheta)};
  const V start{0, 0, kR / std::cos(kTheta)};

  Scene scene(bool rough, Detection detection) const {
    Scene scene = gravityScene(rough, rough);
    scene.detection = detection;
    addMaterial(scene, "putty", 0.3, 1.0);
    scene.bodies = {ball("ball", kM, kR, "putty")};
    scene.obstacles = {plane("incline", up, 0.0, "putty"),
                       plane("wall", wall_normal, wall_offset, "putty")};
    return scene;
  }
  double depth(const V& centre) const {
    return std::max(depthInPlane(centre, kR, up, 0.0),
                    depthInPlane(centre, kR, wall_normal, wall_offset));
  }
};

/// The contacts' forces on their body a: -(N n + F) each, summed.
V forceOnBody(const std::vector<ContactRecord>& contacts) {
  V sum = V::Zero();
  for (const ContactRecord& c : contacts) sum -= c.normal_force * c.normal + c.friction_force;
  return sum;
}

// The corner with friction and spin (continuous detection): the ball rolls down at
// a = 5/7 g sin t (2/7 tan t < mu), reaches the wall at sqrt(2 s / a) = 0.573 s and bounces
// there (e = 0.3) to rest. At rest static friction is indeterminate (ContactForces,
// RoughCornerWithSpinHoldsWithoutPulling), but what statics determines must hold: the ball
// stays where it touches both planes, at speed and spin 0, never more than 1e-9 r inside either,
// and the contacts' forces on it sum to its weight m g. Asked: at rest by 2 s (3.5 times the
// arrival), and then for the 3 s after, without moving.
TEST(LastingContact, StaysAtRestInARoughCornerWithSpin) {
  const CornerScene corner;
  ImpactMonitor monitor(corner.scene(true, Detection::kContinuous), longLived());
  double deepest = -1, rest_since = INFINITY;
  int left_rest = 0;
  StepReport last;
  run(monitor, {state(monitor, "ball", corner.start)}, 100, 5.0,
      [&](double t, const StepReport& report) {
        const auto [centre, velocity] = *monitor.predictedState(0, t);
        deepest = std::max(deepest, corner.depth(centre));
        const bool at_rest = (centre - corner.corner).norm() <= 1e-9 * CornerScene::kR &&
                             velocity.norm() <= 1e-15 &&
                             monitor.predictedAngularVelocity(0, t).norm() <= 1e-15;
        if (at_rest && rest_since == INFINITY) rest_since = t;
        if (!at_rest && rest_since < t) ++left_rest;
        last = report;
      });
  EXPECT_LT(deepest, 1e-9 * CornerScene::kR);
  EXPECT_LE(rest_since, 2.0);
  EXPECT_EQ(left_rest, 0) << "samples after " << rest_since << " s not at rest in the corner";
  ASSERT_EQ(last.contacts.size(), 2u);
  for (const ContactRecord& contact : last.contacts) {
    EXPECT_EQ(contact.state, ContactState::kResting);
    EXPECT_GE(contact.normal_force, 0.0);
    EXPECT_LE(contact.friction_force.norm(), 1.0 * contact.normal_force);
  }
  EXPECT_LT((forceOnBody(last.contacts) - V(0, 0, CornerScene::kM * kG)).norm(), 1e-9);
}

// Discrete detection finds an impact by overlap at a sample, so a body meets a plane up to speed x
// period inside it (doc/model.md, "Detection"); lasting contact must then hold it there, not let it
// go through. The corner under discrete detection at 100 Hz, frictionless and with
// friction and spin: the fastest arrival is what the fall to the wall gives without rolling,
// v = sqrt(2 g s sin t) = 0.825 m/s, and a body is found at most one period after it arrives,
// so the ball is never more than (v + g / rate) / rate inside a plane;
// it ends at rest touching both (within that depth), by 2 s, and stays for 3 s. The contacts'
// forces on it sum to its weight; frictionless they are the corner's m g / cos t and m g tan t
// (the planes' normals, however deep the ball is held).
TEST(LastingContact, DiscreteDetectionHoldsABallInTheCorner) {
  const CornerScene corner;
  const double rate = 100;
  const double bound =
      (std::sqrt(2 * kG * CornerScene::kSlide * std::sin(CornerScene::kTheta)) + kG / rate) / rate;
  for (const bool rough : {false, true}) {
    ImpactMonitor monitor(corner.scene(rough, Detection::kDiscrete), longLived());
    double deepest = -1, rest_since = INFINITY;
    int moved_at_rest = 0;
    V rest = V::Constant(NAN);
    StepReport last;
    run(monitor, {state(monitor, "ball", corner.start)}, rate, 5.0,
        [&](double t, const StepReport& report) {
          const auto [centre, velocity] = *monitor.predictedState(0, t);
          deepest = std::max(deepest, corner.depth(centre));
          const bool still = velocity.norm() <= 1e-15 &&
                             monitor.predictedAngularVelocity(0, t).norm() <= 1e-15 &&
                             report.contacts.size() == 2;
          if (still && rest_since == INFINITY) {
            rest_since = t;
            rest = centre;
          }
          if (rest_since < t && (!still || centre != rest)) ++moved_at_rest;
          last = report;
        });
    EXPECT_LT(deepest, bound) << rough;
    EXPECT_LE(rest_since, 2.0) << rough;
    EXPECT_EQ(moved_at_rest, 0) << rough;
    // At rest it touches both planes: inside each by no more than the bound, away by none.
    EXPECT_GT(depthInPlane(rest, CornerScene::kR, corner.up, 0.0), -1e-9 * CornerScene::kR);
    EXPECT_GT(depthInPlane(rest, CornerScene::kR, corner.wall_normal, corner.wall_offset),
              -1e-9 * CornerScene::kR);
    ASSERT_EQ(last.contacts.size(), 2u) << rough;
    EXPECT_LT((forceOnBody(last.contacts) - V(0, 0, CornerScene::kM * kG)).norm(), 1e-9) << rough;
    if (!rough) {
      EXPECT_NEAR(last.contacts[0].normal_force,
                  CornerScene::kM * kG / std::cos(CornerScene::kTheta), 1e-9);
      EXPECT_NEAR(last.contacts[1].normal_force,
                  CornerScene::kM * kG * std::tan(CornerScene::kTheta), 1e-9);
    }
  }
}

// A ball dropped from 1 m onto a floor under discrete detection, for e = 0.3, 0.6 and 0.9 at
// 30, 100 and 1000 Hz: it arrives at v = sqrt(2 g h) = 4.43 m/s, the fastest of its arrivals,
// and is found at most one period later, so never more than (v + g / rate) / rate inside. Its
// bounces shrink until one could not stay out of the overlap it was found in for a whole period
// (a sample would not see it out, and it would fall back in where no new impact is found); from
// there it rests, touching the floor (within that depth), pressing with m g. The bounces take
// sqrt(2 h / g) (1 + e) / (1 - e) in all (8.6 s at e = 0.9), so by 10 s it rests.
TEST(LastingContact, DiscreteDetectionBouncesToRestOnTheFloor) {
  const double r = 0.05, h = 1.0;
  for (const double restitution : {0.3, 0.6, 0.9}) {
    for (const double rate : {30.0, 100.0, 1000.0}) {
      SCOPED_TRACE(::testing::Message() << "e = " << restitution << ", " << rate << " Hz");
      Scene scene = gravityScene();
      scene.detection = Detection::kDiscrete;
      addMaterial(scene, "rubber", restitution, 0.0);
      scene.bodies = {ball("ball", 0.1, r, "rubber")};
      scene.obstacles = {plane("floor", V(0, 0, 1), 0.0, "rubber")};
      ImpactMonitor monitor(scene, longLived());
      const double bound = (std::sqrt(2 * kG * h) + kG / rate) / rate;
      double deepest = -1;
      StepReport last;
      run(monitor, {state(monitor, "ball", V(0, 0, r + h))}, rate, 10.0,
          [&](double t, const StepReport& report) {
            deepest = std::max(deepest, r - monitor.predictedState(0, t)->first.z());
            last = report;
          });
      EXPECT_LT(deepest, bound);
      const auto [centre, velocity] = *monitor.predictedState(0, 10.0);
      EXPECT_EQ(velocity.norm(), 0.0);
      EXPECT_GT(r - centre.z(), -1e-9 * r);
      ASSERT_EQ(last.contacts.size(), 1u);
      EXPECT_EQ(last.contacts[0].state, ContactState::kResting);
      EXPECT_NEAR(last.contacts[0].normal_force, 0.1 * kG, 1e-12);
    }
  }
}

// Discrete detection: a ball that bounced off the floor from 2 cm inside it (found so at a
// sample, rising at 0.8 m/s: fast enough to leave, so not held) is still inside it at the next
// sample when a ball falling at 3 m/s strikes it from above. The floor pair
// overlapped at the sample before, so it is no new impact; but it takes part in the new one: the
// blow runs into the floor instead of driving the lower ball through it (a pile of 27 in a box
// lost balls 19 m below its floor so). After the sample the lower ball does not move into the
// floor, and the floor took an impulse.
TEST(LastingContact, DiscreteAStrikeOnABallStillInTheFloorRunsIntoIt) {
  const double r = 0.05, m = 0.1, dt = 0.01;
  Scene scene = gravityScene();
  scene.detection = Detection::kDiscrete;
  addMaterial(scene, "rubber", 0.5, 0.0);
  scene.bodies = {ball("high", m, r, "rubber"), ball("low", m, r, "rubber")};
  scene.obstacles = {plane("floor", V(0, 0, 1), 0.0, "rubber")};
  ImpactMonitor monitor(scene, longLived());
  const auto at = [](double z0, double v0, double t) {
    return std::make_pair(z0 + v0 * t - 0.5 * kG * t * t, v0 - kG * t);
  };
  const double low0 = r - 0.02, high0 = 3 * r + 0.01;
  monitor.step(0.0, {state(monitor, "low", V(0, 0, low0), V(0, 0, 0.8)),
                     state(monitor, "high", V(0, 0, high0), V(0, 0, -3.0))});
  const auto [low_z, low_v] = at(low0, 0.8, dt);
  const auto [high_z, high_v] = at(high0, -3.0, dt);
  ASSERT_LT(low_z, r);               // still in the floor
  ASSERT_LT(high_z - low_z, 2 * r);  // the balls overlap: a new impact
  const StepReport report =
      monitor.step(dt, {state(monitor, "low", V(0, 0, low_z), V(0, 0, low_v)),
                        state(monitor, "high", V(0, 0, high_z), V(0, 0, high_v))});
  bool floor_struck = false;
  for (const ImpactRecord& impact : report.impacts) {
    floor_struck = floor_struck || (impact.other_is_obstacle && impact.impulse > 0);
  }
  EXPECT_TRUE(floor_struck);
  const V low_after = monitor.predictedState(*monitor.bodyIndex("low"), dt)->second;
  EXPECT_GE(low_after.z(), -1e-12);
  const V high_after = monitor.predictedState(*monitor.bodyIndex("high"), dt)->second;
  EXPECT_LE(0.5 * m * (low_after.squaredNorm() + high_after.squaredNorm()),
            0.5 * m * (low_v * low_v + high_v * high_v));
}

// A pyramid between walls: two balls on the floor against the walls at x = +-(c + r) (apart by
// 2 c, c = 1.2 r, not touching), one on top touching both. It holds; the top ball's contacts
// lean by phi, sin phi = c / 2 r = 0.6, and carry m_t g / 1.6 each, the walls 0.375 m_t g, the
// floor m_b g + m_t g / 2 under each.
TEST(LastingContact, PyramidHeldBetweenWalls) {
  const double r = 0.05, c = 1.2 * r, mb = 0.3, mt = 0.2;
  const double height = std::sqrt(4 * r * r - c * c);
  Scene scene = gravityScene();
  addMaterial(scene, "wood", 0.6, 0.0);
  scene.bodies = {ball("left", mb, r, "wood"), ball("right", mb, r, "wood"),
                  ball("top", mt, r, "wood")};
  scene.obstacles = {plane("floor", V(0, 0, 1), 0.0, "wood"),
                     plane("wall_left", V(1, 0, 0), -(c + r), "wood"),
                     plane("wall_right", V(-1, 0, 0), -(c + r), "wood")};
  ImpactMonitor monitor(scene, longLived());
  const std::vector<BodyStateSample> start = {state(monitor, "left", V(-c, 0, r)),
                                              state(monitor, "right", V(c, 0, r)),
                                              state(monitor, "top", V(0, 0, r + height))};
  StepReport last;
  const auto impacts =
      run(monitor, start, 100, 1.0, [&](double, const StepReport& report) { last = report; });
  EXPECT_TRUE(impacts.empty());
  EXPECT_LT((monitor.predictedState(2, 1.0)->first - V(0, 0, r + height)).norm(), 1e-14);
  // Pairs in order: left-top, left-floor, left-wall_left, right-top, right-floor,
  // right-wall_right (obstacles sorted by id: floor, wall_left, wall_right).
  ASSERT_EQ(last.contacts.size(), 6u);
  EXPECT_NEAR(last.contacts[0].normal_force, mt * kG / 1.6, 1e-12);
  EXPECT_NEAR(last.contacts[1].normal_force, mb * kG + mt * kG / 2, 1e-12);
  EXPECT_NEAR(last.contacts[2].normal_force, 0.375 * mt * kG, 1e-12);
  EXPECT_EQ(last.contacts[0].normal_force, last.contacts[3].normal_force) << "mirror images";
  EXPECT_EQ(last.contacts[2].normal_force, last.contacts[5].normal_force) << "mirror images";
}

// An elastic ball (e = 1) between two walls 1e-5 m wider than it, moving across at 1 m/s while
// it falls onto a floor: it would strike the walls 50,000 times a second, beyond any step's
// budget. The fallback keeps it in the gap: it never enters a wall, and it lands on the floor.
TEST(LastingContact, WedgedBallNeverLeavesTheGap) {
  const double r = 0.05, clearance = 1e-5;
  Scene scene = gravityScene();
  addMaterial(scene, "elastic", 1.0, 0.0);
  addMaterial(scene, "sand", 0.5, 0.0);  // the floor: min(1, 0.5), the ball bounces to rest
  scene.bodies = {ball("ball", 0.1, r, "elastic")};
  scene.obstacles = {plane("floor", V(0, 0, 1), 0.0, "sand"),
                     plane("left", V(1, 0, 0), -(r + clearance / 2), "elastic"),
                     plane("right", V(-1, 0, 0), -(r + clearance / 2), "elastic")};
  MonitorSettings settings = longLived();
  settings.max_instants_per_step = 1000;
  ImpactMonitor monitor(scene, settings);
  double outside = 0;
  std::size_t fallbacks = 0;
  run(monitor, {state(monitor, "ball", V(0, 0, 0.5), V(1, 0, 0))}, 100, 2.0,
      [&](double t, const StepReport& report) {
        fallbacks += report.fallbacks;
        outside =
            std::max(outside, std::abs(monitor.predictedState(0, t)->first.x()) - clearance / 2);
      });
  EXPECT_GT(fallbacks, 0u);
  EXPECT_LE(outside, 1e-9 * r);
  EXPECT_NEAR(monitor.predictedState(0, 2.0)->first.z(), r, 1e-9 * r);
}

// A ball dropped from rest with its surface h above what it falls on, e = 0.5, threshold 0: it
// meets it at t1 = sqrt(2 h / g) at v0 = g t1 and then bounces for ever in a finite time, the
// k-th bounce lasting 2 e^k v0 / g: all of them add up to t1 + 2 e v0 / (g (1 - e)) =
// t1 (1 + e) / (1 - e). It rests from that accumulation instant: the contact's `since`. The same
// on the floor, on a fixed sphere, and on a held ball (an immovable body).
TEST(LastingContact, BouncesToRestAtTheAccumulationInstant) {
  const double h = 0.5, r = 0.05, e = 0.5;
  const double t1 = std::sqrt(2 * h / kG), accumulation = t1 * (1 + e) / (1 - e);
  for (const std::string support : {"floor", "dome", "held"}) {
    Scene scene = gravityScene();
    addMaterial(scene, "putty", e, 0.0);
    scene.bodies = {ball("ball", 0.1, r, "putty")};
    if (support == "floor") scene.obstacles = {plane("floor", V(0, 0, 1), 0.0, "putty")};
    if (support == "dome") {
      ObstacleSpec dome;
      dome.id = "dome";
      dome.shape = ObstacleShape::kSphere;
      dome.radius = 0.2;
      dome.position = V(0, 0, -0.2);
      dome.material = "putty";
      scene.obstacles = {dome};
    }
    std::vector<BodyStateSample> start;
    if (support == "held") {
      BodySpec held = ball("held", kImmovableMass, 0.2, "putty");
      scene.bodies.push_back(held);
    }
    ImpactMonitor monitor(scene, longLived());
    start.push_back(state(monitor, "ball", V(0, 0, h + r)));
    if (support == "held") start.push_back(state(monitor, "held", V(0, 0, -0.2)));
    StepReport last;
    double deepest = -1;
    const auto impacts = run(monitor, start, 100, 2.0, [&](double t, const StepReport& report) {
      last = report;
      deepest =
          std::max(deepest, r - monitor.predictedState(*monitor.bodyIndex("ball"), t)->first.z());
    });
    EXPECT_LT(impacts.size(), 60u) << support;
    EXPECT_LT(deepest, 1e-9 * r) << support;
    ASSERT_EQ(last.contacts.size(), 1u) << support;
    EXPECT_NEAR(last.contacts[0].since, accumulation, 1e-12 * accumulation) << support;
    EXPECT_EQ(last.contacts[0].state, ContactState::kResting) << support;
    EXPECT_NEAR(last.contacts[0].normal_force, 0.1 * kG, 1e-12) << support;
  }
}

// A ball resting in the corner of an incline and a wall, struck from above and across by
// another: the strike and the resting ball's lasting contacts are one cluster (the impulse runs
// into both planes at once), energy does not increase, the resting ball never enters a plane,
// and after the dust settles it rests in the corner again.
TEST(LastingContact, BallStruckWhileRestingInACorner) {
  const double theta = 10.0 * M_PI / 180.0, r = 0.05, wall = 0.5;
  const V up(std::sin(theta), 0, std::cos(theta));
  Scene scene = gravityScene();
  addMaterial(scene, "wood", 0.5, 0.0);
  scene.bodies = {ball("resting", 0.2, r, "wood"), ball("striker", 0.1, r, "wood")};
  scene.obstacles = {plane("incline", up, 0.0, "wood"), plane("wall", V(-1, 0, 0), -wall, "wood")};
  ImpactMonitor monitor(scene, longLived());
  const double x = wall - r, z = (r - std::sin(theta) * x) / std::cos(theta);
  const V corner(x, 0, z);
  // The striker comes down at 45 degrees into the corner ball, touching it at t = 0.
  const V direction = V(1, 0, -1).normalized();
  const std::vector<BodyStateSample> start = {
      state(monitor, "resting", corner),
      state(monitor, "striker", corner - 2 * r * direction, 2.0 * direction)};
  double deepest = -1;
  std::vector<ImpactRecord> first;
  const auto impacts = run(monitor, start, 100, 4.0, [&](double t, const StepReport& report) {
    if (first.empty()) first = report.impacts;
    const V centre = monitor.predictedState(0, t)->first;
    deepest = std::max(
        {deepest, depthInPlane(centre, r, up, 0), depthInPlane(centre, r, V(-1, 0, 0), -wall)});
  });
  // The strike (at t = 0, the first step) reaches both planes in the same cluster.
  ASSERT_FALSE(first.empty());
  bool incline = false, wall_hit = false;
  for (const ImpactRecord& impact : first) {
    if (impact.time != 0.0) continue;
    incline = incline || (impact.other_is_obstacle && impact.other == 0 && impact.impulse > 0);
    wall_hit = wall_hit || (impact.other_is_obstacle && impact.other == 1 && impact.impulse > 0);
    EXPECT_GE(impact.energy_lost, -1e-15);
  }
  EXPECT_TRUE(incline);
  EXPECT_TRUE(wall_hit);
  EXPECT_LT(deepest, 1e-9 * r + 1e-15);
  EXPECT_LT((monitor.predictedState(0, 4.0)->first - corner).norm(), 1e-8 * r);
}

// A ball on top of a fixed sphere, nudged at v0 across it (no friction). On the sphere, with d the
// distance of the centres, energy gives v^2 = v0^2 + 2 g d (1 - cos t) and the sphere pushes with
// m (g cos t - v^2 / d), which is 0 at cos t = 2/3 + v0^2 / (3 g d): it leaves there, at speed
// v^2 = g d cos t along the tangent, and flies on with the horizontal velocity it had then,
// sqrt(g d) cos^(3/2) t. On the sphere it never goes into it.
TEST(LastingContact, SlidesOffASphereAtTwoThirds) {
  const double R = 1.0, r = 0.1, d = R + r, v0 = 1e-3;
  Scene scene = gravityScene();
  addMaterial(scene, "ice", 0.5, 0.0);
  scene.bodies = {ball("ball", 0.1, r, "ice")};
  scene.obstacles = {sphere("dome", V::Zero(), R, "ice")};
  ImpactMonitor monitor(scene, longLived());
  double deepest = -1, left = -1;
  run(monitor, {state(monitor, "ball", V(0, 0, d), V(v0, 0, 0))}, 100, 4.0,
      [&](double t, const StepReport& report) {
        deepest = std::max(deepest, d - monitor.predictedState(0, t)->first.norm());
        if (left < 0 && report.contacts.empty()) left = t;
      });
  ASSERT_GT(left, 0.0) << "it left the sphere";
  const double leaves = 2.0 / 3.0 + v0 * v0 / (3 * kG * d);
  const double horizontal = std::sqrt(kG * d) * std::pow(leaves, 1.5);
  EXPECT_NEAR(monitor.predictedState(0, 4.0)->second.x(), horizontal, 1e-7 * horizontal);
  EXPECT_LT(deepest, 1e-9 * d);
}

// The same ball, the dome standing on a floor (z = -R): it leaves the dome at cos t = 2/3, falls
// onto the floor, bounces (e = 0.5) to rest on it and slides away along it (no friction) with
// the horizontal velocity it left with. It never goes into the dome or the floor (the case of
// issue 12 went centimetres into the floor), and ends with its centre r above the floor.
TEST(LastingContact, FallsOffASphereOntoTheFloorAndNeverIntoIt) {
  const double R = 1.0, r = 0.1, d = R + r, v0 = 1e-3;
  Scene scene = gravityScene();
  addMaterial(scene, "ice", 0.5, 0.0);
  scene.bodies = {ball("ball", 0.1, r, "ice")};
  scene.obstacles = {sphere("dome", V::Zero(), R, "ice"), plane("floor", V(0, 0, 1), -R, "ice")};
  ImpactMonitor monitor(scene, longLived());
  double into_dome = -1, into_floor = -1;
  run(monitor, {state(monitor, "ball", V(0, 0, d), V(v0, 0, 0))}, 100, 6.0,
      [&](double t, const StepReport&) {
        const V p = monitor.predictedState(0, t)->first;
        into_dome = std::max(into_dome, d - p.norm());
        into_floor = std::max(into_floor, -R + r - p.z());
      });
  EXPECT_LT(into_dome, 1e-9 * d);
  EXPECT_LT(into_floor, 1e-9 * r);
  EXPECT_NEAR(monitor.predictedState(0, 6.0)->first.z(), -R + r, 1e-9 * r);
  const double leaves = 2.0 / 3.0 + v0 * v0 / (3 * kG * d);
  const double horizontal = std::sqrt(kG * d) * std::pow(leaves, 1.5);
  EXPECT_NEAR(monitor.predictedState(0, 6.0)->second.x(), horizontal, 1e-7 * horizontal);
}

// Rolling with friction (a solid ball, spin, mu large): (7/10) v^2 = (7/10) v0^2 + g d (1 - cos t)
// and the sphere lets go at g d cos t = v^2, so cos t = (10 + 7 v0^2 / (g d)) / 17: 10/17 for a
// nudge of nothing. It flies on with the horizontal velocity sqrt(g d) cos^(3/2) t. (Near N = 0
// static friction runs out and it slips for the last instant; with mu = 1e6 that moves cos t by
// far less than the tolerance.)
TEST(LastingContact, RollsOffASphereAtTenSeventeenths) {
  const double R = 1.0, r = 0.1, d = R + r, v0 = 1e-3;
  Scene scene = gravityScene(true, true);
  addMaterial(scene, "grippy", 0.5, 1e6);
  scene.bodies = {ball("ball", 0.1, r, "grippy")};
  scene.obstacles = {sphere("dome", V::Zero(), R, "grippy")};
  ImpactMonitor monitor(scene, longLived());
  double deepest = -1;
  bool rolled = false;
  // Rolling: w = v / r about the axis of the turn, so that the contact point is at rest.
  run(monitor, {state(monitor, "ball", V(0, 0, d), V(v0, 0, 0), V(0, v0 / r, 0))}, 100, 5.0,
      [&](double t, const StepReport& report) {
        deepest = std::max(deepest, d - monitor.predictedState(0, t)->first.norm());
        if (!report.contacts.empty() && report.contacts[0].state == ContactState::kRolling) {
          rolled = true;
        }
      });
  EXPECT_TRUE(rolled);
  const double leaves = (10 + 7 * v0 * v0 / (kG * d)) / 17;
  const double horizontal = std::sqrt(kG * d) * std::pow(leaves, 1.5);
  EXPECT_NEAR(monitor.predictedState(0, 5.0)->second.x(), horizontal, 1e-6 * horizontal);
  EXPECT_LT(deepest, 1e-9 * d);
}

/// How far a ball's centre is inside the box grown by the ball (> 0: inside), by the box's own
/// distance formula: |max(|p| - h, 0)| outside, minus the depth inside.
double depthInBox(const V& centre, double radius, const V& half) {
  const V outside = (centre.cwiseAbs() - half).cwiseMax(0.0);
  const double inside = std::min(0.0, (centre.cwiseAbs() - half).maxCoeff());
  return radius - outside.norm() - inside;
}

// A ball resting on a box's top face stays where it is, to the bit: at rest the balance is
// exact, and nothing is integrated.
// The box, or the same box as a mesh of 12 triangles (the tests run on both).
ObstacleSpec table(bool as_mesh, const V& half, const std::string& material) {
  return as_mesh
             ? scene_builders::mesh("table", scene_builders::cubeMesh(half), V::Zero(), material)
             : scene_builders::box("table", V::Zero(), 2 * half, material);
}

class OnABoxOrItsMesh : public testing::TestWithParam<bool> {};
INSTANTIATE_TEST_SUITE_P(LastingContact, OnABoxOrItsMesh, testing::Bool(),
                         [](const testing::TestParamInfo<bool>& param) {
                           return param.param ? "Mesh" : "Box";
                         });

TEST_P(OnABoxOrItsMesh, RestsOnAFace) {
  const double r = 0.1;
  Scene scene = gravityScene(true, true);
  addMaterial(scene, "wood", 0.5, 0.4);
  scene.bodies = {ball("ball", 0.1, r, "wood")};
  scene.obstacles = {table(GetParam(), V(0.5, 0.5, 0.5), "wood")};
  ImpactMonitor monitor(scene, longLived());
  const V at(0.2, -0.3, 0.5 + r);
  bool touching = true;
  run(monitor, {state(monitor, "ball", at)}, 100, 1.0, [&](double, const StepReport& report) {
    touching = touching && report.contacts.size() == 1 &&
               report.contacts[0].state == ContactState::kResting;
  });
  EXPECT_TRUE(touching);
  EXPECT_EQ(monitor.predictedState(0, 1.0)->first, at);
  EXPECT_EQ(monitor.predictedState(0, 1.0)->second, V::Zero());
}

// A ball sliding (frictionless) along a box's top face towards its edge at v0 < sqrt(g r) pivots
// about the edge, its centre on a circle of radius r: v^2 = v0^2 + 2 g r (1 - cos t), and the
// edge lets go where g cos t = v^2 / r, cos t = (2 + v0^2 / (g r)) / 3 (the ball off a sphere
// with R = 0). It flies on with the horizontal velocity sqrt(g r) cos^(3/2) t, never inside the
// box; rolling (friction, spin, a solid ball), (7/10) v^2 = (7/10) v0^2 + g r (1 - cos t) and
// cos t = (10 + 7 v0^2 / (g r)) / 17. It reaches the edge at 0.25 s and has left it by 0.5 s.
void offABoxEdge(bool rolling, bool as_mesh) {
  const double r = 0.1, v0 = 0.2;
  Scene scene = gravityScene(rolling, rolling);
  addMaterial(scene, "ice", 0.5, rolling ? 1e6 : 0.0);
  scene.bodies = {ball("ball", 0.1, r, "ice")};
  const V half(0.5, 0.5, 0.5);
  scene.obstacles = {table(as_mesh, half, "ice")};
  ImpactMonitor monitor(scene, longLived());
  double deepest = -1;
  bool rolled = false;
  run(monitor,
      {state(monitor, "ball", V(0.45, 0, 0.5 + r), V(v0, 0, 0), V(0, rolling ? v0 / r : 0, 0))},
      100, 1.0, [&](double t, const StepReport& report) {
        deepest = std::max(deepest, depthInBox(monitor.predictedState(0, t)->first, r, half));
        if (!report.contacts.empty() && report.contacts[0].state == ContactState::kRolling) {
          rolled = true;
        }
      });
  EXPECT_EQ(rolled, rolling);
  const double g_r = kG * r;
  const double leaves = rolling ? (10 + 7 * v0 * v0 / g_r) / 17 : (2 + v0 * v0 / g_r) / 3;
  const double horizontal = std::sqrt(g_r) * std::pow(leaves, 1.5);
  EXPECT_NEAR(monitor.predictedState(0, 1.0)->second.x(), horizontal, 1e-6 * horizontal);
  EXPECT_LT(deepest, 1e-9 * r);
}

TEST_P(OnABoxOrItsMesh, SlidesOffAnEdgeAtTheClosedForm) { offABoxEdge(false, GetParam()); }
TEST_P(OnABoxOrItsMesh, RollsOffAnEdgeAtTheClosedForm) { offABoxEdge(true, GetParam()); }

// A ball of clay (e = 0, no friction) dropped off-centre into the groove between two boxes (their
// top faces at z = 0, their near edges at x = -w/2 and w/2, w = 0.06 < 2 r): it lands on one
// edge, slides round it into the groove and comes to rest on both edges, its centre on the
// groove's middle at z = sqrt(r^2 - (w/2)^2), each edge pushing along the line to the centre,
// at phi = asin(w / (2 r)) from the vertical: N = m g / (2 cos phi). Never inside either box;
// the same with the boxes as meshes.
TEST_P(OnABoxOrItsMesh, ComesToRestInTheGrooveBetweenTwoBoxes) {
  const double r = 0.05, m = 0.2, w = 0.06;
  const V half(0.5, 0.5, 0.25);
  Scene scene = gravityScene();
  addMaterial(scene, "clay", 0.0, 0.0);
  scene.bodies = {ball("ball", m, r, "clay")};
  ObstacleSpec left = table(GetParam(), half, "clay"), right = left;
  left.id = "left";
  left.position = V(-0.5 - w / 2, 0, -0.25);
  right.id = "right";
  right.position = V(0.5 + w / 2, 0, -0.25);
  scene.obstacles = {left, right};
  ImpactMonitor monitor(scene, longLived());
  double deepest = -1;
  StepReport last;
  run(monitor, {state(monitor, "ball", V(0.004, 0, 0.2))}, 100, 4.0,
      [&](double t, const StepReport& report) {
        const V centre = monitor.predictedState(0, t)->first;
        deepest = std::max({deepest, depthInBox(centre - left.position, r, half),
                            depthInBox(centre - right.position, r, half)});
        last = report;
      });
  EXPECT_LT(deepest, 1e-9 * r);
  const V rest(0, 0, std::sqrt(r * r - w * w / 4));
  EXPECT_LT((monitor.predictedState(0, 4.0)->first - rest).norm(), 1e-8 * r);
  ASSERT_EQ(last.contacts.size(), 2u);
  const double cos_phi = std::sqrt(1 - w * w / (4 * r * r));
  EXPECT_NEAR(last.contacts[0].normal_force, m * kG / (2 * cos_phi), 1e-9);
  EXPECT_NEAR(last.contacts[1].normal_force, m * kG / (2 * cos_phi), 1e-9);
}

// A ball rolling across a tessellated floor (8 x 8 squares of two triangles, 2 m across) as on
// the plane it tessellates: no impact, its centre at z = r and its velocity unchanged to 1e-15
// (its contact is integrated as on any finite shape, not the plane's closed form), rolling over
// every internal edge it crosses (where an engine that tests each triangle alone bounces: a
// "ghost collision").
TEST(LastingContact, RollsAcrossATessellatedFloorAsOnItsPlane) {
  const double r = 0.1, v = 0.3;
  Scene scene = gravityScene(true, true);
  addMaterial(scene, "felt", 0.5, 0.6);
  scene.bodies = {ball("ball", 0.1, r, "felt")};
  scene.obstacles = {
      scene_builders::mesh("floor", scene_builders::floorMesh(8, 2.0), V::Zero(), "felt")};
  ImpactMonitor monitor(scene, longLived());
  // Diagonally across the squares' edges and their diagonals; w x (-r z) = v: rolling.
  const V velocity(v * 0.8, v * 0.6, 0);
  const V spin = V(0, 0, 1).cross(velocity) / r;
  const V start(-0.8, -0.7, r);
  bool rolling = true;
  const auto impacts = run(monitor, {state(monitor, "ball", start, velocity, spin)}, 100, 3.0,
                           [&](double t, const StepReport& report) {
                             const auto predicted = monitor.predictedState(0, t);
                             EXPECT_NEAR(predicted->first.z(), r, 1e-15) << t;
                             rolling = rolling && report.contacts.size() == 1 &&
                                       report.contacts[0].state == ContactState::kRolling;
                           });
  EXPECT_TRUE(impacts.empty());
  EXPECT_TRUE(rolling);
  const auto end = monitor.predictedState(0, 3.0);
  EXPECT_LE((end->second - velocity).norm(), 1e-15) << (end->second - velocity).transpose();
  EXPECT_NEAR((end->first - (start + 3.0 * velocity)).norm(), 0, 1e-12);
}

// Balls dropped from a loose lattice (0.12 m apart, offsets up to 5 mm) into a box, e = 0.5,
// settling for `duration` (frictionless, or with friction `mu` and spin): they bounce on the
// floor, on each other and on balls that rest on others (curved lasting contact). Nothing may
// pass into anything: at every step no ball is more than 1e-9 of its radius into a wall nor
// 1e-9 of the distance of centres into another ball, and the energy (kinetic plus potential)
// never rises above the drop's beyond rounding. (Before, a ball that bounced off one resting on
// others was let through it: 8 balls ended 0.92 d inside each other.)
void dropPileIntoABox(int count, double rate, double mu = 0.0, double duration = 2.0) {
  Scene scene = gravityScene(mu > 0, mu > 0);
  addMaterial(scene, "pile", 0.5, mu);
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(count))));
  const double spacing = 0.12, size = spacing * side + 0.1, r = 0.05, m = 0.1;
  std::mt19937_64 engine(11);
  std::uniform_real_distribution<double> offset(-0.005, 0.005);
  std::vector<V> start;
  for (int i = 0; i < count; ++i) {
    const V cell(i % side, (i / side) % side, i / (side * side));
    scene.bodies.push_back(ball("ball_" + std::to_string(100 + i), m, r, "pile"));
    start.push_back(V(0.11, 0.11, 0.11) + spacing * cell +
                    V(offset(engine), offset(engine), offset(engine)));
  }
  const V normals[] = {V(1, 0, 0), V(-1, 0, 0), V(0, 1, 0), V(0, -1, 0), V(0, 0, 1), V(0, 0, -1)};
  const double offsets[] = {0, -size, 0, -size, 0, -size};
  for (int w = 0; w < 6; ++w) {
    scene.obstacles.push_back(plane("wall_" + std::to_string(w), normals[w], offsets[w], "pile"));
  }
  ImpactMonitor monitor(scene, longLived());
  std::vector<BodyStateSample> states;
  double released = 0;  // the potential energy above the floor at the start
  for (int i = 0; i < count; ++i) {
    states.push_back(state(monitor, scene.bodies[i].id, start[i]));
    released += m * kG * start[i].z();
  }
  double into_wall = 0, into_ball = 0, gain = -released;
  const std::vector<ImpactRecord> impacts =
      run(monitor, states, rate, duration, [&](double t, const StepReport&) {
        double energy = 0;
        for (int i = 0; i < count; ++i) {
          const auto [p, v] = *monitor.predictedState(i, t);
          energy += m * kG * p.z() + 0.5 * m * v.squaredNorm();
          for (int w = 0; w < 6; ++w) {
            into_wall = std::max(into_wall, depthInPlane(p, r, normals[w], offsets[w]));
          }
          for (int j = i + 1; j < count; ++j) {
            into_ball =
                std::max(into_ball, 2 * r - (monitor.predictedState(j, t)->first - p).norm());
          }
        }
        gain = std::max(gain, energy - released);
      });
  EXPECT_GT(impacts.size(), static_cast<std::size_t>(10 * count));  // it did bounce and settle
  EXPECT_LE(into_wall, 1e-9 * r);
  EXPECT_LE(into_ball, 1e-9 * 2 * r);
  EXPECT_LE(gain, 1e-12 * released);
}

// Three billiard balls rolling in contact on the floor of the effects benchmark's box (gravity,
// friction, spin; the states it fed at 3.33 s, to the bit). Their group's modes changed back
// every two or three ulps of the time line: 20,000 solves in one 10 ms step, which spent the
// step's budget, and the fallback then held every ball where it was. A group's event within
// 1e-12 of the step of its last solve lets its motion go on: no fallback, and the three balls
// roll on (a held ball would stop). That motion still costs the exact model some 3,000 solves a
// ball in this update, over the scene's exact_work_budget (1,024): with the budget the three are
// stepped from there (the only fallback, naming them), without it (0) the exact model finishes
// the update; either way nobody is held.
TEST(LastingContact, RollingInContactDoesNotSpendTheStep) {
  for (const int budget : {0, 1024}) {
    SCOPED_TRACE(budget);
    Scene scene;
    scene.effects.gravity = scene.effects.friction = scene.effects.spin = true;
    const V normals[] = {V(1, 0, 0), V(-1, 0, 0), V(0, 1, 0), V(0, -1, 0), V(0, 0, 1), V(0, 0, -1)};
    for (int i = 0; i < 6; ++i) {
      scene.obstacles.push_back(
          plane("wall_" + std::to_string(i), normals[i], i % 2 == 0 ? 0.0 : -2.0, "billiard_ball"));
    }
    for (const char* id : {"ball_1015", "ball_1094", "ball_1099"}) {
      scene.bodies.push_back(ball(id, 0.17, 0.05, "billiard_ball"));
    }
    scene.exact_work_budget = budget;
    ImpactMonitor monitor(scene, longLived());
    const double start = 3.329999999999973;
    std::vector<BodyStateSample> states = {
        state(monitor, "ball_1015", V(1.3856448283084293, 1.5630097316704534, 0.050000000000000003),
              V(0.013332169805527753, -0.046165213560897263, 0),
              V(1.0928565222642912, -1.437225457883323, -0.91659620005833342)),
        state(monitor, "ball_1094", V(1.2864315590252859, 1.5504906582961786, 0.050000000000000003),
              V(0.013725658587406167, -0.049283599986894265, 0),
              V(0.78048929590984972, 1.7812718077449601, 0.68311191372731273)),
        state(monitor, "ball_1099", V(1.2608829541660407, 1.6471719325417435, 0.050000000000000003),
              V(0.066653530618672518, -0.035297093301712115, 0),
              V(0.8513460425212247, 1.0258412518694544, -1.4940366770556039))};
    for (BodyStateSample& sample : states) sample.time = start;
    monitor.step(start, states);
    const StepReport report = monitor.step(start + 0.01, {});
    EXPECT_FALSE(report.truncated);
    EXPECT_EQ(report.fallbacks, report.over_budget.size());
    const std::vector<std::size_t> stepped =
        budget == 0 ? std::vector<std::size_t>{} : std::vector<std::size_t>{0, 1, 2};
    EXPECT_EQ(report.over_budget, stepped);
    for (std::size_t body = 0; body < 3; ++body) {
      EXPECT_GT(monitor.predictedState(body, start + 0.01)->second.norm(), 0.01) << body;
    }
  }
}

TEST(LastingContact, PileOfEightInABoxNeverInsideAnything) {
  dropPileIntoABox(8, 100);
  dropPileIntoABox(8, 30);
}

TEST(LastingContact, PileOfTwentySevenInABoxNeverInsideAnything) { dropPileIntoABox(27, 100); }

// A hundred balls with friction (mu = 1) and spin, over the first 0.3 s of their settling (the
// first layer lands at 0.09 s). Before, three things each put a ball 0.5 to 5 mm into another or
// into the floor: a curved group whose friction modes stopped holding at the instant they were
// chosen (solved again there it would be so for ever) kept an integrated motion that ended there,
// and nothing looked at its bodies to the step's end; a group formed again, closing its contacts'
// normal velocities, turned a ball leaving the floor, which touched it, into it, and that touching
// pair was never scheduled; a ball a stepped cluster let go of at a step's start was never paired
// with the floor its new motion reached.
TEST(LastingContact, PileOfAHundredWithFrictionNeverInsideAnything) {
  dropPileIntoABox(100, 100, 1.0, 0.3);
}

// Off a table's edge (config/scenes/table.yaml: a box 1 x 1 x 0.05 m, its top at z = 0.75 and
// its edge at x = 0.5; a tennis ball, r = 33.5 mm, m = 57 g), moving at v0 = 0.3 m/s along the
// top: when its centre crosses the edge's line the contact passes from the face to the edge, its
// normal turning continuously, and the ball pivots about the edge until the edge's push N is 0.
// No impact begins there. Times from the crossing, from test/exact/edge_roll_off.py (Newton's
// and Coulomb's laws in closed form and quadrature, mpmath at 40 digits, checked against the ODE
// integrated by Taylor series): sliding (mu = 0, or gravity alone) it leaves after
// 0.065243934245168263 s at cos t = (2 + v0^2 / (g r)) / 3; rolling with mu = 1 it slips at
// t = 0.6836 rad (0.066044274 s) and leaves after 0.073262898451230338 s at cos t = 0.70886157;
// with mu = 100 it slips at 0.79282 rad and leaves after 0.074064004537895647 s. Each flies on
// at the edge's velocity then, r t' (cos t, -sin t).
struct EdgeCase {
  const char* name;
  bool friction;      ///< the friction and spin effects (otherwise gravity alone)
  double mu;          ///< Coulomb's coefficient with friction
  double on_edge;     ///< s from the crossing to the leave
  double cos_leaves;  ///< the angle of the line from the edge to the centre then
  double vx, vz;      ///< m/s, the flight's velocity after
};

constexpr EdgeCase kEdgeCases[] = {
    {"gravity alone", false, 0.0, 0.065243934245168263, 0.75795335250353734, 0.37828630989487046,
     -0.32556023673987285},
    {"mu 0", true, 0.0, 0.065243934245168263, 0.75795335250353734, 0.37828630989487046,
     -0.32556023673987285},
    {"mu 1", true, 1.0, 0.073262898451230338, 0.70886157447319529, 0.34213622540477646,
     -0.34044019561851176},
    {"mu 100", true, 100.0, 0.074064004537895647, 0.7010866561367906, 0.3365227730901561,
     -0.34227771828038342},
};

/// What a start off the table's edge did: its impacts, the steps whose report had lost the
/// contact before the reference's leave, and the ball's state at the run's end, in flight.
struct EdgeRun {
  std::size_t impacts = 0;
  int contact_lost_early = 0;
  double end = 0.0;
  V position = V::Constant(NAN), velocity = V::Constant(NAN);
  double free_since = NAN;  ///< the instant its free flight holds from (motionSince)
  V free_position = V::Constant(NAN), free_velocity = V::Constant(NAN);  ///< then
};

constexpr double kEdgeR = 0.0335, kEdgeV0 = 0.3;

/// The ball rolls (spin v0 / r; without friction it only slides) from x0 = 0.5 - v0 crossing at
/// `rate` until a few updates after it has left the edge.
EdgeRun offTheTablesEdge(const EdgeCase& edge, double rate, double crossing) {
  Scene scene = gravityScene(edge.friction, edge.friction);
  addMaterial(scene, "felt", 0.712, edge.mu);
  scene.bodies = {ball("ball", 0.057, kEdgeR, "felt")};
  scene.obstacles = {scene_builders::box("table", V(0, 0, 0.725), V(1, 1, 0.05), "felt")};
  ImpactMonitor monitor(scene, longLived());
  const double x0 = 0.5 - kEdgeV0 * crossing;
  EdgeRun result;
  result.end = std::ceil((crossing + edge.on_edge + 0.01) * rate) / rate;
  const auto impacts = run(monitor,
                           {state(monitor, "ball", V(x0, 0, 0.75 + kEdgeR), V(kEdgeV0, 0, 0),
                                  V(0, kEdgeV0 / kEdgeR, 0))},
                           rate, result.end, [&](double t, const StepReport& report) {
                             if (report.contacts.empty() && t < crossing + edge.on_edge)
                               ++result.contact_lost_early;
                           });
  result.impacts = impacts.size();
  std::tie(result.position, result.velocity) = *monitor.predictedState(0, result.end);
  result.free_since = monitor.motionSince(0);
  std::tie(result.free_position, result.free_velocity) =
      *monitor.predictedState(0, result.free_since);
  return result;
}

/// 40 starts a scan, their crossings spread over one update (`rate`) so that the passage from
/// the face to the edge, the slip and the leave fall at every phase of it: after a roll along the
/// top of `before` s. Each flight is held against the reference's from its leave, a parabola
/// from the edge's point at r (sin t, 0, cos t) with the velocity there: the leave's instant
/// as the flight shows it (where it passes the reference's leave point), the instant its flight
/// holds from (motionSince), and the flight's velocity and position at the run's end, each to
/// the integrator's error (its tolerance 1e-9 per step: within 1.6e-9 s, 1.9e-8 m/s and 1.2e-9 m
/// in these runs). Before, 13 (100 Hz) and 2 (1 kHz) of each 40 fell back onto the edge in 1 to
/// 4 impacts, and 3 of 40 at 100 Hz had their flight restarted at the update's end.
void scanTheTablesEdge(double rate, double before) {
  const V gravity(0, 0, -kG);
  for (const EdgeCase& edge : kEdgeCases) {
    int with_impacts = 0, lost = 0, off_n_zero = 0, held = 0;
    double worst_instant = 0, worst_velocity = 0, worst_position = 0;
    const double sin_leaves = std::sqrt(1 - edge.cos_leaves * edge.cos_leaves);
    const V leave_point(0.5 + kEdgeR * sin_leaves, 0, 0.75 + kEdgeR * edge.cos_leaves);
    const V leave_velocity(edge.vx, 0, edge.vz);
    for (int k = 0; k < 40; ++k) {
      const double crossing = before + (k + 0.5) / (40 * rate);
      const EdgeRun flight = offTheTablesEdge(edge, rate, crossing);
      const double leaves = crossing + edge.on_edge, since = flight.end - leaves;
      const double seen_leaving =
          flight.end - (flight.position.x() - leave_point.x()) / flight.velocity.x();
      const double instant = std::abs(seen_leaving - leaves);
      const double velocity = (flight.velocity - (leave_velocity + gravity * since)).norm();
      const double position =
          (flight.position - (leave_point + leave_velocity * since + 0.5 * gravity * since * since))
              .norm();
      with_impacts += flight.impacts > 0;
      lost += flight.contact_lost_early > 0;
      off_n_zero += instant > 1e-8;
      held += std::abs(flight.free_since - leaves) > 1e-8;
      worst_instant = std::max(worst_instant, instant);
      worst_velocity = std::max(worst_velocity, velocity);
      worst_position = std::max(worst_position, position);
    }
    SCOPED_TRACE(std::string(edge.name) + " at " + std::to_string(rate) + " Hz");
    EXPECT_EQ(with_impacts, 0) << "starts (of 40) with an impact at the passage";
    EXPECT_EQ(lost, 0) << "starts (of 40) that lost the contact before N = 0";
    EXPECT_EQ(off_n_zero, 0) << "starts (of 40) that left more than 1e-8 s from N = 0";
    EXPECT_EQ(held, 0) << "starts (of 40) whose flight holds from another instant than N = 0";
    EXPECT_LT(worst_instant, 1e-8);
    EXPECT_LT(worst_velocity, 5e-8);
    EXPECT_LT(worst_position, 5e-9);
  }
}

TEST(EdgeScan, NoImpactAtThePassageAndEveryLeaveAtNZeroAt100Hz) {
  scanTheTablesEdge(100, 0.2 / 0.3);
}
TEST(EdgeScan, NoImpactAtThePassageAndEveryLeaveAtNZeroAt1kHz) { scanTheTablesEdge(1000, 0.005); }

// mu = 1 from x0 = 0.3 at 100 Hz (its crossing at 0.2 / 0.3 s): it slips at t = 0.6836 rad and
// leaves at 0.73992956511789707 s (test/exact/edge_roll_off.py), within the update that ends at
// 0.74 s. Its flight holds from that instant, the centre at cos t = 0.70886157447319529 on the
// circle about the edge, at the edge's velocity then. (It was restarted at 0.74 s, the ball
// touching still: its contact said to end at the update's end, its gap and normal velocity
// closed there as if the edge held it.)
TEST(LastingContact, LeavesAnEdgeWhereItsForceIsZeroNotAtTheUpdatesEnd) {
  const EdgeCase& mu_1 = kEdgeCases[2];
  const EdgeRun flight = offTheTablesEdge(mu_1, 100, 0.2 / 0.3);
  EXPECT_EQ(flight.impacts, 0u);
  EXPECT_EQ(flight.contact_lost_early, 0);
  EXPECT_NEAR(flight.free_since, 0.73992956511789707, 1e-8);
  EXPECT_NEAR((flight.free_position.z() - 0.75) / kEdgeR, mu_1.cos_leaves, 1e-8);
  EXPECT_NEAR(flight.free_velocity.x(), mu_1.vx, 5e-8);
  EXPECT_NEAR(flight.free_velocity.z(), mu_1.vz, 5e-8);
}

}  // namespace
}  // namespace collision_response::core
