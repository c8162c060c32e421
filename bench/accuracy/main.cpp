// The accuracy-versus-cost benchmark: every scene at every setting (ours: continuous and
// discrete detection, state rates 10..1000 Hz, effects on and off; Bullet with its defaults and
// its recommended bouncing settings; ODE), errors against exact answers written to a JSON file,
// CPU time measured by Google Benchmark. scripts/accuracy.sh runs it and makes doc/accuracy.md
// and doc/accuracy.png.
//   accuracy_benchmark <errors.json> [Google Benchmark flags]
#include <benchmark/benchmark.h>

#include <cstdio>
#include <limits>
#include <map>
#include <random>

#include "collision_response/core/impact.h"
#include "collision_response/core/time_of_impact.h"
#include "harness.h"

namespace collision_response::bench {
namespace {

struct Setting {
  std::string engine;   ///< ours, bullet, ode
  std::string variant;  ///< continuous, discrete, default, bouncing, ...
  std::string effects;  ///< none, or what is turned on
  Engine play;
  double rate;
};

std::vector<Setting> settingsFor(const BenchScene& bench) {
  std::vector<Setting> settings;
  for (const double rate : {10.0, 30.0, 60.0, 100.0, 300.0, 1000.0}) {
    settings.push_back(
        {"ours", "continuous", "none", oursEngine(core::Detection::kContinuous), rate});
    settings.push_back({"ours", "discrete", "none", oursEngine(core::Detection::kDiscrete), rate});
#ifdef COLLISION_RESPONSE_WITH_BULLET
    settings.push_back({"bullet", "default", "none", bulletEngine(false), rate});
    settings.push_back({"bullet", "bouncing", "none", bulletEngine(true), rate});
#endif
#ifdef COLLISION_RESPONSE_WITH_ODE
    settings.push_back({"ode", "default", "none", odeEngine(), rate});
#endif
  }
  // Effects on, against the same scene with them off (100 Hz, continuous): friction and spin
  // on the break, gravity on the gas.
  if (bench.name == "billiards_break" || bench.name == "sphere_gas") {
    const std::string effects = bench.name == "billiards_break" ? "friction, spin" : "gravity";
    settings.push_back(
        {"ours", "continuous", effects, oursEngine(core::Detection::kContinuous), 100.0});
  }
  return settings;
}

core::Scene withEffects(const BenchScene& bench, const std::string& effects) {
  core::Scene scene = bench.scene;
  if (effects.find("friction") != std::string::npos) scene.effects.friction = true;
  if (effects.find("spin") != std::string::npos) scene.effects.spin = true;
  if (effects.find("gravity") != std::string::npos) scene.effects.gravity = true;
  return scene;
}

std::string number(double value) {
  if (std::isnan(value)) return "null";
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

// The float and double kernels against long double, on random impacts and times of impact.
void kernelErrors(std::FILE* out) {
  std::mt19937_64 engine(3);
  std::uniform_real_distribution<double> unit(-1, 1);
  double impact_error[2] = {0, 0}, toi_error[2] = {0, 0};
  for (int i = 0; i < 100000; ++i) {
    const V va(unit(engine), unit(engine), unit(engine)),
        vb(unit(engine), unit(engine), unit(engine));
    const V n = V(unit(engine), unit(engine), unit(engine)).normalized();
    const double wa = std::exp(3 * unit(engine)), wb = std::exp(3 * unit(engine)),
                 e = 0.5 * (1 + unit(engine));
    using L = Eigen::Matrix<long double, 3, 1>;
    const auto exact = core::resolveImpact<long double>(
        wa, va.cast<long double>(), wb, vb.cast<long double>(), n.cast<long double>(), e);
    const auto d = core::resolveImpact<double>(wa, va, wb, vb, n, e);
    const auto f =
        core::resolveImpact<float>(static_cast<float>(wa), va.cast<float>(), static_cast<float>(wb),
                                   vb.cast<float>(), n.cast<float>(), static_cast<float>(e));
    const L reference = exact.velocity_a;
    impact_error[0] =
        std::max(impact_error[0], double((d.velocity_a.cast<long double>() - reference).norm()));
    impact_error[1] =
        std::max(impact_error[1], double((f.velocity_a.cast<long double>() - reference).norm()));
    const V s(1 + unit(engine), unit(engine), unit(engine));
    const V v(-1 - unit(engine), 0.1 * unit(engine), 0.1 * unit(engine));
    const auto te = core::timeOfImpactSpheres<long double>(s.cast<long double>(),
                                                           v.cast<long double>(), 0.5L, 100.0L);
    const auto td = core::timeOfImpactSpheres<double>(s, v, 0.5, 100.0);
    const auto tf =
        core::timeOfImpactSpheres<float>(s.cast<float>(), v.cast<float>(), 0.5f, 100.0f);
    if (te && td && tf) {
      toi_error[0] = std::max(toi_error[0], double(std::abs(*td - *te)));
      toi_error[1] = std::max(toi_error[1], double(std::abs(*tf - *te)));
    }
  }
  std::fprintf(out,
               "  \"kernels\": {\"impact_velocity_error\": {\"double\": %s, \"float\": %s}, "
               "\"time_of_impact_error\": {\"double\": %s, \"float\": %s}},\n",
               number(impact_error[0]).c_str(), number(impact_error[1]).c_str(),
               number(toi_error[0]).c_str(), number(toi_error[1]).c_str());
}

template <typename Scalar>
void BM_ImpactKernel(benchmark::State& state) {
  using Vec = Eigen::Matrix<Scalar, 3, 1>;
  const Vec va(Scalar(1), Scalar(0.2), Scalar(-0.3)), vb(Scalar(-0.5), Scalar(0.1), Scalar(0.4));
  const Vec n = Vec(Scalar(0.6), Scalar(0.8), Scalar(0));
  for (auto _ : state) {
    auto r = core::resolveImpact<Scalar>(Scalar(2), va, Scalar(3), vb, n, Scalar(0.7));
    benchmark::DoNotOptimize(r);
  }
}
template <typename Scalar>
void BM_TimeOfImpactKernel(benchmark::State& state) {
  using Vec = Eigen::Matrix<Scalar, 3, 1>;
  const Vec s(Scalar(1.5), Scalar(0.2), Scalar(-0.1)), v(Scalar(-2), Scalar(0.05), Scalar(0));
  for (auto _ : state) {
    auto t = core::timeOfImpactSpheres<Scalar>(s, v, Scalar(0.5), Scalar(10));
    benchmark::DoNotOptimize(t);
  }
}

}  // namespace
}  // namespace collision_response::bench

int main(int argc, char** argv) {
  using namespace collision_response::bench;
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s <errors.json> [benchmark flags]\n", argv[0]);
    return 2;
  }
  std::FILE* out = std::fopen(argv[1], "w");
  std::fprintf(out, "{\n");
  kernelErrors(out);
  std::fprintf(out, "  \"runs\": [\n");
  const std::vector<BenchScene> scenes = {dropTestScene(), cradleScene(), breakScene(),
                                          tunnellingScene(), gasScene()};
  bool first_row = true;
  for (const BenchScene& bench : scenes) {
    // The break's exact answer: our continuous detection, whose instants do not depend on the
    // rate (the same answer at 10 Hz and 1 kHz to rounding), with the setting's effects.
    std::map<std::string, Run> references;
    for (const Setting& setting : settingsFor(bench)) {
      const collision_response::core::Scene scene = withEffects(bench, setting.effects);
      if (references.count(setting.effects) == 0) {
        references[setting.effects] = oursEngine(collision_response::core::Detection::kContinuous)(
            scene, 1000.0, bench.duration);
      }
      const Run run = setting.play(scene, setting.rate, bench.duration);
      const Errors e = measure(bench, scene, run, &references[setting.effects]);
      const std::string name = bench.name + "/" + setting.engine + "/" + setting.variant + "/" +
                               setting.effects + "/" + number(setting.rate);
      std::fprintf(
          out,
          "%s    {\"name\": \"%s\", \"scene\": \"%s\", \"engine\": \"%s\", \"variant\": \"%s\", "
          "\"effects\": \"%s\", \"rate\": %s, \"updates\": %zu, \"impacts\": %zu, "
          "\"instant\": %s, \"velocity\": %s, \"restitution\": %s, \"apex\": %s, "
          "\"missed\": %s, \"momentum_drift\": %s, \"energy_drift\": %s}",
          first_row ? "" : ",\n", name.c_str(), bench.name.c_str(), setting.engine.c_str(),
          setting.variant.c_str(), setting.effects.c_str(), number(setting.rate).c_str(),
          run.times.size() - 1, run.impacts, number(e.instant).c_str(), number(e.velocity).c_str(),
          number(e.restitution).c_str(), number(e.apex).c_str(), number(e.missed).c_str(),
          number(e.momentum_drift).c_str(), number(e.energy_drift).c_str());
      first_row = false;
      const Engine play = setting.play;
      const double rate = setting.rate, duration = bench.duration;
      benchmark::RegisterBenchmark(name.c_str(),
                                   [play, scene, rate, duration](benchmark::State& state) {
                                     for (auto _ : state)
                                       benchmark::DoNotOptimize(play(scene, rate, duration));
                                   })
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.2);
    }
  }
  std::fprintf(out, "\n  ]\n}\n");
  std::fclose(out);
  benchmark::RegisterBenchmark("kernel/impact/double", &BM_ImpactKernel<double>);
  benchmark::RegisterBenchmark("kernel/impact/float", &BM_ImpactKernel<float>);
  benchmark::RegisterBenchmark("kernel/time_of_impact/double", &BM_TimeOfImpactKernel<double>);
  benchmark::RegisterBenchmark("kernel/time_of_impact/float", &BM_TimeOfImpactKernel<float>);
  int bench_argc = argc - 1;
  benchmark::Initialize(&bench_argc, argv + 1);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
