#include "collision_response/ros/collision_response_node.h"

#include <cmath>
#include <exception>

#include "collision_response/core/validation.h"
#include "collision_response/ros/collision_services.h"
#include "collision_response/ros/parameters.h"
#include "collision_response/ros/scene_loader.h"

namespace collision_response {

CollisionResponseNode::CollisionResponseNode(const ros::NodeHandle& node,
                                             const ros::NodeHandle& private_node)
    : node_(node), private_node_(private_node) {}

CollisionResponseNode::~CollisionResponseNode() {
  if (service_spinner_) service_spinner_->stop();
  if (predict_spinner_) predict_spinner_->stop();
  predict_impacts_server_.shutdown();
  if (diagnostics_spinner_) diagnostics_spinner_->stop();
  diagnostics_timer_.stop();
  compute_collision_server_.shutdown();
  estimate_restitution_server_.shutdown();
}

bool CollisionResponseNode::initialize() {
  // Nothing a parameter holds may escape as an exception (a node would abort with "terminate
  // called", a nodelet manager only say "Failed to load"): every error is named and logged.
  try {
    return start();
  } catch (const std::exception& error) {
    ROS_FATAL_STREAM("collision_response: not started: " << error.what());
    return false;
  }
}

bool CollisionResponseNode::start() {
  // The whole private namespace at once: every parameter read with its type checked, and one
  // the node does not know refused by name (a typo would otherwise be a silent default).
  const std::string ns = private_node_.getNamespace();
  XmlRpc::XmlRpcValue tree;
  if (!ros::param::get(ns, tree)) tree = XmlRpc::XmlRpcValue();
  auto params = MonitorParams::load(tree, ns);
  if (!params) {
    ROS_FATAL_STREAM("collision_response: bad parameter: " << params.error().message());
    return false;
  }
  if (tree.getType() == XmlRpc::XmlRpcValue::TypeStruct && tree.hasMember("scene")) {
    std::vector<std::string> warnings;
    auto scene = loadScene(tree["scene"], joinKey(ns, "scene"),
                           parameterServerUrdf(joinKey(ns, "scene")), &warnings);
    if (!scene) {
      ROS_FATAL_STREAM("collision_response: bad scene: " << scene.error().message());
      return false;
    }
    for (const std::string& left_out : warnings) {
      ROS_WARN_STREAM("collision_response: scene: " << left_out);
    }
    if (auto status = checkBodyTopics(*scene, node_.getNamespace(),
                                      node_.resolveName("body_states"), joinKey(ns, "scene"));
        !status) {
      ROS_FATAL_STREAM("collision_response: bad scene: " << status.error().message());
      return false;
    }
    materials_ = std::make_shared<const core::MaterialTable>(scene->materials);
    logScene(*scene, *params);
    monitor_ = std::make_unique<ImpactMonitorRos>(node_, *scene, *params);

    // Diagnostics, named after this node (or nodelet): ~diagnostic_period s apart (default 1).
    // The Updater would re-read ~diagnostic_period itself, unchecked, at every publication, and
    // a value a ros::Duration cannot hold (rosparam set ~diagnostic_period 1e10) thrown from its
    // timer aborted the node. So it is given a namespace of its own, where it finds no period
    // (its own default then never matters), and the node keeps the period: it re-reads
    // ~diagnostic_period with the check of start-up and calls force_update when the period is
    // over (updateDiagnostics).
    diagnostic_period_ = params->diagnostic_period;
    next_diagnostics_ = ros::Time::now().toSec() + diagnostic_period_;
    diagnostics_ = std::make_unique<diagnostic_updater::Updater>(
        node_, ros::NodeHandle(private_node_, "diagnostic_updater"), private_node_.getNamespace());
    diagnostics_->setHardwareID("none");
    diagnostics_->add("impact monitor", monitor_.get(), &ImpactMonitorRos::diagnose);
    // On a queue and thread of their own: published whatever an update is doing (a long
    // one shows as "update in progress (s)").
    ros::NodeHandle diagnostics_node(node_);
    diagnostics_node.setCallbackQueue(&diagnostics_queue_);
    diagnostics_timer_ = diagnostics_node.createWallTimer(
        ros::WallDuration(0.1), [this](const ros::WallTimerEvent&) { updateDiagnostics(); });
    diagnostics_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &diagnostics_queue_);
    diagnostics_spinner_->start();

    // Live tuning, starting from the scene's values.
    config_.detection = core::toString(scene->detection);
    config_.restitution_threshold = scene->restitution_threshold;
    config_.restitution_combine = core::toString(scene->materials.combineRule());
    reconfigure_ = std::make_unique<dynamic_reconfigure::Server<MonitorConfig>>(reconfigure_mutex_,
                                                                                private_node_);
    reconfigure_->updateConfig(config_);
    reconfigure_->setCallback(
        [this](MonitorConfig& config, std::uint32_t level) { onReconfigure(config, level); });
    // Predictions on their own queue and thread: one at a time, never on the monitor's.
    ros::NodeHandle predict_node(private_node_);
    predict_node.setCallbackQueue(&predict_queue_);
    predict_impacts_server_ = predict_node.advertiseService(
        "predict_impacts", &CollisionResponseNode::onPredictImpacts, this);
    predict_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &predict_queue_);
    predict_spinner_->start();
  } else {
    ROS_WARN_STREAM("collision_response: no " << joinKey(ns, "scene")
                                              << " parameter: serving the services with the "
                                                 "seed's materials, no impact monitor");
  }

  // The services on their own queue and thread: a long step of the monitor never delays them.
  ros::NodeHandle service_node(private_node_);
  service_node.setCallbackQueue(&service_queue_);
  compute_collision_server_ = service_node.advertiseService(
      "compute_collision", &CollisionResponseNode::onComputeCollision, this);
  estimate_restitution_server_ = service_node.advertiseService(
      "estimate_restitution", &CollisionResponseNode::onEstimateRestitution, this);
  service_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &service_queue_);
  service_spinner_->start();
  return true;
}

bool CollisionResponseNode::onPredictImpacts(PredictImpacts::Request& request,
                                             PredictImpacts::Response& response) {
  try {
    monitor_->predict(request, response);
  } catch (const std::exception& error) {
    response = PredictImpacts::Response();
    response.message = std::string("internal error: ") + error.what();
    ROS_ERROR_STREAM_THROTTLE(1.0, "predict_impacts: " << response.message);
  }
  return true;  // a refused request is answered (success false), not failed
}

std::shared_ptr<const core::MaterialTable> CollisionResponseNode::materials() const {
  std::lock_guard<std::mutex> lock(materials_mutex_);
  return materials_;
}

void CollisionResponseNode::updateDiagnostics() {
  rereadDiagnosticPeriod();
  // In doubles: now + a period of up to 2^31 s may lie past a ros::Time's end (2^32 s).
  const double now = ros::Time::now().toSec();
  if (now < next_diagnostics_) return;
  next_diagnostics_ = now + diagnostic_period_;
  diagnostics_->force_update();
}

void CollisionResponseNode::rereadDiagnosticPeriod() {
  const std::string field = joinKey(private_node_.getNamespace(), "diagnostic_period");
  XmlRpc::XmlRpcValue value;
  if (!private_node_.getParamCached("diagnostic_period", value)) return;  // unset: kept
  MonitorParams read;
  read.diagnostic_period = diagnostic_period_;
  if (auto status = readKey(value, MonitorParams::keys(), "diagnostic_period", field, read);
      !status) {
    if (status.error().message() != period_refused_) {
      period_refused_ = status.error().message();
      ROS_WARN_STREAM("collision_response: refused a new value: "
                      << period_refused_ << "; kept " << core::formatNumber(diagnostic_period_)
                      << " s");
    }
    return;
  }
  period_refused_.clear();
  if (read.diagnostic_period != diagnostic_period_) {
    // As the Updater did: the next publication moves by the change of the period.
    next_diagnostics_ += read.diagnostic_period - diagnostic_period_;
    diagnostic_period_ = read.diagnostic_period;
  }
}

void CollisionResponseNode::logScene(const core::Scene& scene, const MonitorParams& params) const {
  ROS_INFO_STREAM("collision_response: scene: fixed_frame "
                  << scene.fixed_frame << ", detection " << core::toString(scene.detection)
                  << ", effects " << core::toString(scene.effects));
  ROS_INFO_STREAM("collision_response: restitution_threshold "
                  << scene.restitution_threshold << " m/s, restitution_combine "
                  << core::toString(scene.materials.combineRule()) << ", "
                  << scene.materials.names().size() << " materials");
  if (scene.effects.gravity) {
    // Stepped clusters act with gravity only (README, "Scene file").
    ROS_INFO_STREAM("collision_response: stepped_cluster_min_bodies "
                    << scene.stepped_cluster_min_bodies
                    << (scene.stepped_cluster_min_bodies == 0 ? " (never)" : "")
                    << ", stepped_cluster_time_step " << scene.stepped_cluster_time_step << " s");
  }
  ROS_INFO_STREAM("collision_response: " << scene.bodies.size() << " bodies, "
                                         << scene.obstacles.size() << " obstacles");
  ROS_INFO_STREAM("collision_response: transform_timeout "
                  << params.transform_timeout << " s, frame_velocity_interval "
                  << params.frame_velocity_interval << " s, body_timeout " << params.body_timeout
                  << " s, contact_tolerance " << params.contact_tolerance << ", clock_jump_back "
                  << params.clock_jump_back << " s, future_stamp_tolerance "
                  << params.future_stamp_tolerance << " s, queue_size " << params.queue_size
                  << ", max_states " << params.max_states << ", prediction_cpu_budget "
                  << params.prediction_cpu_budget << " s, calibration_window "
                  << params.calibration_window << " s");
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
  if (auto status = core::checkRestitutionThreshold(config.restitution_threshold,
                                                    prefix + "restitution_threshold");
      !status) {
    ROS_ERROR_STREAM("collision_response: reconfigure refused: "
                     << status.error().message() << "; kept " << config_.restitution_threshold);
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
  if (materials()->combineRule() != *rule) {
    auto table = std::make_shared<core::MaterialTable>(*materials());
    table->setCombineRule(*rule);
    std::lock_guard<std::mutex> lock(materials_mutex_);
    materials_ = std::move(table);
  }
  config_ = config;
}

// Both callbacks answer every request: a refused one with success = false and the reason. No
// exception leaves a callback (roscpp would drop the answer and the caller would see a failure).
bool CollisionResponseNode::onComputeCollision(ComputeCollision::Request& request,
                                               ComputeCollision::Response& response) {
  try {
    answerComputeCollision(request, *materials(), response);
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
    if (request.body.empty()) {
      answerEstimateRestitution(request, *materials(), response);
    } else if (!monitor_) {
      response = EstimateRestitution::Response();
      response.message = "body: '" + request.body +
                         "': no ~scene loaded, so the node tracks no body (the drop test, body "
                         "empty, needs none)";
    } else {
      monitor_->estimateRestitution(request, response);  // live, from the tracked states
    }
  } catch (const std::exception& error) {
    response = EstimateRestitution::Response();
    response.message = std::string("internal error: ") + error.what();
    ROS_ERROR_STREAM_THROTTLE(1.0, "estimate_restitution: " << response.message);
  }
  return true;
}

}  // namespace collision_response
