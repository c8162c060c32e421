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
#include "collision_response/core/motion.h"
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
  /// Motion since `start` in closed form: a straight line, a parabola under gravity, or a slide
  /// along the plane the body rests on (core/motion.h, the monitor's own model).
  struct Segment {
    ros::Time start;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
    bool apex_published = false;  ///< its highest point (against gravity) has been published
  };
  /// A new segment from `start`, under gravity, or resting on a fixed plane when it touches one
  /// slowly (core::restingPlane).
  Segment makeSegment(const core::BodySpec& body, const ros::Time& start,
                      const Eigen::Vector3d& position, const Eigen::Vector3d& velocity) const;
  Eigen::Vector3d positionAt(const Segment& segment, const ros::Time& time) const;
  Eigen::Vector3d velocityAt(const Segment& segment, const ros::Time& time) const;
  void onTimer(const ros::TimerEvent& event);
  void onImpacts(const ImpactArray::ConstPtr& message);
  void applyImpact(const std::string& id, const ros::Time& stamp, const Eigen::Vector3d& centre,
                   const Eigen::Vector3d& velocity_after);
  void publishStates(const ros::Time& time);
  /// Publishes on `apexes` each segment's highest point once it is past; with
  /// ~report_restitution, prints e = sqrt(h'/h) of each body's first bounce off a plane.
  void publishApexes(const ros::Time& time);

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  core::Scene scene_;
  std::vector<MovingFrame> frames_;
  double rate_ = 100.0;
  double duration_ = 0.0;
  double start_delay_ = 1.0;
  double contact_tolerance_ = 1e-9;
  bool report_restitution_ = false;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();  ///< zero without the gravity effect
  std::vector<core::Plane> fixed_planes_;
  std::vector<std::string> fixed_plane_material_;
  std::map<std::string, const core::BodySpec*> body_spec_;
  std::map<std::string, int> bounces_;  ///< impacts seen per body, for the restitution report
  ros::Time created_;
  ros::Time start_;
  bool started_ = false;
  std::map<std::string, Segment> segments_;
  std::map<std::string, double> radius_;
  ros::Publisher state_publisher_;
  ros::Publisher apex_publisher_;
  ros::Subscriber impact_subscriber_;
  tf2_ros::TransformBroadcaster broadcaster_;
  ros::Timer timer_;
};

}  // namespace collision_response
