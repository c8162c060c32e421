// Issue 41, item 4: one simultaneous impact of many bodies is bounded. A touching lattice of
// balls with friction and spin closing on its centre in one message is one impact cluster whose
// joint solves, round after round, cost 44 s for 12 x 12 x 12 balls in one update. The joint
// solves of a step now spend at most MonitorSettings::max_impact_work_per_step (contact
// iterations): past it a friction solve stops where it got to, and a cluster whose normal solve
// would pass it is locked together (doc/model.md, "Simultaneous contacts"). What must hold
// whatever the bound cuts: the fallback named (StepReport::over_impact_work), the work counted
// within the bound, no ball inside another or a wall, no kinetic energy gained, momentum kept
// (free lattice); and under the bound, the exact answer to the bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;

constexpr double kRadius = 0.05;  // m
constexpr double kMass = 0.1;     // kg
constexpr double kStep = 0.01;    // s: the second message, 10 ms after the first

/// n^3 touching balls (spacing 2 r, solid: I = 2/5 m r^2), e = 0.5 and mu = 0.3 on every
/// contact, friction and spin, no gravity; `walls`: a box of six planes touching the outer balls.
Scene latticeScene(int n, bool walls) {
  Scene scene;
  scene.effects.friction = true;
  scene.effects.spin = true;
  EXPECT_TRUE(scene.materials.addMaterial("clay", Material{0.5, 0.3}, "m").ok());
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        char id[32];
        std::snprintf(id, sizeof id, "ball_%d_%d_%d", i, j, k);
        scene.bodies.push_back(scene_builders::ball(
            id, kMass, kRadius, "clay", V(2 * kRadius * i, 2 * kRadius * j, 2 * kRadius * k)));
      }
    }
  }
  if (walls) {
    const double far = 2 * kRadius * (n - 1) + kRadius;
    for (int axis = 0; axis < 3; ++axis) {
      scene.obstacles.push_back(
          scene_builders::plane("low" + std::to_string(axis), V::Unit(axis), -kRadius, "clay"));
      scene.obstacles.push_back(
          scene_builders::plane("high" + std::to_string(axis), -V::Unit(axis), -far, "clay"));
    }
  }
  return scene;
}

/// The states of the first message: each ball closing on the centre at 1 m/s per m, swirling
/// about z at 1 rad/s, spinning at up to 10 rad/s about an axis of its own (seeded).
std::vector<BodyStateSample> closingStates(const ImpactMonitor& monitor, int n) {
  std::mt19937_64 engine(3);
  std::uniform_real_distribution<double> unit(-1, 1);
  const V centre = V::Constant(kRadius * (n - 1));
  std::vector<BodyStateSample> states;
  for (std::size_t b = 0; b < monitor.bodyCount(); ++b) {
    BodyStateSample state;
    state.body = b;
    state.position = monitor.body(b).position;
    const V offset = state.position - centre;
    state.velocity = -offset + V::UnitZ().cross(offset);
    state.angular_velocity = 10 * V(unit(engine), unit(engine), unit(engine));
    states.push_back(state);
  }
  return states;
}

struct Motion {
  std::vector<V> position, velocity, angular_velocity;
};

Motion motionAt(const ImpactMonitor& monitor, double time) {
  Motion motion;
  for (std::size_t b = 0; b < monitor.bodyCount(); ++b) {
    const auto state = monitor.predictedState(b, time);
    motion.position.push_back(state->first);
    motion.velocity.push_back(state->second);
    motion.angular_velocity.push_back(monitor.predictedAngularVelocity(b, time));
  }
  return motion;
}

/// 1/2 m v^2 + 1/2 I w^2 summed in long double (I = 2/5 m r^2).
long double kineticEnergy(const std::vector<V>& velocity, const std::vector<V>& angular) {
  long double energy = 0;
  for (std::size_t b = 0; b < velocity.size(); ++b) {
    energy += 0.5L * kMass * static_cast<long double>(velocity[b].squaredNorm()) +
              0.5L * 0.4L * kMass * kRadius * kRadius *
                  static_cast<long double>(angular[b].squaredNorm());
  }
  return energy;
}

/// The deepest any ball is into another (m, > 0 inside), and into a wall of the box of
/// latticeScene(n, true) where `walls`.
double deepest(const std::vector<V>& position, int n, bool walls) {
  double depth = -std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < position.size(); ++a) {
    for (std::size_t b = a + 1; b < position.size(); ++b) {
      depth = std::max(depth, 2 * kRadius - (position[b] - position[a]).norm());
    }
    if (!walls) continue;
    const double far = 2 * kRadius * (n - 1) + kRadius;
    for (int axis = 0; axis < 3; ++axis) {
      depth = std::max(depth, kRadius - (position[a][axis] + kRadius));
      depth = std::max(depth, kRadius - (far - position[a][axis]));
    }
  }
  return depth;
}

/// The lattice met in one message under `bound`: the first message starts the monitor, the
/// second (10 ms later, no states) is the update that resolves the impact at the first's instant.
struct LatticeRun {
  StepReport report;
  std::vector<BodyStateSample> states;
  Motion after;
};

LatticeRun closeLattice(int n, bool walls, std::size_t bound) {
  const Scene scene = latticeScene(n, walls);
  MonitorSettings settings;
  settings.max_impact_work_per_step = bound;
  ImpactMonitor monitor(scene, settings);
  LatticeRun run;
  run.states = closingStates(monitor, n);
  monitor.step(0.0, run.states);
  run.report = monitor.step(kStep, {});
  run.after = motionAt(monitor, kStep);
  return run;
}

// A 6 x 6 x 6 lattice (216 balls, 540 touching pairs) under a bound of 5,000 contact iterations;
// unbounded, its joint friction solves spend about 490,000 (0.5 s).
TEST(ImpactWorkBound, ALatticeClosingInOneMessageIsCutAtTheBoundNamedKeptApartAndLosesEnergy) {
  const int n = 6;
  const std::size_t bound = 5000;
  const LatticeRun run = closeLattice(n, false, bound);
  const StepReport& report = run.report;
  ASSERT_FALSE(report.impacts.empty());
  // The fallback was taken and names the balls (every ball of the lattice's cluster).
  EXPECT_EQ(report.over_impact_work.size(), 216u);
  EXPECT_TRUE(std::is_sorted(report.over_impact_work.begin(), report.over_impact_work.end()));
  // The count: no joint friction solve spends past what the step has left.
  EXPECT_GT(report.impact_work, 0u);
  EXPECT_LE(report.impact_work, bound);
  EXPECT_FALSE(report.truncated);

  // No ball inside another (the contact tolerance: 1e-9 of the contact distance 2 r).
  EXPECT_LE(deepest(run.after.position, n, false), 1e-9 * 2 * kRadius);

  // No kinetic energy gained (summed in long double from the doubles the monitor holds).
  std::vector<V> velocity, angular;
  for (const BodyStateSample& state : run.states) {
    velocity.push_back(state.velocity);
    angular.push_back(state.angular_velocity);
  }
  const long double before = kineticEnergy(velocity, angular);
  const long double after = kineticEnergy(run.after.velocity, run.after.angular_velocity);
  EXPECT_LE(after, before);
  EXPECT_LT(after, 0.9L * before) << "the impact at e = 0.5 removes energy";

  // Momentum: every impulse acts on two balls, equal and opposite, so only the rounding of each
  // ball's velocity moves the sum: once for each solve the ball takes part in (at most twice an
  // impact of it: the normal solve and the friction's), half an ulp of its speed each. The
  // bound: 4 ulps of m v_max for each impact of each ball.
  V momentum_before = V::Zero(), momentum_after = V::Zero();
  double fastest = 0;
  for (std::size_t b = 0; b < velocity.size(); ++b) {
    momentum_before += kMass * velocity[b];
    momentum_after += kMass * run.after.velocity[b];
    fastest = std::max({fastest, velocity[b].norm(), run.after.velocity[b].norm()}, std::less<>());
  }
  const double ball_impacts = 2.0 * static_cast<double>(report.impacts.size());
  EXPECT_LE((momentum_after - momentum_before).lpNorm<Eigen::Infinity>(),
            4 * ball_impacts * std::numeric_limits<double>::epsilon() * kMass * fastest)
      << "momentum before " << momentum_before.transpose() << " after "
      << momentum_after.transpose();
}

// Once a cluster's normal solve would pass the bound, every later cluster of the step is locked
// too (MonitorSettings::max_impact_work_per_step): the step's work is spent. Beside the 6 x 6 x 6
// lattice under 5,000, 10 m away, three balls in a row: the outer two close on the middle one at
// 1 m/s each, at the same instant. Solved (Newton, e = 0.5), by symmetry the middle one keeps
// still and each outer one leaves at e 1 m/s = 0.5 m/s: A J = (1 + e) 1 m/s with A = 2w - w
// (w = 1/m), so J = 1.5 m/s times m and dv = w J = 1.5 m/s. Locked, all three take their centre
// of mass's velocity, zero. Before, a cut left the step's count under the bound and the row was
// solved as if nothing had run out.
TEST(ImpactWorkBound, AfterACutTheStepsLaterClustersAreLockedToo) {
  const int n = 6;
  Scene scene = latticeScene(n, false);
  const char* row[] = {"zrow_a", "zrow_b", "zrow_c"};
  for (int k = 0; k < 3; ++k) {
    scene.bodies.push_back(
        scene_builders::ball(row[k], kMass, kRadius, "clay", V(10 + 2 * kRadius * k, 0, 0)));
  }
  MonitorSettings settings;
  settings.max_impact_work_per_step = 5000;
  ImpactMonitor monitor(scene, settings);
  std::vector<BodyStateSample> states = closingStates(monitor, n);
  const std::size_t first = states.size() - 3;
  for (int k = 0; k < 3; ++k) {
    states[first + k].velocity = V(k == 0 ? 1.0 : (k == 2 ? -1.0 : 0.0), 0, 0);
    states[first + k].angular_velocity = V::Zero();
  }
  monitor.step(0.0, states);
  const StepReport report = monitor.step(kStep, {});
  ASSERT_FALSE(report.over_impact_work.empty());
  EXPECT_LE(report.impact_work, 5000u);
  for (int k = 0; k < 3; ++k) {
    const V velocity = monitor.predictedState(first + k, kStep)->second;
    EXPECT_NEAR(velocity.x(), 0.0, 1e-15) << row[k] << " (solved: -0.5, 0, 0.5 m/s)";
    EXPECT_NE(std::find(report.over_impact_work.begin(), report.over_impact_work.end(), first + k),
              report.over_impact_work.end())
        << row[k] << " is not named";
  }
}

// The same lattice met inside a box whose walls touch its outer balls: balls sent outwards by
// the impact strike the walls in later rounds of the same instant, with friction cut short.
TEST(ImpactWorkBound, ALatticeClosingInABoxStaysOutOfItsWallsPastTheBound) {
  const int n = 5;
  const std::size_t bound = 2000;
  const LatticeRun run = closeLattice(n, true, bound);
  EXPECT_FALSE(run.report.over_impact_work.empty());
  EXPECT_LE(run.report.impact_work, bound);
  EXPECT_LE(deepest(run.after.position, n, true), 1e-9 * 2 * kRadius);
  std::vector<V> velocity, angular;
  for (const BodyStateSample& state : run.states) {
    velocity.push_back(state.velocity);
    angular.push_back(state.angular_velocity);
  }
  EXPECT_LE(kineticEnergy(run.after.velocity, run.after.angular_velocity),
            kineticEnergy(velocity, angular));
}

// Under the bound nothing changes: a 2 x 2 x 2 lattice (its joint solves spend well
// below the default bound) gives the same impacts and motion, to the bit, bounded and not.
TEST(ImpactWorkBound, UnderTheBoundTheImpactIsTheExactOneToTheBit) {
  const int n = 2;
  const LatticeRun bounded = closeLattice(n, false, MonitorSettings{}.max_impact_work_per_step);
  const LatticeRun unbounded = closeLattice(n, false, 0);
  EXPECT_TRUE(bounded.report.over_impact_work.empty());
  EXPECT_GT(bounded.report.impact_work, 0u);
  EXPECT_LT(bounded.report.impact_work, MonitorSettings{}.max_impact_work_per_step);
  EXPECT_EQ(bounded.report.impact_work, unbounded.report.impact_work);
  ASSERT_EQ(bounded.report.impacts.size(), unbounded.report.impacts.size());
  for (std::size_t k = 0; k < bounded.report.impacts.size(); ++k) {
    EXPECT_EQ(bounded.report.impacts[k].impulse, unbounded.report.impacts[k].impulse) << k;
    EXPECT_EQ(bounded.report.impacts[k].friction_impulse,
              unbounded.report.impacts[k].friction_impulse)
        << k;
  }
  for (std::size_t b = 0; b < bounded.after.velocity.size(); ++b) {
    EXPECT_EQ(bounded.after.velocity[b], unbounded.after.velocity[b]) << b;
    EXPECT_EQ(bounded.after.angular_velocity[b], unbounded.after.angular_velocity[b]) << b;
  }
}

}  // namespace
}  // namespace collision_response::core
