// What a tumbling body's exact free rotation costs per evaluation (geometry/free_rotation.h):
// its construction, its body-frame angular velocity and its orientation at a time, for an
// asymmetric body (Jacobi elliptic functions, the angle about L by Carlson's R_F and R_J), near
// the separatrix (a long period) and for a cylinder (closed form); and the orientation 1,000 s
// on (many whole periods: the same cost). Google Benchmark; built on demand: cmake --build
// .ws/build --target bench_free_rotation.
#include <benchmark/benchmark.h>

#include "geometry/free_rotation.h"

namespace collision_response::core {
namespace {

const Eigen::Quaterniond kTurned = Eigen::Quaterniond(0.48, 0.64, 0.36, 0.48).normalized();

FreeRotation body(int which) {
  switch (which) {
    case 0:
      return FreeRotation::create({2.0, 3.0, 4.0}, kTurned, {0.3, -0.5, 2.0}).value();
    case 1:
      return FreeRotation::create({3.0, 5.0, 6.0}, Eigen::Quaterniond::Identity(),
                                  {1.0, 0.5, 1.000000001})
          .value();
    default:
      return FreeRotation::create({1.0, 1.0, 1.5}, kTurned, {0.3, -2.0, 0.5}).value();
  }
}

void construct(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(body(which));
}

void angularVelocity(benchmark::State& state) {
  const FreeRotation r = body(static_cast<int>(state.range(0)));
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(r.bodyAngularVelocity(t));
    t += 0.001;
  }
}

void orientation(benchmark::State& state) {
  const FreeRotation r = body(static_cast<int>(state.range(0)));
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(r.orientation(t));
    t += 0.001;
  }
}

void orientationLate(benchmark::State& state) {
  const FreeRotation r = body(static_cast<int>(state.range(0)));
  double t = 1000.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(r.orientation(t));
    t += 0.001;
  }
}

// 0: asymmetric, 1: near the separatrix, 2: axisymmetric.
BENCHMARK(construct)->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(angularVelocity)->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(orientation)->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(orientationLate)->Arg(0)->Arg(1);

}  // namespace
}  // namespace collision_response::core

BENCHMARK_MAIN();
