// The collision_response node: loads the scene and serves the collision services.
#pragma once

#include <ros/ros.h>

#include "collision_response/ComputeCollision.h"
#include "collision_response/EstimateRestitution.h"
#include "collision_response/core/materials.h"

namespace collision_response {

class CollisionResponseNode {
 public:
  /// `node` resolves topics (relative names), `private_node` the `~` parameters and services.
  CollisionResponseNode(const ros::NodeHandle& node, const ros::NodeHandle& private_node);

  /// Reads and validates `~scene`, advertises the services. On a bad scene it logs the error
  /// (naming the parameter and the reason) and returns false.
  bool initialize();

 private:
  bool onComputeCollision(ComputeCollision::Request& request, ComputeCollision::Response& response);
  bool onEstimateRestitution(EstimateRestitution::Request& request,
                             EstimateRestitution::Response& response);

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  core::MaterialTable materials_ = core::MaterialTable::seed();
  ros::ServiceServer compute_collision_server_;
  ros::ServiceServer estimate_restitution_server_;
};

}  // namespace collision_response
