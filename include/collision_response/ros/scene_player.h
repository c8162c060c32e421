// The scene player: moves the scene's bodies, publishes their states, applies the impacts it
// receives. It closes the loop with the monitor over real topics.
#pragma once

#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "collision_response/ImpactArray.h"
#include "collision_response/core/playback.h"
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

  /// Reads `~scene`, `~player/frames`, `~rate`, `~duration`, `~start_delay`,
  /// `~contact_tolerance`, `~report_restitution`; false (logged) on a bad value.
  bool initialize();

 private:
  void onTimer(const ros::TimerEvent& event);
  void onImpacts(const ImpactArray::ConstPtr& message);
  void publishStates(const ros::Time& time);
  /// Publishes on `apexes` each flight's highest point once it is past; with
  /// ~report_restitution, prints e = sqrt(h'/h) of each body's first bounce off the floor.
  void publishApexes(const ros::Time& time);
  double sinceStart(const ros::Time& time) const { return (time - start_).toSec(); }

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  core::Scene scene_;
  std::vector<MovingFrame> frames_;
  double rate_ = 100.0;
  double duration_ = 0.0;
  double start_delay_ = 1.0;
  double contact_tolerance_ = 1e-9;
  bool report_restitution_ = false;
  ros::Time created_;
  ros::Time start_;
  std::unique_ptr<core::Playback> playback_;  ///< from the start on (the bodies' motion)
  ros::Publisher state_publisher_;
  ros::Publisher apex_publisher_;
  ros::Subscriber impact_subscriber_;
  tf2_ros::TransformBroadcaster broadcaster_;
  ros::Timer timer_;
};

}  // namespace collision_response
