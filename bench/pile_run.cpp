// A pile of balls dropped into a closed box, played as the scene player plays it (core::Playback
// moving the bodies by the monitor's model, the monitor's impacts applied from their instants),
// for profiling and for the cost per simulated second: the monitor's CPU and its worst update.
//   pile_run [balls=8] [seconds=1] [friction=0.5, 0: none] [rate=100] [seed=11]
// PILE_RUN_VERBOSE=1: a line per update; PILE_RUN_IMPACTS=1: every impact record;
// PILE_RUN_STEPPED_WORK=n: MonitorSettings::max_stepped_work_per_step (0: no bound).
// The pile: bench/dropped_pile.h (a pile is chaotic: compare settings over several seeds).
#include <cstdio>
#include <cstdlib>

#include "dropped_pile.h"

int main(int argc, char** argv) {
  using namespace collision_response;
  using V = Eigen::Vector3d;
  const int count = argc > 1 ? std::atoi(argv[1]) : 8;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 1.0;
  const double mu = argc > 3 ? std::atof(argv[3]) : 0.5;
  const double rate = argc > 4 ? std::atof(argv[4]) : 100.0;
  const unsigned seed = argc > 5 ? static_cast<unsigned>(std::atoi(argv[5])) : 11u;
  if (count < 1 || !(seconds > 0) || !(mu >= 0) || !(rate > 0)) {
    std::fprintf(stderr,
                 "usage: pile_run [balls >= 1] [seconds > 0] [mu >= 0] [rate > 0] [seed]\n");
    return 2;
  }
  const bool verbose = std::getenv("PILE_RUN_VERBOSE") != nullptr;
  const bool impacts = std::getenv("PILE_RUN_IMPACTS") != nullptr;
  core::MonitorSettings settings;
  if (const char* work = std::getenv("PILE_RUN_STEPPED_WORK")) {
    settings.max_stepped_work_per_step = std::strtoull(work, nullptr, 10);
  }
  const bench::PileFigures figures = bench::playPile(
      bench::droppedPile(count, mu, seed), seconds, rate,
      [&](double time, const core::StepReport& report, double cpu) {
        if (impacts) {
          for (const core::ImpactRecord& i : report.impacts) {
            const V other = i.other_is_obstacle ? V::Zero() : V(i.velocity_b_before);
            std::printf("  impact %.15f a %zu %s %zu e %g J %.3g approach %.3g\n", i.time, i.body_a,
                        i.other_is_obstacle ? "obstacle" : "body", i.other, i.restitution,
                        i.impulse, (i.velocity_a_before - other).dot(i.normal));
          }
        }
        if (verbose) {
          std::printf(
              "t %.2f impacts %zu contacts %zu stepped %zu stepped work %zu held over it %zu "
              "monitor %.4f s\n",
              time, report.impacts.size(), report.contacts.size(), report.stepped_bodies,
              report.stepped_work, report.over_stepped_work.size(), cpu);
        }
      },
      settings);
  std::printf(
      "balls %d mu %g rate %g: %g s simulated, monitor %.3f s CPU (%.3f s per simulated s), "
      "worst update %.3f s at %.2f s, source %.3f s CPU, impacts %zu, fallbacks %zu, deepest "
      "%.3g m\n",
      count, mu, rate, seconds, figures.monitor_cpu, figures.monitor_cpu / seconds,
      figures.worst_update, figures.worst_time, figures.source_cpu, figures.impacts,
      figures.fallbacks, figures.deepest);
}
