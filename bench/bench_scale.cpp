// Scale: pair responses per second, and one state update of a gas of 1k, 10k and 100k spheres
// in a box (every body's state each update, as a source that applies the responses sends
// them), with Bullet's btDbvtBroadphase and solver on the same gas in the same run.
// scripts/performance.sh runs it and writes doc/performance.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "box_walls.h"
#include "collision_response/core/impact.h"
#include "collision_response/core/monitor.h"
#ifdef COLLISION_RESPONSE_WITH_BULLET
#include <btBulletDynamicsCommon.h>
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

#ifdef COLLISION_RESPONSE_WITH_BULLET
btScalar bt(double value) { return static_cast<btScalar>(value); }

void BM_BulletGasUpdate(benchmark::State& state) {
  const Gas gas = makeGas(static_cast<int>(state.range(0)));
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration);
  world.setGravity(btVector3(0, 0, 0));
  btSphereShape sphere(bt(0.05));
  btVector3 inertia(0, 0, 0);
  sphere.calculateLocalInertia(bt(0.1), inertia);
  std::vector<std::unique_ptr<btDefaultMotionState>> motions;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<std::unique_ptr<btCollisionShape>> planes;
  for (const core::BodySpec& spec : gas.scene.bodies) {
    btTransform start;
    start.setIdentity();
    start.setOrigin(btVector3(bt(spec.position.x()), bt(spec.position.y()), bt(spec.position.z())));
    motions.push_back(std::make_unique<btDefaultMotionState>(start));
    btRigidBody::btRigidBodyConstructionInfo info(bt(0.1), motions.back().get(), &sphere, inertia);
    info.m_restitution = 1;
    info.m_friction = 0;
    bodies.push_back(std::make_unique<btRigidBody>(info));
    bodies.back()->setLinearVelocity(
        btVector3(bt(spec.velocity.x()), bt(spec.velocity.y()), bt(spec.velocity.z())));
    bodies.back()->setActivationState(DISABLE_DEACTIVATION);
    world.addRigidBody(bodies.back().get());
  }
  for (const core::ObstacleSpec& wall : gas.scene.obstacles) {
    planes.push_back(std::make_unique<btStaticPlaneShape>(
        btVector3(bt(wall.normal.x()), bt(wall.normal.y()), bt(wall.normal.z())), bt(wall.offset)));
    btTransform identity;
    identity.setIdentity();
    motions.push_back(std::make_unique<btDefaultMotionState>(identity));
    btRigidBody::btRigidBodyConstructionInfo info(0, motions.back().get(), planes.back().get());
    info.m_restitution = 1;
    bodies.push_back(std::make_unique<btRigidBody>(info));
    world.addRigidBody(bodies.back().get());
  }
  for (auto _ : state) world.stepSimulation(bt(0.01), 1, bt(0.01));
  state.counters["bodies"] = static_cast<double>(gas.scene.bodies.size());
  for (const auto& body : bodies) world.removeRigidBody(body.get());
}
BENCHMARK(BM_BulletGasUpdate)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
#endif

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
