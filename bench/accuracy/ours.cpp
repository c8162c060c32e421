#include <map>

#include "collision_response/core/monitor.h"
#include "collision_response/core/playback.h"
#include "harness.h"

namespace collision_response::bench {

Engine oursEngine(core::Detection detection) {
  return [detection](const core::Scene& input, double rate, double duration) {
    core::Scene scene = input;
    scene.detection = detection;
    core::MonitorSettings settings;
    settings.body_timeout = 2 * duration + 1;
    core::ImpactMonitor monitor(scene, settings);
    core::Playback playback(scene, settings.contact_tolerance, 0.0);
    std::vector<std::size_t> monitor_index;
    for (const core::BodySpec& body : scene.bodies)
      monitor_index.push_back(*monitor.bodyIndex(body.id));
    const bool exact_contact = detection == core::Detection::kContinuous;

    Run run;
    const auto updates = static_cast<long>(std::llround(duration * rate));
    std::vector<core::BodyStateSample> states(scene.bodies.size());
    for (long k = 0; k <= updates; ++k) {
      const double t = static_cast<double>(k) / rate;
      // The source publishes every body's state at t; the monitor finds the impacts since the
      // last states; the source applies them (the scene player's loop).
      for (std::size_t i = 0; i < states.size(); ++i) {
        states[i].body = monitor_index[i];
        states[i].time = t;
        states[i].position = playback.position(i, t);
        states[i].velocity = playback.velocity(i, t);
      }
      const core::StepReport report = monitor.step(t, states);
      for (const core::ImpactRecord& impact : report.impacts) {
        playback.applyImpact(monitor, impact, exact_contact);
        run.impact_times.push_back(impact.time);
      }
      run.impacts += report.impacts.size();
      run.times.push_back(t);
      std::vector<V> positions, velocities;
      for (std::size_t i = 0; i < states.size(); ++i) {
        positions.push_back(playback.position(i, t));
        velocities.push_back(playback.velocity(i, t));
      }
      run.positions.push_back(positions);
      run.velocities.push_back(velocities);
    }
    return run;
  };
}

}  // namespace collision_response::bench
