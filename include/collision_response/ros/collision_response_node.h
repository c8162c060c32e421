// The collision_response node: loads the scene, serves the collision services and runs the
// impact monitor on the scene's bodies.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <ros/ros.h>

#include <boost/thread/recursive_mutex.hpp>

#include <memory>

#include "collision_response/ComputeCollision.h"
#include "collision_response/EstimateRestitution.h"
#include "collision_response/MonitorConfig.h"
#include "collision_response/core/materials.h"
#include "collision_response/ros/impact_monitor_ros.h"

namespace collision_response {

class CollisionResponseNode {
 public:
  /// `node` resolves topics (relative names), `private_node` the `~` parameters and services.
  CollisionResponseNode(const ros::NodeHandle& node, const ros::NodeHandle& private_node);

  /// Reads and validates `~scene` and the monitor's parameters, advertises the services and
  /// starts the monitor. On a bad parameter it logs the error (naming the parameter and the
  /// reason) and returns false.
  bool initialize();

 private:
  bool onComputeCollision(ComputeCollision::Request& request, ComputeCollision::Response& response);
  bool onEstimateRestitution(EstimateRestitution::Request& request,
                             EstimateRestitution::Response& response);
  void logScene(const core::Scene& scene, const MonitorParams& params) const;
  /// dynamic_reconfigure: checks each value as the scene file's; a refused value is put back
  /// to the one in use (in `config`, which the server then reports) with an error naming it.
  void onReconfigure(MonitorConfig& config, std::uint32_t level);

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  core::MaterialTable materials_ = core::MaterialTable::seed();
  std::unique_ptr<ImpactMonitorRos> monitor_;
  ros::ServiceServer compute_collision_server_;
  ros::ServiceServer estimate_restitution_server_;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;
  ros::WallTimer diagnostics_timer_;
  boost::recursive_mutex reconfigure_mutex_;  ///< the server's, so updateConfig is safe
  std::unique_ptr<dynamic_reconfigure::Server<MonitorConfig>> reconfigure_;
  MonitorConfig config_;  ///< the values in use
};

}  // namespace collision_response
