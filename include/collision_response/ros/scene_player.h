// The scene player: moves the scene's bodies, publishes their states, applies the impacts it
// receives. It closes the loop with the monitor over real topics.
#pragma once

#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "collision_response/ImpactArray.h"
#include "collision_response/core/scene.h"

namespace collision_response {

/// A frame the player moves in a straight line (for tf-attached obstacles: a paddle).
struct MovingFrame {
  std::string frame;
  std::string parent;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< m, at the start, in parent
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< m/s, in parent
};

class ScenePlayer {
 public:
  ScenePlayer(const ros::NodeHandle& node, const ros::NodeHandle& private_node);

  /// Reads `~scene`, `~player/frames`, `~rate`, `~duration`, `~start_delay`; false (logged)
  /// on a bad value.
  bool initialize();

 private:
  /// Straight-line motion since `start`.
  struct Segment {
    ros::Time start;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  };
  Eigen::Vector3d positionAt(const Segment& segment, const ros::Time& time) const;
  void onTimer(const ros::TimerEvent& event);
  void onImpacts(const ImpactArray::ConstPtr& message);
  void applyImpact(const std::string& id, const ros::Time& stamp, const Eigen::Vector3d& centre,
                   const Eigen::Vector3d& velocity_after);
  void publishStates(const ros::Time& time);

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  core::Scene scene_;
  std::vector<MovingFrame> frames_;
  double rate_ = 100.0;
  double duration_ = 0.0;
  double start_delay_ = 1.0;
  ros::Time created_;
  ros::Time start_;
  bool started_ = false;
  std::map<std::string, Segment> segments_;
  std::map<std::string, double> radius_;
  ros::Publisher state_publisher_;
  ros::Subscriber impact_subscriber_;
  tf2_ros::TransformBroadcaster broadcaster_;
  ros::Timer timer_;
};

}  // namespace collision_response
