// Playing a scene without ROS: the bodies moved from their initial states by the monitor's own
// model (free flight, and lasting contact: resting, sliding, rolling, stacked; a shaped body by
// its exact motion among the obstacles), the impacts it is told of applied from their instants. The scene player (ROS) and the accuracy benchmark use it.
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
/// Impacts arrive after the states that revealed them were played, so the motion is kept as the
/// model at each instant asked for (in increasing order) over the last `replay_window` s, from
/// what is final: the model at the latest instant asked for that is more than `replay_window` s
/// before the last one (window 0: the one before the last, so an impact must be heard within a
/// period). An impact inside the window is applied by playing the motion again from its instant
/// through the same instants (the same steps, so the same result as heard in time); an impact
/// older than what is final is refused (false). Bodies are the scene's, as listed.
class Playback {
 public:
  /// Starts every body of `scene` at `start` from its `position` and `velocity`; impacts heard
  /// up to `replay_window` s (>= 0) after the latest instant asked for are still applied.
  Playback(const Scene& scene, double contact_tolerance, double start, double replay_window = 0.0);

  std::size_t bodyCount() const { return scene_.bodies.size(); }
  Eigen::Vector3d position(std::size_t body, double time) const;
  Eigen::Vector3d velocity(std::size_t body, double time) const;
  Eigen::Vector3d angularVelocity(std::size_t body, double time) const;
  /// World from body: a shaped body's followed in flight, through its impacts and its lasting
  /// contact (the monitor's predictedOrientation); a ball's the scene's initial one (a ball's does
  /// not matter).
  Eigen::Quaterniond orientation(std::size_t body, double time) const;

  /// An impact on `body` at `time`: from then on it moves from `centre` with the velocities after
  /// (its lasting contacts formed again there). False when `time` is older than what is final.
  /// The instants asked for after `time` are played again at the next question.
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
  /// The model at one instant asked for; empty while an impact heard since has to be played
  /// again through it.
  struct Played {
    double time = 0.0;
    std::optional<ImpactMonitor> model;
    std::vector<ContactRecord> contacts;  ///< the lasting contacts of the step that reached it
  };
  /// The model at `time`: the latest instant played at or before it, advanced with the impacts
  /// applied up to then.
  const ImpactMonitor& at(double time) const;
  /// Plays again every instant whose model an impact dropped, each from the one before.
  void replay() const;
  /// `played_[k]`'s model from `played_[k - 1]`'s, with the impacts in between.
  void playFromPrevious(std::size_t k) const;
  /// The impacts applied in (from, to], in time order.
  std::vector<BodyStateSample> impactsIn(double from, double to) const;

  Scene scene_;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();
  std::vector<std::size_t> model_index_;  // scene body -> the model's index
  std::map<std::string, std::size_t> index_;
  double replay_window_ = 0.0;
  /// The instants asked for, in increasing order: the front is final (an impact before it is
  /// refused), the others within replay_window_ of the back.
  mutable std::vector<Played> played_;
  mutable std::vector<BodyStateSample> pending_;  // impacts after played_.front(), by time
  mutable std::optional<ImpactMonitor> view_;     // between two instants asked for
  mutable double view_time_ = 0.0;
  mutable std::vector<ContactRecord> view_contacts_;
  mutable const std::vector<ContactRecord>* at_contacts_ = nullptr;  // those of at()'s model
  std::vector<Flight> flights_;
};

}  // namespace collision_response::core
