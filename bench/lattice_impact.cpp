// lattice_impact: one simultaneous impact of many bodies (issue 41, item 4). A touching n x n x n
// lattice of balls (r = 0.05 m, 0.1 kg, solid), e = 0.5 and mu = 0.3 with friction and spin,
// each closing on the centre at 1 m/s per m, swirling about z at 1 rad/s and spinning at up to
// 10 rad/s (seeded), met in one message: the first message starts the monitor, the update 10 ms
// later resolves the impact at its instant. Prints the update's wall time, its impacts, the
// impact clusters' work (MonitorSettings::max_impact_work_per_step) and the bodies it cut short,
// then the next updates' times (doc/performance.md, "One impact of many bodies").
//   lattice_impact [n = 12] [gravity 0/1 = 0] [bound = the default; 0: none] [updates = 3]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"

using collision_response::core::BodySpec;
using collision_response::core::BodyStateSample;
using collision_response::core::ImpactMonitor;
using collision_response::core::Material;
using collision_response::core::MonitorSettings;
using collision_response::core::Scene;
using collision_response::core::StepReport;
using V = Eigen::Vector3d;

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 12;
  const bool gravity = argc > 2 && std::atoi(argv[2]) != 0;
  MonitorSettings settings;
  if (argc > 3) settings.max_impact_work_per_step = std::strtoull(argv[3], nullptr, 10);
  const int updates = argc > 4 ? std::atoi(argv[4]) : 3;
  Scene scene;
  scene.effects.gravity = gravity;
  scene.effects.friction = true;
  scene.effects.spin = true;
  if (!scene.materials.addMaterial("clay", Material{0.5, 0.3}, "materials").ok()) return 1;
  const double r = 0.05;
  const V centre = V::Constant(r * (n - 1));
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        BodySpec body;
        body.id = "ball_" + std::to_string(i) + "_" + std::to_string(j) + "_" + std::to_string(k);
        body.mass = 0.1;
        body.radius = r;
        body.material = "clay";
        body.position = V(2 * r * i, 2 * r * j, 2 * r * k);
        scene.bodies.push_back(body);
      }
    }
  }
  ImpactMonitor monitor(scene, settings);
  std::mt19937_64 engine(3);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<BodyStateSample> states;
  for (const BodySpec& body : scene.bodies) {
    BodyStateSample state;
    state.body = *monitor.bodyIndex(body.id);
    state.position = body.position;
    const V offset = body.position - centre;
    state.velocity = -offset + V::UnitZ().cross(offset);
    const double x = unit(engine), y = unit(engine), z = unit(engine);
    state.angular_velocity = 10 * V(x, y, z);
    states.push_back(state);
  }
  monitor.step(0.0, states);
  for (int update = 1; update <= updates; ++update) {
    const auto start = std::chrono::steady_clock::now();
    const StepReport report = monitor.step(0.01 * update, {});
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf(
        "{\"balls\": %d, \"gravity\": %d, \"bound\": %zu, \"update\": %d, \"seconds\": %.4f, "
        "\"impacts\": %zu, \"impact_work\": %zu, \"over_impact_work\": %zu, \"stepped\": %zu, "
        "\"stepped_work\": %zu}\n",
        n * n * n, gravity ? 1 : 0, settings.max_impact_work_per_step, update, seconds,
        report.impacts.size(), report.impact_work, report.over_impact_work.size(),
        report.stepped_bodies, report.stepped_work);
  }
  return 0;
}
