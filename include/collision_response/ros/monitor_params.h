// The node's private parameters: one struct with documented defaults and one loader that reads
// every `~` parameter with its type and range checked (README.md, "Parameters").
#pragma once

#include <XmlRpcValue.h>

#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/scene.h"
#include "collision_response/ros/markers.h"
#include "collision_response/ros/parameters.h"

namespace collision_response {

struct MonitorParams {
  double transform_timeout = 0.1;         ///< s (wall): how long a state waits for its transform
  double frame_velocity_interval = 0.01;  ///< s: finite difference for a moving frame's velocity
  /// s: within an update, tf-attached obstacles are placed again from tf at least this often
  /// (0: once an update, at its end)
  double obstacle_update_period = 0.001;
  double body_timeout = 1.0;              ///< s: a body with no state this long is forgotten
  double contact_tolerance = 1e-9;        ///< fraction of the contact distance that is touching
  double clock_jump_back = 1.0;           ///< s: a source's stamps this much older are a jump
  double future_stamp_tolerance = 300.0;  ///< s: a stamp further ahead of the clock is dropped
  int queue_size = 1000;                  ///< input messages waiting for transforms, at most
  int max_states = 100000;         ///< states in one BodyStateArray, and waiting in all, at most
  double diagnostic_period = 1.0;  ///< s: diagnostic_updater's own parameter, checked here
  MarkerParams markers;            ///< ~marker_rate, ~impact_marker_lifetime, ...
  /// s of the prediction thread's CPU time one ~predict_impacts request may spend (0: no budget)
  double prediction_cpu_budget = 1.0;
  /// s of stamps of each tracked body's states kept for ~estimate_restitution's live fit
  /// (live_calibration.h; 0: off, none kept)
  double calibration_window = 10.0;

  /// Every private parameter the node reads: its own above, `scene` (read by loadScene),
  /// `player` (a scene file's part for the scene player, type-checked only) and
  /// the values dynamic_reconfigure keeps there (`detection`, `restitution_threshold`,
  /// `restitution_combine`, type-checked only: the scene gives their starting values).
  static const KeyTable<MonitorParams>& keys();

  /// Reads the node's private namespace, `tree` (the whole `~` mapping, as
  /// ros::param::get(namespace) returns it; `ns` its name for messages): a wrong type, a value
  /// out of range or a parameter the node does not know stops it, the error naming the key.
  static core::Expected<MonitorParams> load(const XmlRpc::XmlRpcValue& tree, const std::string& ns);
};

/// The scene's body topics as the node would subscribe to them (resolved in `node_namespace`,
/// as a NodeHandle there resolves them): each must be a valid name, differ from the states
/// topic `array_topic` (resolved) and from every other body's. Errors name the body's key
/// (`field`/bodies[i]/topic).
core::Status checkBodyTopics(const core::Scene& scene, const std::string& node_namespace,
                             const std::string& array_topic, const std::string& field);

}  // namespace collision_response
