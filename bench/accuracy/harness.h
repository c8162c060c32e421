// The accuracy-versus-cost harness: scenes with exact answers, engines that play them at a
// state rate, and the errors of what they did. See scripts/accuracy.sh.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "collision_response/core/scene.h"

namespace collision_response::bench {

using V = Eigen::Vector3d;

/// What an engine did: every body's state after each update, and the instants of impact it
/// found (engines that report them).
struct Run {
  std::vector<double> times;
  std::vector<std::vector<V>> positions;   ///< [update][body], bodies as the scene lists them
  std::vector<std::vector<V>> velocities;  ///< [update][body]
  std::vector<double> impact_times;        ///< ours only: the instants found
  std::size_t impacts = 0;                 ///< ours: impacts resolved (peers: not counted)
};

/// Plays `scene` for `duration` s, states exchanged at `rate` Hz.
using Engine = std::function<Run(const core::Scene& scene, double rate, double duration)>;

/// A scene of the benchmark and how long it is played.
struct BenchScene {
  std::string name;
  core::Scene scene;
  double duration = 1.0;
};

BenchScene dropTestScene();
BenchScene cradleScene();
BenchScene breakScene();
BenchScene tunnellingScene();
BenchScene gasScene();

/// The errors of a run against the scene's exact answers (NaN where not measured).
struct Errors {
  double instant = NAN;         ///< s, |first impact instant - exact|
  double velocity = NAN;        ///< m/s, after the impacts, worst body (or RMS for the break)
  double restitution = NAN;     ///< relative, drop test: e from the first bounce's apex, worst
  double apex = NAN;            ///< relative, drop test: the apex after 3 bounces, worst
  double missed = 0;            ///< impacts missed (tunnelling)
  double momentum_drift = NAN;  ///< relative
  double energy_drift = NAN;    ///< relative
};
/// `scene`: the bench scene as played (with the setting's effects); `reference`: the exact
/// answer where no closed form exists (our continuous detection, the same effects).
Errors measure(const BenchScene& bench, const core::Scene& scene, const Run& run,
               const Run* reference);

/// Our engine: the core's ImpactMonitor watching a core::Playback, as the node and the scene
/// player do over ROS.
Engine oursEngine(core::Detection detection);

#ifdef COLLISION_RESPONSE_WITH_BULLET
/// Bullet 3: btDiscreteDynamicsWorld, spheres and static planes. `recommended`: the settings
/// its maintainers give for bouncing (restitution velocity threshold 0, no warm starting, split
/// impulse, CCD on); otherwise its defaults.
Engine bulletEngine(bool recommended);
#endif
#ifdef COLLISION_RESPONSE_WITH_ODE
/// ODE: dWorldStep, contact joints with bounce = e, bounce_vel = 0, mu = 0.
Engine odeEngine();
#endif

}  // namespace collision_response::bench
