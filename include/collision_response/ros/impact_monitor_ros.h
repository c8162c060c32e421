// The impact monitor on ROS: body states in (any tf frame), impacts out.
#pragma once

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

  /// Reads `~transform_timeout` and the others; a bad value is an error naming it.
  static core::Expected<MonitorParams> load(const ros::NodeHandle& private_node);
};

class ImpactMonitorRos {
 public:
  /// Subscribes `body_states` and the bodies' own topics, advertises `impacts`.
  ImpactMonitorRos(ros::NodeHandle node, const core::Scene& scene, const MonitorParams& params);

  /// Counts of what the monitor did and dropped, by reason (for logs and diagnostics).
  const std::map<std::string, std::uint64_t>& counters() const { return counters_; }

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
  ros::WallTimer queue_timer_;
  std::deque<Pending> queue_;
  ros::Time epoch_;
  std::set<std::size_t> placed_obstacles_;  ///< tf-attached obstacles placed at least once
  std::map<std::string, std::uint64_t> counters_;
  std::vector<std::size_t> index_hints_;  ///< body index of each place of the last array
  ThrottledWarning warnings_;
};

}  // namespace collision_response
