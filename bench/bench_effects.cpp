// What each effect costs in CPU time: per impact and per state update, on versus off
// (Google Benchmark). scripts/bench_effects.sh runs it and writes doc/effects.md.
#include <benchmark/benchmark.h>

#include "effects_workload.h"

namespace collision_response::bench {
namespace {

void impact(benchmark::State& state, const std::vector<std::string>& effects) {
  const core::CollisionRequest request = ballOnFloor(effects);
  const core::MaterialTable materials = core::MaterialTable::seed();
  for (auto _ : state) {
    auto outcome = core::computeCollision(request, materials);
    benchmark::DoNotOptimize(outcome);
  }
}

void update(benchmark::State& state, bool gravity, bool friction, bool spin, bool drag = false,
            bool magnus = false) {
  BoxRun run(gravity, friction, spin, drag, magnus);
  std::size_t impacts = 0;
  for (auto _ : state) impacts += run.update();
  state.counters["impacts/update"] =
      static_cast<double>(impacts) / static_cast<double>(state.iterations());
}

// The updates of one run: its first 2 s, as the instruction count's workload
// (effects_instructions.cpp). The motion changes from update to update, so the count is fixed
// rather than chosen by the library (with every effect on, later updates cost more: the balls
// gather and roll in contact, see doc/effects.md).
constexpr int kUpdates = 200;

void BM_ImpactNone(benchmark::State& s) { impact(s, {}); }
void BM_ImpactFriction(benchmark::State& s) { impact(s, {"friction"}); }
void BM_ImpactFrictionSpin(benchmark::State& s) { impact(s, {"friction", "spin"}); }
void BM_UpdateNone(benchmark::State& s) { update(s, false, false, false); }
void BM_UpdateGravity(benchmark::State& s) { update(s, true, false, false); }
void BM_UpdateFriction(benchmark::State& s) { update(s, false, true, false); }
void BM_UpdateFrictionSpin(benchmark::State& s) { update(s, false, true, true); }
void BM_UpdateAll(benchmark::State& s) { update(s, true, true, true); }
void BM_UpdateGravityDrag(benchmark::State& s) { update(s, true, false, false, true); }
void BM_UpdateGravityAir(benchmark::State& s) { update(s, true, false, true, true, true); }

BENCHMARK(BM_ImpactNone);
BENCHMARK(BM_ImpactFriction);
BENCHMARK(BM_ImpactFrictionSpin);
BENCHMARK(BM_UpdateNone)->Unit(benchmark::kMicrosecond)->Iterations(kUpdates);
BENCHMARK(BM_UpdateGravity)->Unit(benchmark::kMicrosecond)->Iterations(kUpdates);
BENCHMARK(BM_UpdateFriction)->Unit(benchmark::kMicrosecond)->Iterations(kUpdates);
BENCHMARK(BM_UpdateFrictionSpin)->Unit(benchmark::kMicrosecond)->Iterations(kUpdates);
BENCHMARK(BM_UpdateAll)->Unit(benchmark::kMicrosecond)->Iterations(kUpdates);
BENCHMARK(BM_UpdateGravityDrag)->Unit(benchmark::kMicrosecond)->Iterations(kUpdates);
BENCHMARK(BM_UpdateGravityAir)->Unit(benchmark::kMicrosecond)->Iterations(kUpdates);

}  // namespace
}  // namespace collision_response::bench

BENCHMARK_MAIN();
