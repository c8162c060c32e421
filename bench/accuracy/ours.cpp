#include "collision_response/core/monitor.h"
#include "collision_response/core/playback.h"
#include "harness.h"

namespace collision_response::bench {

Engine oursEngine(core::Detection detection, int stepped_cluster_min_bodies) {
  return [detection, stepped_cluster_min_bodies](const core::Scene& input, const Play& play) {
    core::Scene scene = input;
    scene.detection = detection;
    if (stepped_cluster_min_bodies > 0) {
      scene.stepped_cluster_min_bodies = stepped_cluster_min_bodies;
    }
    core::MonitorSettings settings;
    settings.body_timeout = 2 * play.duration + 1;
    core::ImpactMonitor monitor(scene, settings);
    core::Playback playback(scene, settings.contact_tolerance, 0.0);
    // The monitor indexes bodies by sorted id; the run lists them as the scene does.
    std::vector<std::size_t> monitor_index, scene_index(scene.bodies.size());
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      monitor_index.push_back(*monitor.bodyIndex(scene.bodies[i].id));
      scene_index[monitor_index.back()] = i;
    }
    const bool exact_contact = detection == core::Detection::kContinuous;

    Run run;
    // A stepped cluster's bounces are not reported as impacts: a run that forces stepping is
    // measured from its states.
    run.reports_impacts = stepped_cluster_min_bodies <= 0;
    const auto updates = static_cast<long>(std::llround(play.duration * play.rate));
    std::vector<core::BodyStateSample> states(scene.bodies.size());
    std::vector<V> positions(states.size()), velocities(states.size());
    for (long k = 0; k <= updates; ++k) {
      const double t = static_cast<double>(k) / play.rate;
      // The source publishes every body's state at t; the monitor finds the impacts since the
      // last states; the source applies them (the scene player's loop).
      for (std::size_t i = 0; i < states.size(); ++i) {
        states[i].body = monitor_index[i];
        states[i].time = t;
        states[i].position = playback.position(i, t);
        states[i].velocity = playback.velocity(i, t);
        // With spin, a rolling ball's spin is part of its state (zero would say it slips).
        states[i].angular_velocity = playback.angularVelocity(i, t);
      }
      // Moving obstacles: their frames at t (the obstacle at its scene position plus v t).
      for (std::size_t o = 0; o < play.obstacle_velocities.size(); ++o) {
        if (play.obstacle_velocities[o] == V::Zero()) continue;
        core::RigidPose frame;
        frame.time = t;
        frame.transform.translation() = t * play.obstacle_velocities[o];
        frame.velocity = play.obstacle_velocities[o];
        monitor.setObstaclePose(o, frame);
      }
      const core::StepReport report = monitor.step(t, states);
      run.truncated = run.truncated || report.truncated;
      run.stepped_bodies = static_cast<double>(report.stepped_bodies);
      playback.applyImpacts(monitor, report.impacts, exact_contact);
      for (const core::ImpactRecord& impact : report.impacts) {
        // Where the source placed a body at the instant: continuous, at the contact, r along the
        // normal from the impact's point (as Playback::applyImpact places it: no query, which
        // would cost the source a replay of the update up to the instant, for every impact);
        // discrete, where the source has it then.
        const auto placed = [&](std::size_t body, double side) {
          return exact_contact
                     ? V(impact.contact_point + side * scene.bodies[body].radius * impact.normal)
                     : playback.position(body, impact.time);
        };
        ReportedImpact reported;
        reported.time = impact.time;
        reported.body = scene_index[impact.body_a];
        if (play.impact_positions) reported.position = placed(reported.body, -1.0);
        reported.velocity_after = impact.velocity_a_after;
        reported.other_is_obstacle = impact.other_is_obstacle;
        if (!impact.other_is_obstacle) {
          reported.other = scene_index[impact.other];
          if (play.impact_positions) reported.other_position = placed(reported.other, 1.0);
          reported.other_velocity_after = impact.velocity_b_after;
        } else {
          reported.other = impact.other;
        }
        run.impacts.push_back(reported);
      }
      for (std::size_t i = 0; i < states.size(); ++i) {
        positions[i] = playback.position(i, t);
        velocities[i] = playback.velocity(i, t);
      }
      run.record(play, t, positions, velocities);
    }
    return run;
  };
}

}  // namespace collision_response::bench
