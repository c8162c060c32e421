// Playing a scene without ROS: the bodies moved from their initial states by the monitor's own
// model (free flight, and lasting contact: resting, sliding, rolling, stacked), the impacts it is
// told of applied from their instants. The scene player (ROS) and the accuracy benchmark use it.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"

namespace collision_response::core {

/// One flight's highest point (against gravity).
struct Apex {
  std::size_t body = 0;  ///< index into the scene's bodies (as listed)
  double time = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  int impacts_before = 0;  ///< impacts the body had before this flight
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< rad/s, constant in flight
};

/// A scene played forward by the monitor's model, the impacts of whoever watches the played
/// states (the node over ROS) applied from their instants. Under the scene's continuous detection
/// the played motion also finds and resolves impacts itself, by the same model, until the
/// watcher's arrive and replace them: no body is shown inside another while an impact is on its
/// way, nor where replaying the watcher's impacts drifts from its motion by the residual of its
/// contact solves (a squeezed ball in a settling pile). Under discrete detection it does not:
/// the watcher finds impacts as overlaps at its samples, which the played bodies must reach.
///
/// Impacts arrive after the states that revealed them were played, so the motion is kept in two
/// parts: what is final (committed, up to the latest instant asked for before the last one) and
/// what is played ahead from it with the impacts applied so far. Asking for a later instant makes
/// the earlier part final; an impact older than what is final is refused (false). Bodies are the
/// scene's, as listed.
class Playback {
 public:
  /// Starts every body of `scene` at `start` from its `position` and `velocity`.
  Playback(const Scene& scene, double contact_tolerance, double start);

  std::size_t bodyCount() const { return scene_.bodies.size(); }
  Eigen::Vector3d position(std::size_t body, double time) const;
  Eigen::Vector3d velocity(std::size_t body, double time) const;
  Eigen::Vector3d angularVelocity(std::size_t body, double time) const;

  /// An impact on `body` at `time`: from then on it moves from `centre` with the velocities after
  /// (its lasting contacts formed again there). False when `time` is older than what is final.
  bool applyImpact(std::size_t body, double time, const Eigen::Vector3d& centre,
                   const Eigen::Vector3d& velocity_after,
                   const Eigen::Vector3d& angular_velocity_after = Eigen::Vector3d::Zero());

  /// Applies an impact record of `monitor` (whose bodies are indexed by id) to the bodies it
  /// names, placing them at the contact (`exact_contact`: continuous detection, where the
  /// surfaces touch there) or where they were. False when a body refused it (its instant is older
  /// than what is final: it came too late to be played), so that the caller can say so.
  bool applyImpact(const ImpactMonitor& monitor, const ImpactRecord& impact, bool exact_contact);

  /// applyImpact for every record of one step (discrete detection's all at one instant): where
  /// the bodies are is read once for them all, before any is applied (an impact does not move a
  /// body at its instant), instead of the played motion being worked out again after each one.
  /// Returns the indices of the records a body refused (came too late to be played).
  std::vector<std::size_t> applyImpacts(const ImpactMonitor& monitor,
                                        const std::vector<ImpactRecord>& impacts,
                                        bool exact_contact);

  /// The flights whose highest point is at or before `time` and not yet reported (under gravity
  /// without drag or Magnus: a parabola's apex).
  std::vector<Apex> apexesUntil(double time);

  std::optional<std::size_t> bodyIndex(const std::string& id) const;

  /// The lasting contacts of the played motion at `time` (as the monitor reports them).
  std::vector<ContactRecord> contacts(double time) const;

 private:
  struct Flight {
    double start = 0.0;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    bool apex_reported = false;
    int impacts_before = 0;
    Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  };
  /// The model at `time`: the final part advanced with the impacts applied up to then.
  const ImpactMonitor& at(double time) const;

  Scene scene_;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();
  std::vector<std::size_t> model_index_;  // scene body -> the model's index
  std::map<std::string, std::size_t> index_;
  mutable ImpactMonitor committed_;
  mutable double committed_time_;
  mutable std::vector<BodyStateSample> pending_;  // impacts after committed_time_, by time
  mutable std::optional<ImpactMonitor> view_;
  mutable double view_time_ = 0.0;
  mutable double horizon_;  // the latest instant asked for
  mutable std::vector<ContactRecord> view_contacts_;
  std::vector<Flight> flights_;
};

}  // namespace collision_response::core
