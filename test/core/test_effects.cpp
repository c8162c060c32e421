// The effects a scene may turn on (gravity, friction, spin), against closed forms derived by
// hand in the comments.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "collision_response/core/collision.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/time_of_impact.h"

namespace collision_response::core {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();
using V = Eigen::Vector3d;

// --- Gravity: the ballistic time of impact -----------------------------------------------------

// gap(t) = gap + rate t + (a/2) t^2. With gap 0.5 m, rate -0.5 m/s, a = -2 m/s^2:
// 0.5 - 0.5 t - t^2 = 0, roots t = 0.5 and t = -1: the entry is at 0.5 s.
TEST(Gravity, BallisticRootClosedForm) {
  const auto t = timeOfImpactPlaneBallistic(0.5, -0.5, -2.0, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 0.5, 2 * kEps);
}

// Dropped from rest 1 m above the floor: t = sqrt(2 h / g).
TEST(Gravity, DropFromRest) {
  const auto t = timeOfImpactPlaneBallistic(1.0, 0.0, -9.81, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, std::sqrt(2.0 / 9.81), 4 * kEps);
}

// A 1e-12 m gap closed at 100 m/s: t = gap/100 (1 + O(g gap / 100^2)), the correction 5e-16
// relative... of 1e-14 s: below an ulp. The naive root (-r - sqrt(r^2 - 2 a gap)) / a would
// lose every digit to cancellation.
TEST(Gravity, TinyGapFastApproach) {
  const auto t = timeOfImpactPlaneBallistic(1e-12, -100.0, -9.81, 1.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1e-14, 4 * kEps * 1e-14);
}

// Just bounced (inside the touching band, leaving at 2 m/s): not the root where it leaves, but
// the return, 2 u / g later.
TEST(Gravity, ReturnAfterABounce) {
  const auto t = timeOfImpactPlaneBallistic(0.0, 2.0, -9.81, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 4.0 / 9.81, 4 * kEps);
  EXPECT_FALSE(timeOfImpactPlaneBallistic(0.0, 2.0, -9.81, 0.4));  // back after the horizon
  EXPECT_FALSE(timeOfImpactPlaneBallistic(1.0, 0.0, 9.81, 10.0));  // accelerating away
}

// Falling from rest onto a held sphere directly below: |s| = 2 - (g/2) t^2 reaches R = 0.5 at
// t = sqrt(1.5 / 4.905).
TEST(Gravity, FallingOntoAHeldSphere) {
  const auto t = timeOfImpactSpheresAccelerated(V(0, 0, -2), V::Zero(), V(0, 0, 9.81), 0.5, 10.0);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, std::sqrt(1.5 / 4.905), 1e-12);
  // Falling past it 1 m to the side: no contact.
  EXPECT_FALSE(timeOfImpactSpheresAccelerated(V(1, 0, -2), V::Zero(), V(0, 0, 9.81), 0.5, 10.0));
}

// --- Friction and spin at an impact on the floor -------------------------------------------------
//
// A ball of mass m, radius r on an immovable floor (normal a -> b = (0, 0, -1)), arriving at
// (v_x, 0, -v_z) without spin, e = 0.5. The normal impulse is J_n = (1 + e) m v_z. The slip at
// the contact is -v_x along x; a solid sphere's tangential inverse mass is W_t = (1 + 1/k) / m
// with k = 2/5, i.e. 3.5 / m, so stopping the slip takes J_stick = m v_x / 3.5.
//  - sticking (mu J_n >= J_stick): v_x' = v_x - J_stick / m = (5/7) v_x, and it rolls:
//    w_y' = (5/7) v_x / r;
//  - sliding: J_t = mu J_n, v_x' = v_x - mu (1 + e) v_z, w_y' = (5/2) mu (1 + e) v_z / r.
CollisionRequest ballOnFloor(double vx, double vz, double mu) {
  CollisionRequest request;
  request.a.mass = 0.057;
  request.a.radius = 0.033;
  request.a.velocity = V(vx, 0, -vz);
  request.b.mass = kInf;
  request.normal = V(0, 0, -1);
  request.restitution = 0.5;
  request.friction = mu;
  request.effects = {"friction", "spin"};
  return request;
}

TEST(Friction, SolidSphereSticks) {
  const auto outcome = computeCollision(ballOnFloor(3.0, 4.0, 0.2), MaterialTable::seed());
  ASSERT_TRUE(outcome.ok()) << outcome.error().message();
  EXPECT_TRUE(outcome->sticking);
  EXPECT_NEAR(outcome->impact.velocity_a.x(), 15.0 / 7.0, 4 * kEps * 3);
  EXPECT_EQ(outcome->impact.velocity_a.z(), 2.0);  // e v_z, the normal part untouched
  EXPECT_NEAR(outcome->angular_velocity_a.y(), 15.0 / 7.0 / 0.033, 1e-12);
  EXPECT_NEAR(outcome->friction_impulse, 0.057 * 3.0 / 3.5, 1e-15);
  // Rolling: the contact point is still, v_x' = w_y' r.
  EXPECT_NEAR(outcome->impact.velocity_a.x(), outcome->angular_velocity_a.y() * 0.033, 1e-14);
}

TEST(Friction, SolidSphereSlides) {
  const auto outcome = computeCollision(ballOnFloor(3.0, 4.0, 0.05), MaterialTable::seed());
  ASSERT_TRUE(outcome.ok()) << outcome.error().message();
  EXPECT_FALSE(outcome->sticking);
  EXPECT_NEAR(outcome->impact.velocity_a.x(), 3.0 - 0.05 * 1.5 * 4.0, 4 * kEps * 3);
  EXPECT_NEAR(outcome->angular_velocity_a.y(), 2.5 * 0.05 * 1.5 * 4.0 / 0.033, 1e-12);
  EXPECT_NEAR(outcome->friction_impulse, 0.05 * 1.5 * 0.057 * 4.0, 1e-15);
  // Still slipping forward: friction never reverses the slip.
  EXPECT_GT(outcome->impact.velocity_a.x() - outcome->angular_velocity_a.y() * 0.033, 0.0);
}

TEST(Friction, HollowSphereSticksAtThreeFifths) {
  // k = 2/3: W_t = (1 + 3/2) / m, v_x' = v_x - v_x / 2.5 = (3/5) v_x.
  CollisionRequest request = ballOnFloor(3.0, 4.0, 0.5);
  request.a.inertia = Inertia::kHollow;
  const auto outcome = computeCollision(request, MaterialTable::seed());
  ASSERT_TRUE(outcome.ok()) << outcome.error().message();
  EXPECT_NEAR(outcome->impact.velocity_a.x(), 1.8, 4 * kEps * 3);
}

// Topspin: dropped straight down spinning forward at w_y = 50 rad/s. The contact point moves
// back at w r, friction pushes the ball forward; sticking, v_x' = (2/7) w r and w_y' = (2/7) w.
TEST(Friction, TopspinKicksForward) {
  CollisionRequest request = ballOnFloor(0.0, 4.0, 1.0);
  request.a.angular_velocity = V(0, 50, 0);
  const auto outcome = computeCollision(request, MaterialTable::seed());
  ASSERT_TRUE(outcome.ok()) << outcome.error().message();
  EXPECT_TRUE(outcome->sticking);
  EXPECT_NEAR(outcome->impact.velocity_a.x(), 2.0 / 7.0 * 50 * 0.033, 1e-14);
  EXPECT_NEAR(outcome->angular_velocity_a.y(), 2.0 / 7.0 * 50, 1e-12);
}

TEST(Friction, WithoutSpinNothingTurns) {
  // Friction alone: the ball is a point for the tangential impulse, W_t = 1/m, so sticking
  // stops the slip entirely: v_x' = 0; the angular velocity is carried unchanged.
  CollisionRequest request = ballOnFloor(3.0, 4.0, 1.0);
  request.effects = {"friction"};
  request.a.angular_velocity = V(1, 2, 3);
  const auto outcome = computeCollision(request, MaterialTable::seed());
  ASSERT_TRUE(outcome.ok()) << outcome.error().message();
  EXPECT_NEAR(outcome->impact.velocity_a.x(), 0.0, 4 * kEps * 3);
  EXPECT_EQ(outcome->angular_velocity_a, V(1, 2, 3));
}

TEST(Friction, RequestErrors) {
  CollisionRequest request = ballOnFloor(3.0, 4.0, -0.1);
  EXPECT_EQ(computeCollision(request, MaterialTable::seed()).error().field, "friction");
  request = ballOnFloor(3.0, 4.0, 0.3);
  request.effects = {};
  EXPECT_EQ(computeCollision(request, MaterialTable::seed()).error().field, "friction");
  request = ballOnFloor(3.0, 4.0, 0.3);
  request.a.material = "tennis_ball";
  request.b.material = "concrete";
  request.restitution = 0.0;
  EXPECT_EQ(computeCollision(request, MaterialTable::seed()).error().field, "friction");
  request.friction = 0.0;  // the pair's: tennis ball on concrete has the default
  const auto outcome = computeCollision(request, MaterialTable::seed());
  ASSERT_TRUE(outcome.ok()) << outcome.error().message();
  request.effects = {"friction", "friction"};
  EXPECT_EQ(computeCollision(request, MaterialTable::seed()).error().field, "effects[1]");
}

// With friction and spin on, energy never increases: random impacts with random spins, mu in
// [0, 2], e in [0, 1], solid and hollow, masses 1e-2..1e2 kg (and immovable, not spinning). Kinetic
// energy (linear and rotational) is summed in long double; it may not grow by more than rounding,
// and the reported energy lost is what it lost.
TEST(Friction, EnergyNeverIncreases) {
  std::mt19937_64 engine(11);
  std::uniform_real_distribution<double> unit(-1, 1), zero_one(0, 1);
  const auto vector = [&](double scale) {
    return V(scale * unit(engine), scale * unit(engine), scale * unit(engine));
  };
  for (int i = 0; i < 20000; ++i) {
    CollisionRequest request;
    request.a.mass = std::pow(10.0, 2 * unit(engine));
    request.b.mass = i % 5 == 0 ? kInf : std::pow(10.0, 2 * unit(engine));
    request.a.radius = 0.01 + zero_one(engine);
    request.b.radius = 0.01 + zero_one(engine);
    request.a.inertia = i % 2 ? Inertia::kSolid : Inertia::kHollow;
    request.a.velocity = vector(10);
    request.b.velocity = vector(10);
    request.a.angular_velocity = vector(100);
    // An immovable body that spins is a driven wheel: it may hand energy to the other (the
    // reported energy lost is what the contact dissipates). Here immovable bodies do not spin.
    request.b.angular_velocity = std::isinf(request.b.mass) ? V::Zero() : vector(100);
    request.b.position = vector(1);
    request.restitution = zero_one(engine);
    request.friction = 2 * zero_one(engine);
    request.effects = {"friction", "spin"};
    const auto outcome = computeCollision(request, MaterialTable::seed());
    ASSERT_TRUE(outcome.ok()) << outcome.error().message();
    const auto energy = [&](const Body& body, const V& v, const V& w) -> long double {
      if (std::isinf(body.mass)) return 0.0L;
      const double k = body.inertia == Inertia::kSolid ? 0.4 : 2.0 / 3.0;
      const long double inertia = k * body.mass * body.radius * body.radius;
      return 0.5L * body.mass * v.cast<long double>().squaredNorm() +
             0.5L * inertia * w.cast<long double>().squaredNorm();
    };
    // Against an immovable body the energy is counted in its rest frame.
    const V frame = std::isinf(request.b.mass) ? request.b.velocity : V::Zero();
    const long double before =
        energy(request.a, request.a.velocity - frame, request.a.angular_velocity) +
        energy(request.b, request.b.velocity, request.b.angular_velocity);
    const long double after =
        energy(request.a, outcome->impact.velocity_a - frame, outcome->angular_velocity_a) +
        energy(request.b, outcome->impact.velocity_b, outcome->angular_velocity_b);
    const double tolerance = 64 * kEps * double(before);
    ASSERT_LE(double(after - before), tolerance) << "case " << i;
    ASSERT_GE(outcome->impact.energy_lost, 0.0) << "case " << i;
    ASSERT_NEAR(double(before - after), outcome->impact.energy_lost, tolerance) << "case " << i;
  }
}

// Effects on, but nothing for them to do (mu = 0, no spin): the very same numbers as the seed's
// model, bit for bit.
TEST(Effects, FrictionlessSpinlessImpactIsIdenticalWithEffectsOnAndOff) {
  std::mt19937_64 engine(12);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int i = 0; i < 5000; ++i) {
    CollisionRequest off;
    off.a.mass = std::pow(10.0, 2 * unit(engine));
    off.b.mass = std::pow(10.0, 2 * unit(engine));
    off.a.radius = 0.1;
    off.b.radius = 0.2;
    off.a.velocity = V(unit(engine), unit(engine), unit(engine));
    off.b.velocity = V(unit(engine), unit(engine), unit(engine));
    off.b.position = V(unit(engine), unit(engine), unit(engine));
    off.restitution = 0.5 * (1 + unit(engine));
    CollisionRequest on = off;
    on.effects = {"gravity", "friction", "spin"};
    const auto without = computeCollision(off, MaterialTable::seed());
    const auto with = computeCollision(on, MaterialTable::seed());
    ASSERT_TRUE(without.ok() && with.ok());
    ASSERT_EQ(with->impact.velocity_a, without->impact.velocity_a) << i;
    ASSERT_EQ(with->impact.velocity_b, without->impact.velocity_b) << i;
    ASSERT_EQ(with->impact.normal_impulse, without->impact.normal_impulse) << i;
    ASSERT_EQ(with->impact.energy_lost, without->impact.energy_lost) << i;
    ASSERT_EQ(with->angular_velocity_a, V::Zero()) << i;
  }
}

// --- A ball bouncing to rest ------------------------------------------------------------------
//
// Dropped from rest with its surface h = 1 m above the floor, g = 9.81, e = 0.7, threshold
// v_th = 1 m/s. It meets the floor at v_0 = sqrt(2 g h), and after the k-th bounce leaves at
// e^k v_0. Impacts at or above v_th bounce: those with e^k v_0 >= v_th, k = 0..N-1, where
// N = floor(ln(v_th / v_0) / ln e) + 1 (here 5); the next impact, at e^N v_0 < v_th, rests.
// So N + 1 impacts in all, the last at t_rest = sqrt(2 h / g) + sum_{k=1..N} 2 e^k v_0 / g, and
// after it the ball lies on the floor, never below it.
TEST(Gravity, BallBouncesToRestInFinitelyManyImpacts) {
  const double g = 9.81, h = 1.0, e = 0.7, threshold = 1.0, r = 0.05;
  Scene scene;
  ASSERT_TRUE(scene.materials.addMaterial("putty", Material{e, {}}, "m").ok());
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -g);
  scene.restitution_threshold = threshold;
  BodySpec ball;
  ball.id = "ball";
  ball.mass = 0.1;
  ball.radius = r;
  ball.material = "putty";
  scene.bodies = {ball};
  ObstacleSpec floor;
  floor.id = "floor";
  floor.material = "putty";
  scene.obstacles = {floor};
  MonitorSettings settings;
  settings.body_timeout = 100.0;
  ImpactMonitor monitor(scene, settings);

  const double v0 = std::sqrt(2 * g * h);
  const int bounces = static_cast<int>(std::floor(std::log(threshold / v0) / std::log(e))) + 1;
  ASSERT_EQ(bounces, 5);
  double t_rest = std::sqrt(2 * h / g);
  for (int k = 1; k <= bounces; ++k) t_rest += 2 * std::pow(e, k) * v0 / g;

  BodyStateSample start;
  start.body = 0;
  start.time = 0.0;
  start.position = V(0, 0, h + r);
  monitor.step(0.0, {start});
  std::vector<ImpactRecord> impacts;
  double lowest = INFINITY;
  for (int k = 1; k <= 500; ++k) {  // 100 Hz for 5 s, no states: the monitor's own motion
    const double t = 0.01 * k;
    for (const ImpactRecord& impact : monitor.step(t, {}).impacts) impacts.push_back(impact);
    lowest = std::min(lowest, monitor.predictedState(0, t)->first.z());
  }
  ASSERT_EQ(impacts.size(), static_cast<std::size_t>(bounces + 1));
  for (int k = 0; k < bounces; ++k) EXPECT_EQ(impacts[k].restitution, e) << k;
  EXPECT_EQ(impacts.back().restitution, 0.0);
  EXPECT_NEAR(impacts.back().time, t_rest, 1e-12);
  EXPECT_NEAR(-impacts.back().velocity_a_before.z(), std::pow(e, bounces) * v0, 1e-12);
  EXPECT_TRUE(monitor.restingOn(0).has_value());
  EXPECT_GE(lowest, r - 1e-12) << "never below the floor";
  EXPECT_NEAR(monitor.predictedState(0, 5.0)->first.z(), r, 1e-12);
}

// Without a threshold (0), e < 1 would bounce for ever in finite time; a bounce too slow to
// leave the touching band rests instead (restSpeed), after finitely many impacts.
TEST(Gravity, ZeroThresholdStillComesToRest) {
  Scene scene;
  ASSERT_TRUE(scene.materials.addMaterial("putty", Material{0.7, {}}, "m").ok());
  scene.effects.gravity = true;
  BodySpec ball;
  ball.id = "ball";
  ball.mass = 0.1;
  ball.radius = 0.05;
  ball.material = "putty";
  scene.bodies = {ball};
  ObstacleSpec floor;
  floor.id = "floor";
  floor.material = "putty";
  scene.obstacles = {floor};
  MonitorSettings settings;
  settings.body_timeout = 100.0;
  ImpactMonitor monitor(scene, settings);
  BodyStateSample start;
  start.position = V(0, 0, 1.05);
  monitor.step(0.0, {start});
  std::size_t impacts = 0;
  bool truncated = false;
  for (int k = 1; k <= 500; ++k) {
    const StepReport report = monitor.step(0.01 * k, {});
    impacts += report.impacts.size();
    truncated = truncated || report.truncated;
  }
  EXPECT_FALSE(truncated);
  EXPECT_LT(impacts, 100u);
  EXPECT_TRUE(monitor.restingOn(0).has_value());
  EXPECT_NEAR(monitor.predictedState(0, 5.0)->first.z(), 0.05, 1e-9);
}

}  // namespace
}  // namespace collision_response::core
