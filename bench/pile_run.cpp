// A pile of balls dropped into a closed box, played as the scene player plays it (core::Playback
// moving the bodies by the monitor's model, the monitor's impacts applied from their instants),
// for profiling and for the cost per simulated second: the monitor's CPU and its worst update.
//   pile_run [balls=8] [seconds=1] [friction=0.5, 0: none] [rate=100] [seed=11]
// PILE_RUN_VERBOSE=1: a line per update; PILE_RUN_IMPACTS=1: every impact record.
// Balls r = 0.05 m, 0.1 kg, e = 0.5, solid; with friction > 0 the friction and spin effects are
// on (mu on every contact). The lattice is the accuracy benchmark's ballPileScene: 0.12 m apart,
// offsets up to 5 mm (seed 11 by default), box of side 0.12 ceil(cbrt(n)) + 0.1 m.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <random>
#include <string>
#include <vector>

#include "box_walls.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/playback.h"

namespace {

using V = Eigen::Vector3d;

double cpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace collision_response;
  const int count = argc > 1 ? std::atoi(argv[1]) : 8;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 1.0;
  const double mu = argc > 3 ? std::atof(argv[3]) : 0.5;
  const double rate = argc > 4 ? std::atof(argv[4]) : 100.0;
  // The lattice's offsets: a pile is chaotic, so compare settings over several seeds.
  const unsigned seed = argc > 5 ? static_cast<unsigned>(std::atoi(argv[5])) : 11u;
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
  bench::addBoxWalls(scene, size, "pile");

  core::MonitorSettings settings;
  core::ImpactMonitor monitor(scene, settings);
  core::Playback source(scene, settings.contact_tolerance, 0.0);
  std::vector<core::BodyStateSample> states(scene.bodies.size());
  for (std::size_t i = 0; i < states.size(); ++i) {
    states[i].body = *monitor.bodyIndex(scene.bodies[i].id);
  }
  double monitor_cpu = 0, source_cpu = 0, worst = 0, worst_time = 0;
  std::size_t impacts = 0, fallbacks = 0;
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
    source_cpu += (sampled - began) + (applied - stepped);
    monitor_cpu += stepped - sampled;
    if (stepped - sampled > worst) {
      worst = stepped - sampled;
      worst_time = time;
    }
    impacts += report.impacts.size();
    fallbacks += report.fallbacks;
    if (std::getenv("PILE_RUN_IMPACTS")) {
      for (const core::ImpactRecord& i : report.impacts) {
        const V va = i.velocity_a_before, vb = i.velocity_b_before;
        std::printf("  impact %.15f a %zu %s %zu e %g J %.3g approach %.3g\n", i.time, i.body_a,
                    i.other_is_obstacle ? "obstacle" : "body", i.other, i.restitution, i.impulse,
                    (va - (i.other_is_obstacle ? V::Zero() : vb)).dot(i.normal));
      }
    }
    if (std::getenv("PILE_RUN_VERBOSE")) {
      std::printf("t %.2f impacts %zu contacts %zu stepped %zu monitor %.4f s\n", time,
                  report.impacts.size(), report.contacts.size(), report.stepped_bodies,
                  stepped - sampled);
    }
  }
  std::printf(
      "balls %d mu %g rate %g: %g s simulated, monitor %.3f s CPU (%.3f s per simulated s), "
      "worst update %.3f s at %.2f s, source %.3f s CPU, impacts %zu, fallbacks %zu\n",
      count, mu, rate, seconds, monitor_cpu, monitor_cpu / seconds, worst, worst_time, source_cpu,
      impacts, fallbacks);
}
