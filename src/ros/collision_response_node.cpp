#include "collision_response/ros/collision_response_node.h"

#include <cmath>
#include <exception>

#include "collision_response/core/validation.h"
#include "collision_response/ros/collision_services.h"
#include "collision_response/ros/scene_loader.h"

namespace collision_response {

CollisionResponseNode::CollisionResponseNode(const ros::NodeHandle& node,
                                             const ros::NodeHandle& private_node)
    : node_(node), private_node_(private_node) {}

bool CollisionResponseNode::initialize() {
  const std::string scene_key = private_node_.resolveName("scene");
  XmlRpc::XmlRpcValue scene_value;
  if (private_node_.getParam("scene", scene_value)) {
    auto scene = loadScene(scene_value, scene_key);
    if (!scene) {
      ROS_FATAL_STREAM("collision_response: bad scene: " << scene.error().message());
      return false;
    }
    auto params = MonitorParams::load(private_node_);
    if (!params) {
      ROS_FATAL_STREAM("collision_response: bad parameter: " << params.error().message());
      return false;
    }
    materials_ = scene->materials;
    logScene(*scene, *params);
    monitor_ = std::make_unique<ImpactMonitorRos>(node_, *scene, *params);

    // Diagnostics, named after this node (or nodelet): ~diagnostic_period s apart (default 1).
    diagnostics_ = std::make_unique<diagnostic_updater::Updater>(node_, private_node_,
                                                                 private_node_.getNamespace());
    diagnostics_->setHardwareID("none");
    diagnostics_->add("impact monitor", monitor_.get(), &ImpactMonitorRos::diagnose);
    diagnostics_timer_ = node_.createWallTimer(
        ros::WallDuration(0.1), [this](const ros::WallTimerEvent&) { diagnostics_->update(); });

    // Live tuning, starting from the scene's values.
    config_.detection = core::toString(scene->detection);
    config_.restitution_threshold = scene->restitution_threshold;
    config_.restitution_combine = core::toString(scene->materials.combineRule());
    reconfigure_ = std::make_unique<dynamic_reconfigure::Server<MonitorConfig>>(reconfigure_mutex_,
                                                                                private_node_);
    reconfigure_->updateConfig(config_);
    reconfigure_->setCallback(
        [this](MonitorConfig& config, std::uint32_t level) { onReconfigure(config, level); });
  } else {
    ROS_WARN_STREAM("collision_response: no " << scene_key
                                              << " parameter: serving the services with the "
                                                 "seed's materials, no impact monitor");
  }

  compute_collision_server_ = private_node_.advertiseService(
      "compute_collision", &CollisionResponseNode::onComputeCollision, this);
  estimate_restitution_server_ = private_node_.advertiseService(
      "estimate_restitution", &CollisionResponseNode::onEstimateRestitution, this);
  return true;
}

void CollisionResponseNode::logScene(const core::Scene& scene, const MonitorParams& params) const {
  ROS_INFO_STREAM("collision_response: scene: fixed_frame "
                  << scene.fixed_frame << ", detection " << core::toString(scene.detection)
                  << ", effects " << core::toString(scene.effects));
  ROS_INFO_STREAM("collision_response: restitution_threshold "
                  << scene.restitution_threshold << " m/s, restitution_combine "
                  << core::toString(scene.materials.combineRule()) << ", "
                  << scene.materials.names().size() << " materials");
  ROS_INFO_STREAM("collision_response: " << scene.bodies.size() << " bodies, "
                                         << scene.obstacles.size() << " obstacles");
  ROS_INFO_STREAM("collision_response: transform_timeout "
                  << params.transform_timeout << " s, frame_velocity_interval "
                  << params.frame_velocity_interval << " s, body_timeout " << params.body_timeout
                  << " s, contact_tolerance " << params.contact_tolerance << ", clock_jump_back "
                  << params.clock_jump_back << " s, queue_size " << params.queue_size
                  << ", max_states " << params.max_states);
}

void CollisionResponseNode::onReconfigure(MonitorConfig& config, std::uint32_t /*level*/) {
  const std::string prefix = private_node_.getNamespace() + "/";
  auto detection = core::parseDetection(config.detection, prefix + "detection");
  if (!detection) {
    ROS_ERROR_STREAM("collision_response: reconfigure refused: " << detection.error().message()
                                                                 << "; kept " << config_.detection);
    config.detection = config_.detection;
    detection = core::parseDetection(config.detection, prefix + "detection");
  }
  auto rule = core::parseCombineRule(config.restitution_combine, prefix + "restitution_combine");
  if (!rule) {
    ROS_ERROR_STREAM("collision_response: reconfigure refused: "
                     << rule.error().message() << "; kept " << config_.restitution_combine);
    config.restitution_combine = config_.restitution_combine;
    rule = core::parseCombineRule(config.restitution_combine, prefix + "restitution_combine");
  }
  if (!std::isfinite(config.restitution_threshold) || config.restitution_threshold < 0.0) {
    ROS_ERROR_STREAM("collision_response: reconfigure refused: "
                     << prefix << "restitution_threshold: must be a finite number >= 0 m/s, got "
                     << core::formatNumber(config.restitution_threshold) << "; kept "
                     << config_.restitution_threshold);
    config.restitution_threshold = config_.restitution_threshold;
  }
  if (config.detection != config_.detection ||
      config.restitution_threshold != config_.restitution_threshold ||
      config.restitution_combine != config_.restitution_combine) {
    ROS_INFO_STREAM("collision_response: reconfigured: detection "
                    << config.detection << ", restitution_threshold "
                    << config.restitution_threshold << " m/s, restitution_combine "
                    << config.restitution_combine);
  }
  monitor_->tune(*detection, config.restitution_threshold, *rule);
  materials_.setCombineRule(*rule);
  config_ = config;
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
