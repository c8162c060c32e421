// Scale: pair responses per second, and one state update of a gas of 1k, 10k and 100k spheres
// in a box (every body's state each update, as a source that applies the responses sends
// them), with Bullet's btDbvtBroadphase and solver on the same gas in the same run; and one
// update of piles of up to 1,000 balls at rest in a box (lasting contact under gravity: one
// layer 1 mm apart or touching, and a stack 10 high), against the same pile with gravity off
// and against Bullet on the same pile; and the friction of one cluster of up to 1,000 touching,
// spinning balls (the joint tangential solve alone); and a pile of 8 dropped into a box with
// friction and spin, played as the scene player plays it, beside Bullet and MuJoCo on piles of
// 8 to 1,000 (issue 26's piles: bench/dropped_pile.h).
// scripts/performance.sh runs it and writes doc/performance.md.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "box_walls.h"
#include "collision_response/core/impact.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/playback.h"
#include "collision_response/core/triangle_mesh.h"
#include "dropped_pile.h"
#include "geometry/narrow_phase.h"
#include "solver/cluster_solver.h"
#ifdef COLLISION_RESPONSE_WITH_BULLET
#include <BulletCollision/NarrowPhaseCollision/btContinuousConvexCollision.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <btBulletDynamicsCommon.h>
#endif
#ifdef COLLISION_RESPONSE_WITH_MUJOCO
#include <mujoco/mujoco.h>

#include <cstring>
#endif

namespace collision_response::bench {
namespace {

using V = Eigen::Vector3d;

/// N balls of radius 0.05 m at 2 m/s at most, one per 0.5 m cube of a closed box: the same
/// density (and impacts per body per second) at every N.
struct Gas {
  core::Scene scene;
  double size = 0;
};

Gas makeGas(int count) {
  Gas gas;
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(count))));
  gas.size = 0.5 * side;
  (void)gas.scene.materials.addMaterial("elastic", core::Material{1.0, {}}, "m");
  std::mt19937_64 engine(5);
  std::uniform_real_distribution<double> speed(-2, 2);
  for (int i = 0; i < count; ++i) {
    core::BodySpec body;
    body.id = "gas_" + std::to_string(1000000 + i);
    body.mass = 0.1;
    body.radius = 0.05;
    body.material = "elastic";
    body.position = V(0.25 + 0.5 * (i % side), 0.25 + 0.5 * ((i / side) % side),
                      0.25 + 0.5 * (i / (side * side)));
    body.velocity = V(speed(engine), speed(engine), speed(engine));
    gas.scene.bodies.push_back(body);
  }
  addBoxWalls(gas.scene, gas.size, "elastic");
  return gas;
}

void BM_PairResponse(benchmark::State& state) {
  std::mt19937_64 engine(1);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<V> velocities(1024), normals(1024);
  for (std::size_t i = 0; i < 1024; ++i) {
    velocities[i] = V(unit(engine), unit(engine), unit(engine));
    normals[i] = V(unit(engine), unit(engine), unit(engine)).normalized();
  }
  std::size_t i = 0;
  for (auto _ : state) {
    const auto r = core::resolveImpact(2.0, velocities[i & 1023], 3.0, velocities[(i + 7) & 1023],
                                       normals[i & 1023], 0.8);
    benchmark::DoNotOptimize(r);
    ++i;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

void BM_GasUpdate(benchmark::State& state) {
  const Gas gas = makeGas(static_cast<int>(state.range(0)));
  core::MonitorSettings settings;
  core::ImpactMonitor monitor(gas.scene, settings);
  std::vector<core::BodyStateSample> states(gas.scene.bodies.size());
  for (std::size_t i = 0; i < states.size(); ++i) {
    states[i].body = *monitor.bodyIndex(gas.scene.bodies[i].id);
    states[i].position = gas.scene.bodies[i].position;
    states[i].velocity = gas.scene.bodies[i].velocity;
  }
  monitor.step(0.0, states);
  double time = 0.0;
  std::size_t impacts = 0;
  for (auto _ : state) {
    time += 0.01;
    for (core::BodyStateSample& sample : states) {
      const auto predicted = monitor.predictedState(sample.body, time);
      sample.time = time;
      sample.position = predicted->first;
      sample.velocity = predicted->second;
    }
    impacts += monitor.step(time, states).impacts.size();
  }
  state.counters["impacts/update"] =
      static_cast<double>(impacts) / static_cast<double>(state.iterations());
  state.counters["bodies"] = static_cast<double>(states.size());
}

/// A pile at rest: `columns` x `rows` x `layers` balls (radius 0.05 m, 0.1 kg, e = 0.5,
/// frictionless) on a floor in a cubic lattice, `gap` apart in each layer (0: each touching its
/// neighbours), each layer resting on the one below (its balls right above theirs, touching),
/// walls around the lattice touching its outer balls. With gravity it is at rest exactly (each
/// ball carries the ones above it, no force between neighbours in a layer): every ball has a
/// lasting contact with the floor or the ball below.
constexpr double kPileRadius = 0.05;

core::Scene makePile(int columns, int rows, int layers, double gap, bool gravity) {
  core::Scene scene;
  scene.effects.gravity = gravity;
  (void)scene.materials.addMaterial("pile", core::Material{0.5, {}}, "m");
  const double r = kPileRadius, pitch = 2 * r + gap;
  for (int i = 0; i < columns * rows * layers; ++i) {
    core::BodySpec body;
    char id[16];
    std::snprintf(id, sizeof id, "ball_%04d", i);
    body.id = id;
    body.mass = 0.1;
    body.radius = r;
    body.material = "pile";
    const int layer = i / (columns * rows), cell = i % (columns * rows);
    body.position =
        V(r + pitch * (cell % columns), r + pitch * (cell / columns), r + 2 * r * layer);
    scene.bodies.push_back(body);
  }
  const double length = pitch * columns - gap, width = pitch * rows - gap;
  const std::pair<V, double> walls[] = {{V(0, 0, 1), 0.0},
                                        {V(1, 0, 0), 0.0},
                                        {V(-1, 0, 0), -length},
                                        {V(0, 1, 0), 0.0},
                                        {V(0, -1, 0), -width}};
  int w = 0;
  for (const auto& [normal, offset] : walls) {
    core::ObstacleSpec wall;
    wall.id = "wall_" + std::to_string(w++);
    wall.material = "pile";
    wall.normal = normal;
    wall.offset = offset;
    scene.obstacles.push_back(wall);
  }
  return scene;
}

/// The pile of a benchmark's arguments: columns, rows, layers, gap (um), gravity (1) or not (0).
core::Scene pileOf(const benchmark::State& state) {
  return makePile(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)),
                  static_cast<int>(state.range(2)), 1e-6 * static_cast<double>(state.range(3)),
                  state.range(4) != 0);
}

/// One update of the pile at 100 Hz, the monitor's step alone: every body's state from a source
/// that follows the monitor, as the scene player and the accuracy benchmark do (core::Playback,
/// which moves the bodies by the monitor's model, resting contact included, and applies the
/// impacts reported). The source's own time per update is the counter source_ms (not timed).
void BM_PileUpdate(benchmark::State& state) {
  const core::Scene scene = pileOf(state);
  core::MonitorSettings settings;
  core::ImpactMonitor monitor(scene, settings);
  core::Playback source(scene, settings.contact_tolerance, 0.0);
  std::vector<core::BodyStateSample> states(scene.bodies.size());
  const auto sample = [&](double time) {
    for (std::size_t i = 0; i < states.size(); ++i) {
      states[i].time = time;
      states[i].position = source.position(i, time);
      states[i].velocity = source.velocity(i, time);
      states[i].angular_velocity = source.angularVelocity(i, time);
    }
  };
  for (std::size_t i = 0; i < states.size(); ++i) {
    states[i].body = *monitor.bodyIndex(scene.bodies[i].id);
  }
  sample(0.0);
  monitor.step(0.0, states);
  double time = 0.0, source_seconds = 0.0;
  std::size_t impacts = 0, contacts = 0, fallbacks = 0, stepped = 0;
  for (auto _ : state) {
    state.PauseTiming();
    time += 0.01;
    const auto began = std::chrono::steady_clock::now();
    sample(time);
    source_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
    state.ResumeTiming();
    const core::StepReport report = monitor.step(time, states);
    state.PauseTiming();
    impacts += report.impacts.size();
    contacts += report.contacts.size();
    fallbacks += report.fallbacks;
    stepped = report.stepped_bodies;
    for (const core::ImpactRecord& impact : report.impacts)
      source.applyImpact(monitor, impact, true);
    state.ResumeTiming();
  }
  double drift = 0;
  for (std::size_t i = 0; i < states.size(); ++i) {
    drift = std::max(drift, (states[i].position - scene.bodies[i].position).norm());
  }
  const auto updates = static_cast<double>(state.iterations());
  state.counters["impacts/update"] = static_cast<double>(impacts) / updates;
  state.counters["contacts/update"] = static_cast<double>(contacts) / updates;
  state.counters["source_ms"] = 1e3 * source_seconds / updates;
  state.counters["drift_m"] = drift;  // the farthest any centre moved from the lattice
  state.counters["bodies"] = static_cast<double>(states.size());
  // In stepped clusters after the last update (doc/model.md, "Lasting contact"), and what the
  // fallbacks did (a stepped sub-step held still, for one) per update.
  state.counters["stepped_bodies"] = static_cast<double>(stepped);
  state.counters["fallbacks/update"] = static_cast<double>(fallbacks) / updates;
}

/// The piles: 1,000 balls in one layer 1 mm apart and touching, and 10 x 10 x 10 touching in a
/// stack (gravity on and off: with gravity all three are stepped clusters, each ball within a
/// sub-step's reach of its neighbours); one layer of 25, 100 and 225 touching.
void pileArguments(benchmark::internal::Benchmark* bench, bool with_gravity_off) {
  bench->ArgNames({"columns", "rows", "layers", "gap_um", "gravity"});
  const std::vector<std::vector<std::int64_t>> thousands = {
      {40, 25, 1, 1000}, {40, 25, 1, 0}, {10, 10, 10, 0}};
  for (const std::vector<std::int64_t>& pile : thousands) {
    bench->Args({pile[0], pile[1], pile[2], pile[3], 1});
    if (with_gravity_off) bench->Args({pile[0], pile[1], pile[2], pile[3], 0});
  }
  for (const int side : {5, 10, 15}) bench->Args({side, side, 1, 0, 1});
}
BENCHMARK(BM_PileUpdate)
    ->Apply([](benchmark::internal::Benchmark* bench) { pileArguments(bench, true); })
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

/// Balls among shaped bodies (doc/model.md, "Balls among shaped bodies"): `range(0)` balls
/// (radius 0.05 m, 0.1 kg, e = 0.5, frictionless) dropped from rest 0.3 to 0.6 m above a floor, a
/// grid 0.3 m apart (never touching each other), bouncing until they rest, for 1 s at 100 Hz on
/// the monitor's own motion; with `range(1)` 1, a box (0.1 m cube) at rest on the floor beside
/// them, so that the balls move as rigid spheres by the shaped bodies' engine; with 0, by the
/// balls' own. The ratio of the two is what a shaped body costs the balls of its scene.
void BM_BallsAmongShapes(benchmark::State& state) {
  const int balls = static_cast<int>(state.range(0));
  const bool with_box = state.range(1) != 0;
  core::Scene scene;
  scene.effects.gravity = true;
  (void)scene.materials.addMaterial("bouncy", core::Material{0.5, {}}, "m");
  const int side = static_cast<int>(std::ceil(std::sqrt(balls)));
  for (int i = 0; i < balls; ++i) {
    core::BodySpec ball;
    ball.id = "ball_" + std::to_string(i);
    ball.mass = 0.1;
    ball.radius = 0.05;
    ball.material = "bouncy";
    ball.position = V(0.3 * (i % side), 0.3 * (i / side), 0.35 + 0.3 * (i % 7) / 6.0);
    scene.bodies.push_back(ball);
  }
  if (with_box) {
    core::BodySpec box;
    box.id = "box";
    box.mass = 1.0;
    box.material = "bouncy";
    box.shape = core::BodyShape::kBox;
    box.size = V(0.1, 0.1, 0.1);
    box.position = V(-0.3, -0.3, 0.05);
    scene.bodies.push_back(box);
  }
  core::ObstacleSpec floor;
  floor.id = "floor";
  floor.material = "bouncy";
  scene.obstacles.push_back(floor);
  core::MonitorSettings settings;
  settings.body_timeout = INFINITY;  // no states after the first: the monitor's own motion
  std::size_t impacts = 0;
  for (auto _ : state) {
    core::ImpactMonitor monitor(scene, settings);
    std::vector<core::BodyStateSample> states;
    for (const core::BodySpec& body : scene.bodies) {
      core::BodyStateSample sample;
      sample.body = *monitor.bodyIndex(body.id);
      sample.position = body.position;
      states.push_back(sample);
    }
    monitor.step(0.0, states);
    impacts = 0;
    for (int k = 1; k <= 100; ++k) impacts += monitor.step(0.01 * k, {}).impacts.size();
  }
  state.counters["impacts"] = static_cast<double>(impacts);
  state.counters["balls"] = static_cast<double>(balls);
}
BENCHMARK(BM_BallsAmongShapes)->ArgsProduct({{8, 32}, {0, 1}})->Unit(benchmark::kMillisecond);

/// A frictional cluster: side^3 touching balls (radius 0.05 m, 0.1 kg, solid: I = 2/5 m r^2) on
/// a cubic lattice, closing on its centre at 1 m/s per m, swirling about z at 1 rad/s and each
/// spinning at up to 10 rad/s about an axis of its own; e = 0.5 and mu = 0.3 on every contact.
/// The normal impulses (resolveSimultaneous) are computed once; each iteration times the
/// friction alone: applyFrictionJointly with spin, the friction and spin effects' cluster step.
void BM_FrictionCluster(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0));
  const double r = 0.05;
  std::vector<core::ClusterBody> bodies;
  std::vector<core::ClusterContact> contacts;
  std::mt19937_64 engine(3);
  std::uniform_real_distribution<double> unit(-1, 1);
  const V centre = V::Constant(r * (side - 1));
  const auto index = [side](int i, int j, int k) {
    return static_cast<std::size_t>((i * side + j) * side + k);
  };
  for (int i = 0; i < side; ++i) {
    for (int j = 0; j < side; ++j) {
      for (int k = 0; k < side; ++k) {
        const V offset = V(2 * r * i, 2 * r * j, 2 * r * k) - centre;
        core::ClusterBody body;
        body.inverse_mass = 10.0;
        body.radius = r;
        body.spin_factor = 2.5;
        body.velocity = -offset + V::UnitZ().cross(offset);
        body.angular_velocity = 10 * V(unit(engine), unit(engine), unit(engine));
        bodies.push_back(body);
        for (int axis = 0; axis < 3; ++axis) {
          int next[3] = {i, j, k};
          if (++next[axis] == side) continue;
          core::ClusterContact contact;
          contact.a = index(i, j, k);
          contact.b = index(next[0], next[1], next[2]);
          contact.normal = V::Unit(axis);
          contact.restitution = 0.5;
          contacts.push_back(contact);
        }
      }
    }
  }
  const std::vector<core::ContactOutcome> normal = core::resolveSimultaneous(bodies, contacts);
  std::vector<core::FrictionContact> frictions;
  for (const core::ContactOutcome& outcome : normal) {
    frictions.push_back(core::FrictionContact{0.3, outcome.impulse});
  }
  std::vector<core::FrictionOutcome> outcomes;
  for (auto _ : state) {
    std::vector<core::ClusterBody> struck = bodies;
    core::applyFrictionJointly<true>(struck, contacts, frictions, outcomes);
    benchmark::DoNotOptimize(struck.data());
  }
  std::size_t sticking = 0;
  for (const core::FrictionOutcome& outcome : outcomes) sticking += outcome.sticking ? 1 : 0;
  state.counters["bodies"] = static_cast<double>(bodies.size());
  state.counters["contacts"] = static_cast<double>(contacts.size());
  state.counters["sticking"] = static_cast<double>(sticking);
}
BENCHMARK(BM_FrictionCluster)
    ->ArgName("side")
    ->DenseRange(3, 6)
    ->Arg(8)
    ->Arg(10)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);

/// Issue 26's piles (bench/dropped_pile.h: r = 0.05 m, 0.1 kg, e = 0.5, dropped from a loose
/// lattice into a closed box): 8, 27, 100 and 1,000 balls with friction and spin (mu = 0.5), and
/// 1,000 frictionless. Arguments: balls, friction (1: mu = 0.5, friction and spin; 0: none).
void droppedPiles(benchmark::internal::Benchmark* bench) {
  bench->ArgNames({"balls", "friction"});
  for (const int balls : {8, 27, 100, 1000}) bench->Args({balls, 1});
  bench->Args({1000, 0});
}

/// The same piles for a peer, at 100 and 300 Hz (a third argument, "rate"); `thousand`: the
/// piles of 1,000 too.
void droppedPilesAtRates(benchmark::internal::Benchmark* bench, bool thousand) {
  bench->ArgNames({"balls", "friction", "rate"});
  for (const int rate : {100, 300}) {
    for (const int balls : {8, 27, 100}) bench->Args({balls, 1, rate});
    if (thousand) {
      bench->Args({1000, 1, rate});
      bench->Args({1000, 0, rate});
    }
  }
}

/// The pile's first simulated second, as every engine here is asked for it.
constexpr double kPileSeconds = 1.0;

/// Ours on a dropped pile, played for its first second at 100 Hz as the scene player plays it,
/// once (the pile is the run): the monitor's CPU per simulated second, its worst update, the
/// played motion's CPU (the scene player's share), the deepest any ball went into another or a
/// wall at the updates' instants, and the bodies the exact work budget handed to stepping.
void BM_DroppedPile(benchmark::State& state) {
  const int balls = static_cast<int>(state.range(0));
  const double mu = state.range(1) != 0 ? 0.5 : 0.0;
  PileFigures figures;
  for (auto _ : state) figures = playPile(droppedPile(balls, mu), kPileSeconds, 100.0);
  state.counters["cpu_per_simulated_s"] = figures.monitor_cpu / kPileSeconds;
  state.counters["worst_update_s"] = figures.worst_update;
  state.counters["source_cpu_per_simulated_s"] = figures.source_cpu / kPileSeconds;
  state.counters["impacts"] = static_cast<double>(figures.impacts);
  state.counters["fallbacks"] = static_cast<double>(figures.fallbacks);
  state.counters["deepest_m"] = figures.deepest;
}
BENCHMARK(BM_DroppedPile)->Apply(droppedPiles)->Iterations(1)->Unit(benchmark::kSecond);

/// What a peer did on a dropped pile: CPU per simulated second, its worst step, the deepest
/// overlap at the steps' ends.
void countPeerPile(benchmark::State& state, double cpu, double worst, double deepest) {
  state.counters["cpu_per_simulated_s"] = cpu / kPileSeconds;
  state.counters["worst_update_s"] = worst;
  state.counters["deepest_m"] = deepest;
}

#ifdef COLLISION_RESPONSE_WITH_BULLET
btScalar bt(double value) { return static_cast<btScalar>(value); }

/// A Bullet world of the scene's balls (spheres of one radius and mass) and plane obstacles,
/// each body's restitution and friction the given ones (Bullet multiplies the two of a pair: pass
/// the square roots of the pair's), every ball simulated (no sleeping: ours watches every ball).
class BulletWorld {
 public:
  BulletWorld(const core::Scene& scene, double radius, double mass, double restitution,
              double friction)
      : world_(&dispatcher_, &broadphase_, &solver_, &configuration_), sphere_(bt(radius)) {
    const V g = scene.effects.gravity ? scene.gravity : V::Zero();
    world_.setGravity(btVector3(bt(g.x()), bt(g.y()), bt(g.z())));
    btVector3 inertia(0, 0, 0);
    sphere_.calculateLocalInertia(bt(mass), inertia);
    for (const core::BodySpec& spec : scene.bodies) {
      btTransform start;
      start.setIdentity();
      start.setOrigin(
          btVector3(bt(spec.position.x()), bt(spec.position.y()), bt(spec.position.z())));
      add(bt(mass), start, &sphere_, inertia, restitution, friction);
      bodies_.back()->setLinearVelocity(
          btVector3(bt(spec.velocity.x()), bt(spec.velocity.y()), bt(spec.velocity.z())));
      bodies_.back()->setActivationState(DISABLE_DEACTIVATION);
    }
    balls_ = bodies_.size();
    for (const core::ObstacleSpec& wall : scene.obstacles) {
      planes_.push_back(std::make_unique<btStaticPlaneShape>(
          btVector3(bt(wall.normal.x()), bt(wall.normal.y()), bt(wall.normal.z())),
          bt(wall.offset)));
      btTransform identity;
      identity.setIdentity();
      add(0, identity, planes_.back().get(), btVector3(0, 0, 0), restitution, friction);
    }
  }
  ~BulletWorld() {
    for (const auto& body : bodies_) world_.removeRigidBody(body.get());
  }
  BulletWorld(const BulletWorld&) = delete;
  BulletWorld& operator=(const BulletWorld&) = delete;

  /// One stepSimulation of `dt` (one sub-step).
  void step(double dt) { world_.stepSimulation(bt(dt), 1, bt(dt)); }
  std::size_t balls() const { return balls_; }
  V position(std::size_t ball) const {
    const btVector3 p = bodies_[ball]->getCenterOfMassPosition();
    return V(p.x(), p.y(), p.z());
  }

 private:
  void add(btScalar mass, const btTransform& start, btCollisionShape* shape,
           const btVector3& inertia, double restitution, double friction) {
    motions_.push_back(std::make_unique<btDefaultMotionState>(start));
    btRigidBody::btRigidBodyConstructionInfo info(mass, motions_.back().get(), shape, inertia);
    info.m_restitution = bt(restitution);
    info.m_friction = bt(friction);
    bodies_.push_back(std::make_unique<btRigidBody>(info));
    world_.addRigidBody(bodies_.back().get());
  }

  btDefaultCollisionConfiguration configuration_;
  btCollisionDispatcher dispatcher_{&configuration_};
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  btDiscreteDynamicsWorld world_;
  btSphereShape sphere_;
  std::vector<std::unique_ptr<btDefaultMotionState>> motions_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<std::unique_ptr<btCollisionShape>> planes_;
  std::size_t balls_ = 0;
};

/// Bullet on the same dropped piles: one stepSimulation of 1 / rate per step for the first
/// second, restitution and friction sqrt(0.5) on every body and wall (e = 0.5, mu = 0.5; mu = 0
/// for the frictionless pile); the CPU per simulated second, the worst step, and the deepest
/// overlap at the steps' ends.
void BM_BulletDroppedPile(benchmark::State& state) {
  const bool friction = state.range(1) != 0;
  const core::Scene scene = droppedPile(static_cast<int>(state.range(0)), friction ? 0.5 : 0.0);
  const double rate = static_cast<double>(state.range(2)), size = -scene.obstacles[1].offset;
  double cpu = 0, worst = 0, deepest = 0;
  for (auto _ : state) {
    BulletWorld world(scene, 0.05, 0.1, std::sqrt(0.5), friction ? std::sqrt(0.5) : 0.0);
    std::vector<V> positions(world.balls());
    for (int k = 0; k < static_cast<int>(std::lround(kPileSeconds * rate)); ++k) {
      const double began = cpuSeconds();
      world.step(1 / rate);
      const double took = cpuSeconds() - began;
      cpu += took;
      worst = std::max(worst, took);
      for (std::size_t i = 0; i < positions.size(); ++i) positions[i] = world.position(i);
      deepest = std::max(deepest, deepestOverlap(positions, 0.05, size));
    }
  }
  countPeerPile(state, cpu, worst, deepest);
}
BENCHMARK(BM_BulletDroppedPile)
    ->Apply([](benchmark::internal::Benchmark* bench) { droppedPilesAtRates(bench, true); })
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

void BM_BulletGasUpdate(benchmark::State& state) {
  const Gas gas = makeGas(static_cast<int>(state.range(0)));
  BulletWorld world(gas.scene, 0.05, 0.1, 1.0, 0.0);
  for (auto _ : state) world.step(0.01);
  state.counters["bodies"] = static_cast<double>(gas.scene.bodies.size());
}
/// Bullet on the same piles, gravity on: one stepSimulation of 0.01 s per update, restitution
/// sqrt(0.5) on every body and wall (Bullet multiplies the two), friction 0, no sleeping (every
/// ball simulated, as ours watches every ball).
void BM_BulletPileUpdate(benchmark::State& state) {
  const core::Scene scene = pileOf(state);
  BulletWorld world(scene, kPileRadius, 0.1, std::sqrt(0.5), 0.0);
  for (auto _ : state) world.step(0.01);
  double drift = 0;
  for (std::size_t i = 0; i < world.balls(); ++i) {
    drift = std::max(drift, (world.position(i) - scene.bodies[i].position).norm());
  }
  state.counters["drift_m"] = drift;
  state.counters["bodies"] = static_cast<double>(world.balls());
}
BENCHMARK(BM_BulletPileUpdate)
    ->Apply([](benchmark::internal::Benchmark* bench) { pileArguments(bench, false); })
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

BENCHMARK(BM_BulletGasUpdate)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
#endif

#ifdef COLLISION_RESPONSE_WITH_MUJOCO
/// MuJoCo on the same dropped piles: every ball a body with a free joint and a sphere geom, the
/// box six planes; friction mu = 0.5 with torsional and rolling friction off (condim 3: sliding
/// friction, the balls turn), 0 and condim 1 for the frictionless pile; MuJoCo's default soft
/// contact (it has no coefficient of restitution: bench/accuracy/mujoco.cpp), its default
/// integrator and Newton solver, one mj_step of 1 / rate per step for the first second. The CPU
/// per simulated second, the worst step, the deepest overlap at the steps' ends, and whether its
/// contacts ever outgrew their room (then some were left out: contacts_full).
std::string mujocoPileXml(const core::Scene& scene, double dt, bool friction) {
  const auto number = [](double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", value);
    return std::string(text);
  };
  const auto triple = [&](const V& v) {
    return number(v.x()) + " " + number(v.y()) + " " + number(v.z());
  };
  // Room for four contacts a ball at once, a row each per dimension of the contact: MuJoCo 2.2
  // preallocates dense njmax x njmax matrices (six a ball of 1,000 outgrew what it allocates).
  const std::size_t contacts = 4 * scene.bodies.size() + 32;
  const std::string room = std::to_string(contacts);
  const std::string contact = friction ? "condim=\"3\" friction=\"0.5 0 0\"" : "condim=\"1\"";
  std::string xml = "<mujoco model=\"pile\">\n  <option timestep=\"" + number(dt) +
                    "\" gravity=\"" + triple(scene.gravity) + "\"/>\n  <size nconmax=\"" + room +
                    "\" njmax=\"" + std::to_string((friction ? 3 : 1) * contacts) +
                    "\"/>\n  <default><geom " + contact + "/></default>\n  <worldbody>\n";
  for (const core::ObstacleSpec& wall : scene.obstacles) {
    const V n = wall.normal.normalized();
    xml += "    <geom type=\"plane\" size=\"0 0 1\" pos=\"" + triple(n * wall.offset) +
           "\" zaxis=\"" + triple(n) + "\"/>\n";
  }
  for (const core::BodySpec& spec : scene.bodies) {
    xml += "    <body pos=\"" + triple(spec.position) +
           "\"><freejoint/><geom type=\"sphere\" size=\"" + number(spec.radius) + "\" mass=\"" +
           number(spec.mass) + "\"/></body>\n";
  }
  return xml + "  </worldbody>\n</mujoco>\n";
}

void BM_MujocoDroppedPile(benchmark::State& state) {
  const bool friction = state.range(1) != 0;
  const core::Scene scene = droppedPile(static_cast<int>(state.range(0)), friction ? 0.5 : 0.0);
  const double rate = static_cast<double>(state.range(2)), size = -scene.obstacles[1].offset;
  const std::string xml = mujocoPileXml(scene, 1 / rate, friction);
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  if (mj_makeEmptyFileVFS(&vfs, "pile.xml", static_cast<int>(xml.size())) != 0) {
    state.SkipWithError("MuJoCo: cannot make the virtual model file");
    return;
  }
  std::memcpy(vfs.filedata[mj_findFileVFS(&vfs, "pile.xml")], xml.data(), xml.size());
  char error[1000] = "";
  mjModel* model = mj_loadXML("pile.xml", &vfs, error, sizeof error);
  mj_deleteVFS(&vfs);
  if (model == nullptr) {
    state.SkipWithError(error);
    return;
  }
  mjData* data = mj_makeData(model);
  double cpu = 0, worst = 0, deepest = 0;
  bool full = false;
  for (auto _ : state) {
    std::vector<V> positions(scene.bodies.size());
    for (int k = 0; k < static_cast<int>(std::lround(kPileSeconds * rate)); ++k) {
      const double began = cpuSeconds();
      mj_step(model, data);
      const double took = cpuSeconds() - began;
      cpu += took;
      worst = std::max(worst, took);
      for (std::size_t i = 0; i < positions.size(); ++i) {
        positions[i] = V(data->qpos[7 * i], data->qpos[7 * i + 1], data->qpos[7 * i + 2]);
      }
      deepest = std::max(deepest, deepestOverlap(positions, 0.05, size));
    }
    full =
        data->warning[mjWARN_CONTACTFULL].number > 0 || data->warning[mjWARN_CNSTRFULL].number > 0;
  }
  countPeerPile(state, cpu, worst, deepest);
  state.counters["contacts_full"] = full ? 1 : 0;
  mj_deleteData(data);
  mj_deleteModel(model);
}
// Not the piles of 1,000: Debian's MuJoCo 2.2 solves them densely (njmax x njmax), and one
// simulated second of the pile of 1,000 with friction had not ended after 15 minutes of CPU.
BENCHMARK(BM_MujocoDroppedPile)
    ->Apply([](benchmark::internal::Benchmark* bench) { droppedPilesAtRates(bench, false); })
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
#endif

// The first contact of a ball against each kind of obstacle (issue 28), beside the plane's and
// the sphere's closed forms: 1,024 throws from 1 to 2 m away aimed within 1.2 times the shape's
// size, straight (first arg 0) or under gravity (1), over a horizon of 1 s (second arg 1000 ms:
// most hit) or of one 100 Hz update (10 ms: the monitor's question, most too far to reach).
// Each shape is about 0.5 m across; the ball's radius is 0.05 m.
/// 1,024 balls (r 0.05 m) thrown from 1 to 2 m away at 2 to 4 m/s, aimed within 0.3 m of the
/// origin; with `gravity`, falling at 9.81 m/s^2. The same throws for every shape and engine.
std::vector<core::BallMotion> shapeThrows(bool gravity) {
  std::mt19937_64 engine(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<core::BallMotion> throws(1024);
  for (core::BallMotion& ball : throws) {
    const V direction = V(unit(engine), unit(engine), unit(engine)).normalized();
    ball.centre = direction * (1.5 + 0.5 * unit(engine));
    const V aim = 0.3 * V(unit(engine), unit(engine), unit(engine));
    ball.velocity = (aim - ball.centre).normalized() * (3 + unit(engine));
    ball.radius = 0.05;
    if (gravity) ball.acceleration = V(0, 0, -9.81);
  }
  return throws;
}

void firstContactOf(benchmark::State& state, const core::Shape& shape) {
  const bool gravity = state.range(0) == 1;
  const double horizon = 1e-3 * static_cast<double>(state.range(1));
  const std::vector<core::BallMotion> throws = shapeThrows(gravity);
  core::PlacedShape placed;
  placed.shape = shape;
  std::size_t i = 0, hits = 0;
  for (auto _ : state) {
    const auto t =
        core::firstContact(throws[i & 1023], placed, V::Zero(), V::Zero(), gravity, horizon);
    hits += t.has_value();
    benchmark::DoNotOptimize(t);
    ++i;
  }
  state.counters["hit_share"] = static_cast<double>(hits) / static_cast<double>(i);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
void BM_FirstContactPlane(benchmark::State& state) {
  firstContactOf(state, core::Plane{V::UnitZ(), 0.25});
}
void BM_FirstContactSphere(benchmark::State& state) {
  firstContactOf(state, core::Sphere{V::Zero(), 0.25});
}
void BM_FirstContactBox(benchmark::State& state) {
  firstContactOf(state, core::Cuboid{V(0.25, 0.2, 0.15)});
}
void BM_FirstContactCylinder(benchmark::State& state) {
  firstContactOf(state, core::Cylinder{0.2, 0.25});
}
void BM_FirstContactCapsule(benchmark::State& state) {
  firstContactOf(state, core::Capsule{0.15, 0.2});
}
void BM_FirstContactMeshCube(benchmark::State& state) {
  // The box above as a mesh of 12 triangles, on the same throws.
  const V h(0.25, 0.2, 0.15);
  std::vector<V> corners;
  for (int i = 0; i < 8; ++i) {
    corners.emplace_back((i & 1 ? 1 : -1) * h.x(), (i & 2 ? 1 : -1) * h.y(),
                         (i & 4 ? 1 : -1) * h.z());
  }
  // Two triangles a face, counter-clockwise seen from outside.
  const std::vector<core::TriangleMesh::Triangle> faces = {
      {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
      {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  firstContactOf(state, core::Mesh{*core::TriangleMesh::build(corners, faces, "cube")});
}

// A ball against a flat floor mesh of n x n squares 0.1 m wide (2 n^2 triangles: n = 7, 71 and
// 708 give 98, 10,082 and 1,002,528), beside the plane it tessellates, on the same 1,024 throws:
// balls of r 0.05 m within 0.1 m of the floor's middle, 0.3 to 1.3 m above it, thrown down at 2
// to 4 m/s up to 8 degrees off the vertical (all land within 0.25 m of the middle, on the
// smallest floor too), straight, over 1 s. The counters: the
// hierarchy's boxes and triangles a query looks at (visited_per_query, about log n), and the
// largest difference of the instant from the plane's closed form (z0 - r) / -v_z, in ulps.
std::shared_ptr<const core::TriangleMesh> floorOf(int n) {
  static std::map<int, std::shared_ptr<const core::TriangleMesh>> floors;
  auto& floor = floors[n];
  if (floor) return floor;
  std::vector<V> vertices;
  vertices.reserve(static_cast<std::size_t>((n + 1) * (n + 1)));
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) vertices.emplace_back(0.1 * (i - 0.5 * n), 0.1 * (j - 0.5 * n), 0);
  }
  std::vector<core::TriangleMesh::Triangle> triangles;
  const auto at = [n](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  floor = *core::TriangleMesh::build(vertices, triangles, "floor");
  return floor;
}

std::vector<core::BallMotion> floorThrows() {
  std::mt19937_64 engine(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<core::BallMotion> throws(1024);
  for (core::BallMotion& ball : throws) {
    ball.radius = 0.05;
    ball.centre = V(0.1 * unit(engine), 0.1 * unit(engine), 0.8 + 0.5 * unit(engine));
    const V direction = V(0.1 * unit(engine), 0.1 * unit(engine), -1).normalized();
    ball.velocity = direction * (3 + unit(engine));
  }
  return throws;
}

void floorContact(benchmark::State& state, const core::Shape& shape) {
  const std::vector<core::BallMotion> throws = floorThrows();
  core::PlacedShape placed;
  placed.shape = shape;
  std::size_t i = 0;
  core::TriangleMesh::visitedCount() = 0;
  for (auto _ : state) {
    const auto t = core::firstContact(throws[i & 1023], placed, V::Zero(), V::Zero(), false, 1.0);
    benchmark::DoNotOptimize(t);
    ++i;
  }
  state.counters["visited_per_query"] =
      static_cast<double>(core::TriangleMesh::visitedCount()) / static_cast<double>(i);
  double worst = 0;
  int missed = 0;
  for (const core::BallMotion& ball : throws) {
    const auto t = core::firstContact(ball, placed, V::Zero(), V::Zero(), false, 1.0);
    if (!t) {
      ++missed;
      continue;
    }
    const long double exact =
        (static_cast<long double>(ball.centre.z()) - ball.radius) / -ball.velocity.z();
    const double ulp = std::nextafter(static_cast<double>(exact), 2.0) - static_cast<double>(exact);
    worst = std::max(worst, static_cast<double>(std::abs(*t - exact)) / ulp);
  }
  state.counters["toi_error_max_ulps"] = worst;
  state.counters["missed"] = missed;
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
void BM_FirstContactFloorPlane(benchmark::State& state) {
  floorContact(state, core::Plane{V::UnitZ(), 0.0});
}
void BM_FirstContactFloorMesh(benchmark::State& state) {
  const auto floor = floorOf(static_cast<int>(state.range(0)));
  state.counters["triangles"] = static_cast<double>(floor->triangles().size());
  floorContact(state, core::Mesh{floor});
}
// The box turning at 10 rad/s about z (a paddle's swing): conservative advancement on the gap,
// no polynomial (the same throws, straight).
void BM_FirstContactTurningBox(benchmark::State& state) {
  const std::vector<core::BallMotion> throws = shapeThrows(false);
  const double horizon = 1e-3 * static_cast<double>(state.range(0));
  core::PlacedShape placed;
  placed.shape = core::Cuboid{V(0.25, 0.2, 0.15)};
  placed.pose.angular_velocity = V(0, 0, 10);
  std::size_t i = 0, hits = 0;
  for (auto _ : state) {
    const auto t =
        core::firstContact(throws[i & 1023], placed, V::Zero(), V::Zero(), false, horizon);
    hits += t.has_value();
    benchmark::DoNotOptimize(t);
    ++i;
  }
  state.counters["hit_share"] = static_cast<double>(hits) / static_cast<double>(i);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_FirstContactMeshCube)->ArgsProduct({{0, 1}, {1000, 10}});
BENCHMARK(BM_FirstContactTurningBox)->Arg(1000)->Arg(10);
BENCHMARK(BM_FirstContactFloorPlane);
BENCHMARK(BM_FirstContactFloorMesh)->Arg(7)->Arg(71)->Arg(708);

#ifdef COLLISION_RESPONSE_WITH_BULLET
// Bullet's continuous collision of a sphere against a box (btContinuousConvexCollision: GJK-based
// conservative advancement; its sphere is a point with a margin of its radius) on the same
// straight throws over 1 s, beside ours: ns a query, and each hit's instant against ours (the
// exact one to a few ulps, FiniteShapes tests): the largest and the mean difference, and the
// throws where one finds a hit the other does not.
void BM_BulletFirstContactBox(benchmark::State& state) {
  const std::vector<core::BallMotion> throws = shapeThrows(false);
  const V half(0.25, 0.2, 0.15);
  btSphereShape sphere(bt(0.05));
  btBoxShape box(btVector3(bt(half.x()), bt(half.y()), bt(half.z())));
  box.setMargin(0);
  const auto bullet = [&](const core::BallMotion& ball) -> std::optional<double> {
    btVoronoiSimplexSolver simplex;
    btGjkEpaPenetrationDepthSolver depth;
    btContinuousConvexCollision cast(&sphere, &box, &simplex, &depth);
    btTransform from, to, still;
    from.setIdentity();
    to.setIdentity();
    still.setIdentity();
    from.setOrigin(btVector3(bt(ball.centre.x()), bt(ball.centre.y()), bt(ball.centre.z())));
    const V end = ball.centre + ball.velocity;
    to.setOrigin(btVector3(bt(end.x()), bt(end.y()), bt(end.z())));
    btConvexCast::CastResult result;
    if (!cast.calcTimeOfImpact(from, to, still, still, result)) return std::nullopt;
    return static_cast<double>(result.m_fraction);
  };
  std::size_t i = 0;
  for (auto _ : state) {
    const auto t = bullet(throws[i & 1023]);
    benchmark::DoNotOptimize(t);
    ++i;
  }
  core::PlacedShape placed;
  placed.shape = core::Cuboid{half};
  double largest = 0, sum = 0;
  int both = 0, disagree = 0;
  for (const core::BallMotion& ball : throws) {
    const auto ours = core::firstContact(ball, placed, V::Zero(), V::Zero(), false, 1.0);
    const auto theirs = bullet(ball);
    if (ours.has_value() != theirs.has_value()) {
      ++disagree;
      continue;
    }
    if (!ours) continue;
    ++both;
    largest = std::max(largest, std::abs(*theirs - *ours));
    sum += std::abs(*theirs - *ours);
  }
  state.counters["toi_error_max_s"] = largest;
  state.counters["toi_error_mean_s"] = both > 0 ? sum / both : 0.0;
  state.counters["hit_or_miss_differs"] = disagree;
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_BulletFirstContactBox);

// Bullet's sweep of a sphere against the same floor meshes (btBvhTriangleMeshShape under its
// quantized hierarchy, btCollisionWorld::convexSweepTest, its continuous query against meshes),
// on the same throws: ns a query, and its instants against the plane's closed form.
void BM_BulletFirstContactFloorMesh(benchmark::State& state) {
  const auto floor = floorOf(static_cast<int>(state.range(0)));
  btTriangleMesh triangles;
  const auto point = [&](std::uint32_t v) {
    const V& p = floor->vertices()[v];
    return btVector3(bt(p.x()), bt(p.y()), bt(p.z()));
  };
  for (const auto& t : floor->triangles())
    triangles.addTriangle(point(t[0]), point(t[1]), point(t[2]));
  btBvhTriangleMeshShape mesh(&triangles, true);
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btCollisionWorld world(&dispatcher, &broadphase, &configuration);
  btCollisionObject object;
  object.setCollisionShape(&mesh);
  world.addCollisionObject(&object);
  world.updateAabbs();
  btSphereShape sphere(bt(0.05));
  const std::vector<core::BallMotion> throws = floorThrows();
  const auto bullet = [&](const core::BallMotion& ball) -> std::optional<double> {
    btTransform from, to;
    from.setIdentity();
    to.setIdentity();
    from.setOrigin(btVector3(bt(ball.centre.x()), bt(ball.centre.y()), bt(ball.centre.z())));
    const V end = ball.centre + ball.velocity;
    to.setOrigin(btVector3(bt(end.x()), bt(end.y()), bt(end.z())));
    btCollisionWorld::ClosestConvexResultCallback hit(from.getOrigin(), to.getOrigin());
    world.convexSweepTest(&sphere, from, to, hit);
    if (!hit.hasHit()) return std::nullopt;
    return static_cast<double>(hit.m_closestHitFraction);
  };
  std::size_t i = 0;
  for (auto _ : state) {
    const auto t = bullet(throws[i & 1023]);
    benchmark::DoNotOptimize(t);
    ++i;
  }
  double largest = 0, sum = 0;
  int hits = 0, missed = 0;
  for (const core::BallMotion& ball : throws) {
    const auto t = bullet(ball);
    if (!t) {
      ++missed;
      continue;
    }
    const double exact = (ball.centre.z() - ball.radius) / -ball.velocity.z();
    largest = std::max(largest, std::abs(*t - exact));
    sum += std::abs(*t - exact);
    ++hits;
  }
  state.counters["triangles"] = static_cast<double>(floor->triangles().size());
  state.counters["toi_error_max_s"] = largest;
  state.counters["toi_error_mean_s"] = hits > 0 ? sum / hits : 0.0;
  state.counters["missed"] = missed;
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_BulletFirstContactFloorMesh)->Arg(7)->Arg(71)->Arg(708);
#endif

BENCHMARK(BM_FirstContactPlane)->ArgsProduct({{0, 1}, {1000, 10}});
BENCHMARK(BM_FirstContactSphere)->ArgsProduct({{0, 1}, {1000, 10}});
BENCHMARK(BM_FirstContactBox)->ArgsProduct({{0, 1}, {1000, 10}});
BENCHMARK(BM_FirstContactCylinder)->ArgsProduct({{0, 1}, {1000, 10}});
BENCHMARK(BM_FirstContactCapsule)->ArgsProduct({{0, 1}, {1000, 10}});

BENCHMARK(BM_PairResponse);
BENCHMARK(BM_GasUpdate)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

}  // namespace
}  // namespace collision_response::bench

BENCHMARK_MAIN();
