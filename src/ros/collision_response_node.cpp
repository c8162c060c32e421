#include "collision_response/ros/collision_response_node.h"

#include <exception>

#include "collision_response/ros/collision_services.h"
#include "collision_response/ros/scene_loader.h"

namespace collision_response {

CollisionResponseNode::CollisionResponseNode(const ros::NodeHandle& node,
                                             const ros::NodeHandle& private_node)
    : node_(node), private_node_(private_node) {}

bool CollisionResponseNode::initialize() {
  const std::string scene_key = private_node_.resolveName("scene");
  XmlRpc::XmlRpcValue scene;
  if (private_node_.getParam("scene", scene)) {
    auto materials = loadMaterials(scene, scene_key);
    if (!materials) {
      ROS_FATAL_STREAM("collision_response: bad scene: " << materials.error().message());
      return false;
    }
    materials_ = std::move(materials.value());
  } else {
    ROS_WARN_STREAM("collision_response: no " << scene_key
                                              << " parameter; using the seed's materials only");
  }
  ROS_INFO_STREAM("collision_response: " << materials_.names().size()
                                         << " materials, restitution_combine: "
                                         << core::toString(materials_.combineRule()));

  compute_collision_server_ = private_node_.advertiseService(
      "compute_collision", &CollisionResponseNode::onComputeCollision, this);
  estimate_restitution_server_ = private_node_.advertiseService(
      "estimate_restitution", &CollisionResponseNode::onEstimateRestitution, this);
  return true;
}

// Both callbacks answer every request: a refused one with success = false and the reason. No
// exception leaves a callback (roscpp would drop the answer and the caller would see a failure).
bool CollisionResponseNode::onComputeCollision(ComputeCollision::Request& request,
                                               ComputeCollision::Response& response) {
  try {
    answerComputeCollision(request, materials_, response);
  } catch (const std::exception& error) {
    response = ComputeCollision::Response();
    response.message = std::string("internal error: ") + error.what();
    ROS_ERROR_STREAM_THROTTLE(1.0, "compute_collision: " << response.message);
  }
  return true;
}

bool CollisionResponseNode::onEstimateRestitution(EstimateRestitution::Request& request,
                                                  EstimateRestitution::Response& response) {
  try {
    answerEstimateRestitution(request, materials_, response);
  } catch (const std::exception& error) {
    response = EstimateRestitution::Response();
    response.message = std::string("internal error: ") + error.what();
    ROS_ERROR_STREAM_THROTTLE(1.0, "estimate_restitution: " << response.message);
  }
  return true;
}

}  // namespace collision_response
