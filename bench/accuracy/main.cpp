// The accuracy-versus-cost benchmark: every scene at every setting (ours: continuous and
// discrete detection, effects on and off, and every body stepped on the scenes that list
// stepped rates; Bullet with its defaults and its recommended bouncing settings; ODE; MuJoCo
// with its default soft contact and with restitution through solref; DART; Box2D on the planar
// scenes), at the scene's state rates; errors against the references of
// reference/references.txt written to a JSON file, CPU time measured by Google Benchmark.
// scripts/accuracy.sh runs it and makes doc/accuracy.md and doc/accuracy.png.
//   accuracy_benchmark --export-scenes <scenes.txt>
//   accuracy_benchmark <references.txt> <errors.json> [Google Benchmark flags]
// --benchmark_filter=<regex> also limits the runs whose errors are measured; --errors_only
// measures the short scenes' errors and times nothing (the long runs are measured as they are
// timed, so not at all).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <regex>

#include "collision_response/core/impact.h"
#include "collision_response/core/time_of_impact.h"
#include "harness.h"

namespace collision_response::bench {
namespace {

/// An engine and its settings, as the report names them.
struct EngineSetting {
  std::string engine;   ///< ours, bullet, ode, mujoco, dart, box2d
  std::string variant;  ///< continuous, discrete, default, bouncing, restitution, ...
  Engine play;
};

/// Every engine setting, in the order of the report's tables.
std::vector<EngineSetting> engineSettings() {
  std::vector<EngineSetting> settings = {
      {"ours", "continuous", oursEngine(core::Detection::kContinuous)},
      {"ours", "discrete", oursEngine(core::Detection::kDiscrete)},
      // Every body under gravity in a stepped cluster (stepped_cluster_min_bodies = 1): what the
      // stepped model costs in accuracy, at the rates of BenchScene::stepped_rates.
      {"ours", "stepped", oursEngine(core::Detection::kContinuous, 1)},
  };
#ifdef COLLISION_RESPONSE_WITH_BULLET
  settings.push_back({"bullet", "default", bulletEngine(false)});
  settings.push_back({"bullet", "bouncing", bulletEngine(true)});
#endif
#ifdef COLLISION_RESPONSE_WITH_ODE
  settings.push_back({"ode", "default", odeEngine()});
#endif
#ifdef COLLISION_RESPONSE_WITH_MUJOCO
  settings.push_back({"mujoco", "default", mujocoEngine(false)});
  settings.push_back({"mujoco", "restitution", mujocoEngine(true)});
#endif
#ifdef COLLISION_RESPONSE_WITH_DART
  settings.push_back({"dart", "default", dartEngine()});
#endif
#ifdef COLLISION_RESPONSE_WITH_BOX2D
  settings.push_back({"box2d", "default", box2dEngine()});
#endif
  return settings;
}

/// One row of the report: a scene (with its effects) played by an engine setting at a rate.
struct Row {
  std::string name, scene, engine, variant, effects;
  double rate = 0;
  double tolerance = 0;  ///< the integration tolerance set for the run; 0: the scene's own
  std::size_t updates = 0;
  bool truncated = false;
  std::string unsupported;
  Metrics metrics;
};

std::string number(double value) {
  if (std::isnan(value)) return "null";
  if (std::isinf(value)) return value > 0 ? "1e999" : "-1e999";
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

std::string json(const Row& row) {
  std::string text = "{\"name\": \"" + row.name + "\", \"scene\": \"" + row.scene +
                     "\", \"engine\": \"" + row.engine + "\", \"variant\": \"" + row.variant +
                     "\", \"effects\": \"" + row.effects + "\", \"rate\": " + number(row.rate) +
                     ", \"tolerance\": " + (row.tolerance > 0 ? number(row.tolerance) : "null") +
                     ", \"updates\": " + std::to_string(row.updates) +
                     ", \"truncated\": " + (row.truncated ? "true" : "false") +
                     ", \"unsupported\": \"" + row.unsupported + "\", \"metrics\": {";
  bool first = true;
  for (const auto& [key, value] : row.metrics) {
    text += (first ? "\"" : ", \"") + key + "\": " + number(value);
    first = false;
  }
  return text + "}}";
}

/// A scene (with its effects) at one rate, played by one engine setting.
struct Case {
  const EngineSetting* setting;
  std::string effects;
  double rate;
  double tolerance = 0;  ///< Scene::contact_integration_tolerance; 0: the scene's own
};

/// Every engine setting (of the scene's engines) at every rate of the scene (ours, stepped: at
/// its stepped rates), then ours with the scene's extra effects, then ours at each integration
/// tolerance of the scene.
std::vector<Case> casesOf(const BenchScene& bench, const std::vector<EngineSetting>& settings) {
  std::vector<Case> cases;
  for (const EngineSetting& setting : settings) {
    const bool plays = bench.engines.empty() ||
                       std::find(bench.engines.begin(), bench.engines.end(), setting.engine) !=
                           bench.engines.end();
    if (!plays) continue;
    const bool stepped = setting.engine == "ours" && setting.variant == "stepped";
    for (const double rate : stepped ? bench.stepped_rates : bench.rates) {
      cases.push_back({&setting, "none", rate});
    }
  }
  for (const std::string& effects : bench.effect_variants) {
    cases.push_back({&settings.front(), effects, 100.0});  // ours, continuous
  }
  std::vector<std::string> all_effects = {"none"};
  all_effects.insert(all_effects.end(), bench.effect_variants.begin(), bench.effect_variants.end());
  for (const std::string& effects : all_effects) {
    for (const double tolerance : bench.integration_tolerances) {
      cases.push_back({&settings.front(), effects, 100.0, tolerance});
    }
  }
  return cases;
}

/// The scene a case plays: the effects turned on, the integration tolerance set.
core::Scene sceneOf(const BenchScene& bench, const Case& c) {
  core::Scene scene = withEffects(bench, c.effects);
  if (c.tolerance > 0) scene.contact_integration_tolerance = c.tolerance;
  return scene;
}

/// A short scene: played once here and measured, then timed by Google Benchmark over repeated
/// runs.
void addShortRun(const BenchScene& bench, const Case& c, Row& row, const References& references) {
  const core::Scene scene = sceneOf(bench, c);
  const Play play{c.rate, bench.duration, bench.record_all, bench.reference != "lasting",
                  bench.obstacle_velocities};
  const Engine engine = c.setting->play;
  const Run run = engine(scene, play);
  row.unsupported = run.unsupported;
  if (!run.unsupported.empty()) return;
  row.updates = run.updates();
  row.truncated = run.truncated;
  row.metrics = measure(bench, c.effects, run, references);
  benchmark::RegisterBenchmark(row.name.c_str(),
                               [engine, scene, play](benchmark::State& state) {
                                 for (auto _ : state) benchmark::DoNotOptimize(engine(scene, play));
                               })
      ->Unit(benchmark::kMillisecond)
      ->MinTime(0.1);
}

/// A long run: played once, inside its benchmark (one iteration, which is its CPU time), and
/// measured there, so that it is not played twice.
void addLongRun(const BenchScene& bench, const Case& c, std::shared_ptr<std::vector<Row>> rows,
                std::size_t index, const References& references) {
  const core::Scene scene = sceneOf(bench, c);
  const Play play{c.rate, bench.duration, bench.record_all, bench.reference != "lasting",
                  bench.obstacle_velocities};
  const Engine engine = c.setting->play;
  // A run of no time: does the engine play this scene at all (Box2D: planar ones only)?
  const Run probe = engine(scene, Play{c.rate, 0.0, false, true, bench.obstacle_velocities});
  if (!probe.unsupported.empty()) {
    (*rows)[index].unsupported = probe.unsupported;
    return;
  }
  const std::string effects = c.effects;
  benchmark::RegisterBenchmark(
      (*rows)[index].name.c_str(),
      [engine, scene, play, bench, effects, rows, index, &references](benchmark::State& state) {
        for (auto _ : state) {
          const Run run = engine(scene, play);
          state.PauseTiming();
          Row& row = (*rows)[index];
          row.updates = run.updates();
          row.truncated = run.truncated;
          row.metrics = measure(bench, effects, run, references);
          state.ResumeTiming();
        }
      })
      ->Unit(benchmark::kMillisecond)
      ->Iterations(1);
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
  if (argc >= 3 && std::strcmp(argv[1], "--export-scenes") == 0) {
    exportScenes(benchScenes(), argv[2]);
    return 0;
  }
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: %s --export-scenes <scenes.txt>\n"
                 "       %s <references.txt> <errors.json> [benchmark flags]\n",
                 argv[0], argv[0]);
    return 2;
  }
  const References references = References::read(argv[1]);
  std::regex filter(".*");
  bool errors_only = false;
  for (int i = 3; i < argc; ++i) {
    const std::string flag = argv[i], prefix = "--benchmark_filter=";
    if (flag.rfind(prefix, 0) == 0) filter = std::regex(flag.substr(prefix.size()));
    if (flag == "--errors_only") errors_only = true;
  }
  std::FILE* out = std::fopen(argv[2], "w");
  if (out == nullptr) {
    std::fprintf(stderr, "cannot write %s\n", argv[2]);
    return 2;
  }
  std::fprintf(out, "{\n");
  kernelErrors(out);

  auto rows = std::make_shared<std::vector<Row>>();
  const std::vector<EngineSetting> settings = engineSettings();
  for (const BenchScene& bench : benchScenes()) {
    for (const Case& c : casesOf(bench, settings)) {
      Row row{"",
              bench.name,
              c.setting->engine,
              c.setting->variant,
              c.effects,
              c.rate,
              c.tolerance,
              0,
              false,
              "",
              {}};
      if (c.tolerance > 0) row.variant = "tolerance_" + number(c.tolerance);
      row.name = bench.name + "/" + row.engine + "/" + row.variant + "/" + c.effects + "/" +
                 number(c.rate);
      if (!std::regex_search(row.name, filter)) continue;
      rows->push_back(row);
      if (bench.long_run) {
        addLongRun(bench, c, rows, rows->size() - 1, references);
      } else {
        addShortRun(bench, c, rows->back(), references);
      }
    }
  }
  benchmark::RegisterBenchmark("kernel/impact/double", &BM_ImpactKernel<double>);
  benchmark::RegisterBenchmark("kernel/impact/float", &BM_ImpactKernel<float>);
  benchmark::RegisterBenchmark("kernel/time_of_impact/double", &BM_TimeOfImpactKernel<double>);
  benchmark::RegisterBenchmark("kernel/time_of_impact/float", &BM_TimeOfImpactKernel<float>);
  int bench_argc = argc - 2;
  argv[2] = argv[0];
  benchmark::Initialize(&bench_argc, argv + 2);
  if (!errors_only) benchmark::RunSpecifiedBenchmarks();

  std::fprintf(out, "  \"runs\": [\n");
  for (std::size_t i = 0; i < rows->size(); ++i) {
    std::fprintf(out, "%s    %s", i == 0 ? "" : ",\n", json((*rows)[i]).c_str());
  }
  std::fprintf(out, "\n  ]\n}\n");
  std::fclose(out);
  return 0;
}
