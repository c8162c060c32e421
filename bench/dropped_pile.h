// A pile of balls dropped into a closed box (the accuracy benchmark's ballPileScene, with
// friction and spin when mu > 0), played as the scene player plays it: core::Playback moves the
// bodies by the monitor's model and takes the monitor's impacts. For bench/pile_run.cpp (by
// hand, for profiling) and bench_scale's BM_DroppedPile (beside Bullet on the same pile).
#pragma once

#include <array>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <functional>
#include <map>
#include <random>
#include <vector>

#include "box_walls.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/playback.h"

namespace collision_response::bench {

/// `count` balls (r = 0.05 m, 0.1 kg, solid, e = 0.5; mu on every contact, 0: frictionless)
/// from a loose cubic lattice 0.12 m apart, each nudged by up to 5 mm (the engine's `seed`), in a
/// box of side 0.12 ceil(cbrt(count)) + 0.1 m.
inline core::Scene droppedPile(int count, double mu, unsigned seed = 11) {
  using V = Eigen::Vector3d;
  core::Scene scene;
  scene.effects.gravity = true;
  scene.effects.friction = mu > 0;
  scene.effects.spin = mu > 0;
  core::Material material{0.5, {}};
  if (mu > 0) material.friction = mu;
  (void)scene.materials.addMaterial("pile", material, "m");
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(count))));
  const double spacing = 0.12, size = spacing * side + 0.1;
  std::mt19937_64 engine(seed);
  std::uniform_real_distribution<double> offset(-0.005, 0.005);
  for (int i = 0; i < count; ++i) {
    const V cell(i % side, (i / side) % side, i / (side * side));
    core::BodySpec body;
    char id[16];
    std::snprintf(id, sizeof id, "ball_%04d", i);
    body.id = id;
    body.mass = 0.1;
    body.radius = 0.05;
    body.material = "pile";
    body.position =
        V(0.11, 0.11, 0.11) + spacing * cell + V(offset(engine), offset(engine), offset(engine));
    scene.bodies.push_back(body);
  }
  addBoxWalls(scene, size, "pile");
  return scene;
}

/// The deepest any of the scene's balls (radius `r`) goes into another or into the walls of a
/// box [0, size]^3, at the positions given; pairs by a grid of cells of 2 r, so that a pile of
/// 1,000 costs no square.
double deepestOverlap(const std::vector<Eigen::Vector3d>& positions, double r, double size) {
  double deepest = 0;
  std::map<std::array<long, 3>, std::vector<std::size_t>> cells;
  const auto cellOf = [r](const Eigen::Vector3d& p) {
    return std::array<long, 3>{std::lround(std::floor(p.x() / (2 * r))),
                               std::lround(std::floor(p.y() / (2 * r))),
                               std::lround(std::floor(p.z() / (2 * r)))};
  };
  for (std::size_t i = 0; i < positions.size(); ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      deepest = std::max({deepest, r - positions[i][axis], positions[i][axis] + r - size});
    }
    cells[cellOf(positions[i])].push_back(i);
  }
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const std::array<long, 3> home = cellOf(positions[i]);
    for (long dx = -1; dx <= 1; ++dx) {
      for (long dy = -1; dy <= 1; ++dy) {
        for (long dz = -1; dz <= 1; ++dz) {
          const auto found = cells.find({home[0] + dx, home[1] + dy, home[2] + dz});
          if (found == cells.end()) continue;
          for (const std::size_t j : found->second) {
            if (j > i) deepest = std::max(deepest, 2 * r - (positions[j] - positions[i]).norm());
          }
        }
      }
    }
  }
  return deepest;
}

/// What a played pile cost, and how deep any ball went into another or a wall.
struct PileFigures {
  double monitor_cpu = 0;  ///< s, the monitor's steps
  double source_cpu = 0;   ///< s, the played motion (Playback): sampling and applying impacts
  double worst_update = 0, worst_time = 0;  ///< s: the monitor's longest step, and when
  std::size_t impacts = 0, fallbacks = 0;
  double deepest = 0;  ///< m: the deepest overlap at the updates' instants
};

inline double cpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

/// Plays `scene` (a droppedPile) for `seconds` at `rate` Hz; `each` (optional) sees every step.
inline PileFigures playPile(
    const core::Scene& scene, double seconds, double rate,
    const std::function<void(double, const core::StepReport&, double)>& each = {},
    const core::MonitorSettings& settings = {}) {
  core::ImpactMonitor monitor(scene, settings);
  core::Playback source(scene, settings.contact_tolerance, 0.0);
  std::vector<core::BodyStateSample> states(scene.bodies.size());
  for (std::size_t i = 0; i < states.size(); ++i) {
    states[i].body = *monitor.bodyIndex(scene.bodies[i].id);
  }
  const double size = -scene.obstacles[1].offset;  // addBoxWalls: wall_1 at x = size
  PileFigures figures;
  const int updates = static_cast<int>(std::lround(seconds * rate));
  for (int k = 0; k <= updates; ++k) {
    const double time = k / rate;
    const double began = cpuSeconds();
    for (std::size_t i = 0; i < states.size(); ++i) {
      states[i].time = time;
      states[i].position = source.position(i, time);
      states[i].velocity = source.velocity(i, time);
      states[i].angular_velocity = source.angularVelocity(i, time);
    }
    const double sampled = cpuSeconds();
    const core::StepReport report = monitor.step(time, states);
    const double stepped = cpuSeconds();
    for (const core::ImpactRecord& impact : report.impacts)
      source.applyImpact(monitor, impact, true);
    const double applied = cpuSeconds();
    figures.source_cpu += (sampled - began) + (applied - stepped);
    figures.monitor_cpu += stepped - sampled;
    if (stepped - sampled > figures.worst_update) {
      figures.worst_update = stepped - sampled;
      figures.worst_time = time;
    }
    figures.impacts += report.impacts.size();
    figures.fallbacks += report.fallbacks;
    std::vector<Eigen::Vector3d> positions(states.size());
    for (std::size_t i = 0; i < states.size(); ++i) positions[i] = states[i].position;
    figures.deepest =
        std::max(figures.deepest, deepestOverlap(positions, scene.bodies.front().radius, size));
    if (each) each(time, report, stepped - sampled);
  }
  return figures;
}

}  // namespace collision_response::bench
