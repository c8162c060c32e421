// The accuracy-versus-cost harness: scenes, engines that play them at a state rate, references
// computed outside the code under test, and the errors of what each engine did.
// See scripts/accuracy.sh. To add a scene: a builder in scenes.cpp listed in benchScenes(), its
// metrics in measure.cpp, its table in scripts/accuracy_report.py (SCENES); the reference
// (reference/make_references.py) plays every exported scene without further work when it needs
// only impacts of spheres and planes.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "collision_response/core/scene.h"

namespace collision_response::bench {

using V = Eigen::Vector3d;

/// How a scene is played: one state (our monitor) or one step (the peers) every 1/rate s, for
/// `duration` s. `record_all`: keep every update's state (false: the first and the last only, for
/// long runs whose metrics need no more).
struct Play {
  double rate = 100.0;
  double duration = 1.0;
  bool record_all = true;
  /// Ours: where the source placed the bodies at each impact (ReportedImpact positions, for the
  /// apexes). A query of the source at a past instant costs it a replay: scenes that use no
  /// impact positions (lasting contact, piles of thousands of impacts) leave them out.
  bool impact_positions = true;
  /// m/s: obstacles that move at a constant velocity, by index (empty, or zero: fixed). Such an
  /// obstacle has a `frame` (ours places it on that frame, at its scene position plus v t; the
  /// peers move a kinematic body).
  std::vector<V> obstacle_velocities = {};
};

/// An impact an engine reported (ours: every one, at its instant).
struct ReportedImpact {
  double time = 0.0;
  std::size_t body = 0;          ///< scene index
  V position = V::Zero();        ///< of `body`'s centre, at the instant (Play::impact_positions)
  V velocity_after = V::Zero();  ///< of `body`
  bool other_is_obstacle = false;
  std::size_t other = 0;  ///< scene index of the other body, or obstacle index
  V other_position = V::Zero();
  V other_velocity_after = V::Zero();  ///< of the other body (obstacles: zero)
};

/// What an engine did: every body's state after each update (bodies as the scene lists them),
/// and the impacts it reports (ours; the peers report none).
struct Run {
  std::string unsupported;  ///< non-empty: the engine cannot play the scene, and why
  std::size_t bodies = 0;
  std::vector<double> times;
  std::vector<V> positions;   ///< [update * bodies + body], bodies as the scene lists them
  std::vector<V> velocities;  ///< [update * bodies + body]
  std::vector<ReportedImpact> impacts;  ///< ours only
  bool reports_impacts = false;         ///< true: `impacts` is the engine's own list
  bool truncated = false;               ///< the engine stopped a step early (ours: a guard)
  std::size_t states = 0;               ///< states recorded, kept or not
  /// Ours: the bodies in stepped clusters after the last update (StepReport::stepped_bodies);
  /// the peers: NaN.
  double stepped_bodies = std::nan("");

  /// Appends the state at `time` (or replaces the last one when only the ends are kept).
  void record(const Play& play, double time, const std::vector<V>& p, const std::vector<V>& v);
  std::size_t samples() const { return times.size(); }
  std::size_t updates() const { return states == 0 ? 0 : states - 1; }
  const V& position(std::size_t sample, std::size_t body) const {
    return positions[sample * bodies + body];
  }
  const V& velocity(std::size_t sample, std::size_t body) const {
    return velocities[sample * bodies + body];
  }
};

/// Whether a scene has a mesh obstacle (an engine without meshes in this harness says so).
inline bool hasMesh(const core::Scene& scene) {
  for (const core::ObstacleSpec& obstacle : scene.obstacles) {
    if (obstacle.shape == core::ObstacleShape::kMesh) return true;
  }
  return false;
}

/// Plays a scene.
using Engine = std::function<Run(const core::Scene& scene, const Play& play)>;

/// A scene of the benchmark: what is played, how long, at which rates, and how it is timed.
struct BenchScene {
  std::string name;
  core::Scene scene;
  double duration = 1.0;
  std::vector<double> rates;
  /// A long run: played once per setting, timed by that single run (Google Benchmark, one
  /// iteration), every state not kept unless `record_all`.
  bool long_run = false;
  bool record_all = true;
  /// Effects turned on in extra rows (100 Hz, ours, continuous), beside the scene as it is.
  std::vector<std::string> effect_variants;
  /// What reference/make_references.py computes: "events" (the exact event-driven motion) or
  /// "conservation" (only the conserved quantities: a chaotic gas's trajectory is not
  /// reproducible beyond a few dozen impacts in any finite precision, its energy is).
  /// "lasting" (contact that lasts, under gravity): closed forms of where the motion ends.
  std::string reference = "events";
  /// Ours (continuous, 100 Hz, the scene's effects and each of its effect variants) again at
  /// each of these Scene::contact_integration_tolerance values: error against CPU.
  std::vector<double> integration_tolerances = {};
  /// The engines that play the scene (empty: every one); e.g. a pile too large for some.
  std::vector<std::string> engines = {};
  /// The rates at which "ours, stepped" (every body in a stepped cluster) plays the scene; empty:
  /// not played. Its sub-step is each update's interval, split evenly when longer than
  /// Scene::stepped_cluster_time_step (0.01 s): 1 / rate from 100 Hz up.
  std::vector<double> stepped_rates = {};
  /// m/s: obstacles moving at a constant velocity, by index (Play::obstacle_velocities).
  std::vector<V> obstacle_velocities = {};
};

/// Whether a run moves obstacles (an engine without moving obstacles in this harness says so).
inline bool movesObstacles(const Play& play) {
  for (const V& v : play.obstacle_velocities) {
    if (v != V::Zero()) return true;
  }
  return false;
}

/// Every scene, short ones first; names are unique. The one list: the benchmark, the exported
/// inputs of the references and the report all follow it.
std::vector<BenchScene> benchScenes();

/// The scene with the effects named in `effects` ("none", or e.g. "friction, spin") turned on.
core::Scene withEffects(const BenchScene& bench, const std::string& effects);
/// The name a scene variant has in the reference file: "sphere_gas", "sphere_gas+gravity".
std::string referenceName(const BenchScene& bench, const std::string& effects);

/// The exact answers of the scenes (reference/references.txt, written by
/// reference/make_references.py): per scene, keys with rows of numbers.
class References {
 public:
  /// Reads `path`; a missing or malformed file is an error (thrown, with the line).
  static References read(const std::string& path);
  bool has(const std::string& scene, const std::string& key) const;
  /// The rows of `key` for `scene` (each row: the numbers after the key); throws when absent.
  const std::vector<std::vector<double>>& rows(const std::string& scene,
                                               const std::string& key) const;
  double value(const std::string& scene, const std::string& key) const {
    return rows(scene, key).front().front();
  }

 private:
  std::map<std::string, std::map<std::string, std::vector<std::vector<double>>>> data_;
};

/// Writes every scene variant's inputs (exact doubles, as C99 hex floats) for the reference.
void exportScenes(const std::vector<BenchScene>& scenes, const std::string& path);

/// The errors of a run against the scene's references: metric name -> value (NaN: not
/// measurable, e.g. a flight with too few samples). scripts/accuracy_report.py names them.
using Metrics = std::map<std::string, double>;
Metrics measure(const BenchScene& bench, const std::string& effects, const Run& run,
                const References& references);

/// For engines that multiply the two bodies' coefficients of restitution (Bullet, DART): each
/// body's and obstacle's own coefficient, such that every product is the scene's coefficient of
/// the pair (exact when the balls share one material, or never meet).
struct ProductRestitutions {
  std::vector<double> bodies, obstacles;
};
ProductRestitutions productRestitutions(const core::Scene& scene);

/// Our engine: the core's ImpactMonitor watching a core::Playback, as the node and the scene
/// player do over ROS. `stepped_cluster_min_bodies` > 0: the scene's Scene::
/// stepped_cluster_min_bodies set to it (1: every body under gravity is stepped). A stepped
/// cluster reports no impacts, so such a run is measured from its states, as the peers' are.
Engine oursEngine(core::Detection detection, int stepped_cluster_min_bodies = 0);

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
#ifdef COLLISION_RESPONSE_WITH_MUJOCO
/// MuJoCo: an MJCF model made per scene (free spheres, planes), frictionless contacts (condim 1).
/// `restitution`: the coefficient through a negative (direct) solref per pair; otherwise MuJoCo's
/// default soft contact.
Engine mujocoEngine(bool restitution);
#endif
#ifdef COLLISION_RESPONSE_WITH_DART
/// DART: a World with free-joint spheres, its FCL collision detector and its boxed-LCP
/// constraint solver; the coefficient through each shape's restitution. No CCD.
Engine dartEngine();
#endif
#ifdef COLLISION_RESPONSE_WITH_BOX2D
/// Box2D 2.4: circles in a plane (planar scenes only), restitution per contact, threshold 0,
/// bullets (continuous collision between moving bodies) on.
Engine box2dEngine();
#endif

}  // namespace collision_response::bench
