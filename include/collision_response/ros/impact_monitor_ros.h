// The impact monitor on ROS: body states in (any tf frame), impacts out.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <deque>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "collision_response/BodyState.h"
#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"
#include "collision_response/ros/markers.h"
#include "collision_response/ros/throttled_warning.h"

namespace collision_response {

/// The monitor's private parameters (besides `~scene`), with their defaults.
struct MonitorParams {
  double transform_timeout = 0.1;         ///< s (wall): how long a state waits for its transform
  double frame_velocity_interval = 0.01;  ///< s: finite difference for a moving frame's velocity
  double body_timeout = 1.0;              ///< s: a body with no state this long is forgotten
  double contact_tolerance = 1e-9;        ///< fraction of the contact distance that is touching
  double clock_jump_back = 1.0;           ///< s: a stamp this much older than now is a clock jump
  int queue_size = 1000;                  ///< input messages waiting for transforms, at most
  int max_states = 100000;                ///< states in one BodyStateArray, at most
  MarkerParams markers;                   ///< ~marker_rate, ~impact_marker_lifetime, ...

  /// Reads `~transform_timeout` and the others; a bad value is an error naming it.
  static core::Expected<MonitorParams> load(const ros::NodeHandle& private_node);
};

class ImpactMonitorRos {
 public:
  /// Subscribes `body_states` and the bodies' own topics, advertises `impacts`.
  ImpactMonitorRos(ros::NodeHandle node, const core::Scene& scene, const MonitorParams& params);

  /// Counts of what the monitor did and dropped, by reason (for logs and diagnostics).
  const std::map<std::string, std::uint64_t>& counters() const { return counters_; }

  /// Live tuning (dynamic_reconfigure), validated by the caller: see core::ImpactMonitor::tune.
  void tune(core::Detection detection, double restitution_threshold, core::CombineRule rule);

  /// The monitor's status for /diagnostics: rates, bodies tracked, drops by reason, timing.
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

 private:
  /// An input waiting for its transforms: an array, kept as received (no copy of its
  /// states; a nodelet's publisher's message itself), or one state.
  struct Pending {
    ros::WallTime received;
    std::string source;  ///< the topic, for warnings
    BodyStateArray::ConstPtr array;
    std::vector<BodyState> single;
    const std::vector<BodyState>& states() const { return array ? array->states : single; }
  };
  struct Converted {
    ros::Time stamp;
    core::BodyStateSample sample;
  };

  void onStateArray(const BodyStateArray::ConstPtr& message);
  void onState(const BodyState::ConstPtr& message, const std::string& topic, const std::string& id);
  void enqueue(Pending pending);
  void processQueue();
  /// true when the head of the queue was handled (processed or dropped), false to wait.
  bool processHead();
  void step(const ros::Time& stamp, const std::vector<core::BodyStateSample>& samples);
  void updateObstacles(const ros::Time& stamp);
  void publish(const ros::Time& stamp, const core::StepReport& report);
  /// Bodies and obstacles (at most ~marker_rate), and the arrows of `impacts`; only while
  /// somebody subscribes to `markers`.
  void publishMarkers(const ros::Time& stamp, const ImpactArray& impacts);
  double toLine(const ros::Time& stamp) const { return (stamp - epoch_).toSec(); }
  void count(const std::string& what) { ++counters_[what]; }

  ros::NodeHandle node_;
  MonitorParams params_;
  core::Scene scene_;
  core::ImpactMonitor monitor_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  ros::Subscriber array_subscriber_;
  std::vector<ros::Subscriber> body_subscribers_;
  ros::Publisher impact_publisher_;
  ros::Publisher marker_publisher_;
  ros::WallTime last_scene_markers_;
  int next_impact_marker_ = 0;
  ros::WallTimer queue_timer_;
  std::deque<Pending> queue_;
  ros::Time epoch_;
  std::set<std::size_t> placed_obstacles_;  ///< tf-attached obstacles placed at least once
  std::map<std::string, std::uint64_t> counters_;
  std::vector<std::size_t> index_hints_;  ///< body index of each place of the last array
  /// Since the last diagnostics report: inputs, steps and their processing time (wall).
  struct Period {
    ros::WallTime start = ros::WallTime::now();
    std::uint64_t messages = 0, states = 0, steps = 0, impacts = 0;
    double step_seconds = 0.0, step_seconds_max = 0.0;
    double latency_seconds = 0.0, latency_seconds_max = 0.0;  ///< arrival to publication
    std::uint64_t latencies = 0;
    std::map<std::string, std::uint64_t> counters;  ///< counters_ at the period's start
  };
  Period period_;
  ThrottledWarning warnings_;
};

}  // namespace collision_response
