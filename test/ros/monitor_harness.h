// What the monitor rostests share: publishing states and transforms, collecting impacts and the
// node's warnings over real topics.
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "collision_response/BodyState.h"
#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"

namespace collision_response::testing {

/// One body's state to publish: position and velocity given in `frame`.
struct StateSpec {
  std::string id;
  Eigen::Vector3d position;
  Eigen::Vector3d velocity;
  std::string frame = "world";
};

inline geometry_msgs::Vector3 vector3(const Eigen::Vector3d& v) {
  geometry_msgs::Vector3 m;
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
  return m;
}

inline Eigen::Vector3d eigen(const geometry_msgs::Vector3& v) { return {v.x, v.y, v.z}; }
inline Eigen::Vector3d eigen(const geometry_msgs::Point& p) { return {p.x, p.y, p.z}; }

inline BodyState makeState(const ros::Time& stamp, const StateSpec& spec) {
  BodyState state;
  state.header.stamp = stamp;
  state.header.frame_id = spec.frame;
  state.id = spec.id;
  state.pose.position.x = spec.position.x();
  state.pose.position.y = spec.position.y();
  state.pose.position.z = spec.position.z();
  state.pose.orientation.w = 1.0;
  state.twist.linear = vector3(spec.velocity);
  return state;
}

inline geometry_msgs::TransformStamped makeTransform(const ros::Time& stamp,
                                                     const std::string& parent,
                                                     const std::string& child,
                                                     const Eigen::Isometry3d& pose) {
  geometry_msgs::TransformStamped transform;
  transform.header.stamp = stamp;
  transform.header.frame_id = parent;
  transform.child_frame_id = child;
  transform.transform.translation = vector3(pose.translation());
  const Eigen::Quaterniond rotation(pose.linear());
  transform.transform.rotation.x = rotation.x();
  transform.transform.rotation.y = rotation.y();
  transform.transform.rotation.z = rotation.z();
  transform.transform.rotation.w = rotation.w();
  return transform;
}

class MonitorHarness {
 public:
  MonitorHarness() {
    states_ = node_.advertise<BodyStateArray>("body_states", 100);
    impacts_ = node_.subscribe("impacts", 100, &MonitorHarness::onImpacts, this);
    rosout_ = node_.subscribe("/rosout", 1000, &MonitorHarness::onLog, this);
  }

  /// Waits until the node listens to body_states and we hear its impacts and its /rosout. Any
  /// publisher of /rosout (this test node's own log is one) is not enough: a warning the node
  /// logs before our link to it is up is lost, so every publisher the master names must be
  /// linked, the node among them.
  bool connect(double timeout = 20.0, const std::string& node = "/collision_response") {
    return waitFor(
        [&] {
          const std::vector<std::string> loggers = publishersOf("/rosout");
          const bool node_logs =
              std::find(loggers.begin(), loggers.end(), node) != loggers.end();
          return states_.getNumSubscribers() > 0 && impacts_.getNumPublishers() > 0 &&
                 node_logs && rosout_.getNumPublishers() >= loggers.size();
        },
        timeout);
  }

  /// The nodes the master lists as publishing `topic` (empty when it cannot be asked).
  static std::vector<std::string> publishersOf(const std::string& topic) {
    XmlRpc::XmlRpcValue args, result, payload;
    args[0] = ros::this_node::getName();
    std::vector<std::string> nodes;
    if (!ros::master::execute("getSystemState", args, result, payload, false)) return nodes;
    if (payload.getType() != XmlRpc::XmlRpcValue::TypeArray || payload.size() < 1) return nodes;
    XmlRpc::XmlRpcValue& publications = payload[0];
    for (int i = 0; i < publications.size(); ++i) {
      if (static_cast<std::string>(publications[i][0]) != topic) continue;
      for (int j = 0; j < publications[i][1].size(); ++j) {
        nodes.push_back(static_cast<std::string>(publications[i][1][j]));
      }
    }
    return nodes;
  }

  void publish(const ros::Time& stamp, const std::vector<StateSpec>& specs) {
    BodyStateArray array;
    array.header.stamp = stamp;
    for (const StateSpec& spec : specs) array.states.push_back(makeState(stamp, spec));
    states_.publish(array);
  }

  void publishRaw(const BodyStateArray& array) { states_.publish(array); }

  /// Spins until `done` or the timeout (s); true when done.
  static bool waitFor(const std::function<bool()>& done, double timeout) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
    while (ros::ok() && ros::WallTime::now() < end) {
      ros::spinOnce();
      if (done()) return true;
      ros::WallDuration(0.005).sleep();
    }
    ros::spinOnce();
    return done();
  }

  /// Impacts involving `body` received so far.
  std::vector<Impact> impactsOf(const std::string& body) const {
    std::vector<Impact> found;
    for (const Impact& impact : impacts_received_) {
      if (impact.body_a == body || impact.body_b == body) found.push_back(impact);
    }
    return found;
  }

  bool waitForImpact(const std::string& body, double timeout = 5.0) {
    return waitFor([&] { return !impactsOf(body).empty(); }, timeout);
  }

  /// A warning (or worse) from the node whose text contains every one of `words`.
  bool waitForWarning(const std::vector<std::string>& words, double timeout = 5.0,
                      const std::string& node = "/collision_response") {
    return waitFor([&] { return countWarnings(words, 0, node) > 0; }, timeout);
  }

  /// Warnings (or worse) from `node` containing every one of `words`, among the logs received
  /// from the `since`-th on.
  std::size_t countWarnings(const std::vector<std::string>& words, std::size_t since = 0,
                            const std::string& node = "/collision_response") const {
    std::size_t count = 0;
    for (std::size_t i = since; i < logs_.size(); ++i) {
      const rosgraph_msgs::Log& log = logs_[i];
      bool all = log.level >= rosgraph_msgs::Log::WARN && log.name == node;
      for (const std::string& word : words) all = all && log.msg.find(word) != std::string::npos;
      count += all ? 1 : 0;
    }
    return count;
  }
  std::size_t logCount() const { return logs_.size(); }

  std::size_t impactCount() const { return impacts_received_.size(); }
  const std::vector<Impact>& impacts() const { return impacts_received_; }
  ros::NodeHandle& node() { return node_; }

 private:
  void onImpacts(const ImpactArray::ConstPtr& message) {
    for (const Impact& impact : message->impacts) impacts_received_.push_back(impact);
  }
  void onLog(const rosgraph_msgs::Log::ConstPtr& log) { logs_.push_back(*log); }

  ros::NodeHandle node_;
  ros::Publisher states_;
  ros::Subscriber impacts_;
  ros::Subscriber rosout_;
  std::vector<Impact> impacts_received_;
  std::vector<rosgraph_msgs::Log> logs_;
};

/// A stamp with whole nanoseconds and room before it (the monitor's time line starts there).
inline ros::Time baseStamp() {
  const ros::Time now = ros::Time::now();
  return ros::Time(now.sec + 1, 0);
}

}  // namespace collision_response::testing
