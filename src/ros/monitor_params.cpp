#include "collision_response/ros/monitor_params.h"

#include <ros/names.h>

#include <map>

#include "collision_response/core/validation.h"

namespace collision_response {
namespace {

using P = MonitorParams;

/// A key whose value another part of the node reads; here only its type is checked.
Key<P> typeOnly(const std::string& name, XmlRpc::XmlRpcValue::Type type, const char* what) {
  return {name, false,
          [type, what](const XmlRpc::XmlRpcValue& value, const std::string& field, P&) {
            if (value.getType() == type || (type == XmlRpc::XmlRpcValue::TypeDouble &&
                                            value.getType() == XmlRpc::XmlRpcValue::TypeInt)) {
              return core::Status(core::Ok{});
            }
            return core::Status(
                core::Error{field, std::string("must be ") + what + ", got " + typeName(value)});
          }};
}

}  // namespace

const KeyTable<MonitorParams>& MonitorParams::keys() {
  static const KeyTable<P> kKeys = {
      typeOnly("scene", XmlRpc::XmlRpcValue::TypeStruct, "a mapping (the scene)"),
      // A scene file's `player:` part (the scene player's), loaded beside `scene:`.
      typeOnly("player", XmlRpc::XmlRpcValue::TypeStruct, "a mapping (the scene player's)"),
      numberKey<P>(
          "transform_timeout", [](P& p) -> double& { return p.transform_timeout; },
          checkDurationOrZero),
      numberKey<P>(
          "frame_velocity_interval", [](P& p) -> double& { return p.frame_velocity_interval; },
          checkDuration),
      numberKey<P>(
          "obstacle_update_period", [](P& p) -> double& { return p.obstacle_update_period; },
          checkDurationOrZero),
      numberKey<P>(
          "body_timeout", [](P& p) -> double& { return p.body_timeout; }, checkDuration),
      numberKey<P>(
          "contact_tolerance", [](P& p) -> double& { return p.contact_tolerance; },
          core::checkContactTolerance),
      numberKey<P>(
          "clock_jump_back", [](P& p) -> double& { return p.clock_jump_back; }, checkDuration),
      numberKey<P>(
          "future_stamp_tolerance", [](P& p) -> double& { return p.future_stamp_tolerance; },
          checkDuration),
      countKey<P>(
          "queue_size", [](P& p) -> int& { return p.queue_size; }, 1),
      countKey<P>(
          "max_states", [](P& p) -> int& { return p.max_states; }, 1),
      numberKey<P>(
          "marker_rate", [](P& p) -> double& { return p.markers.rate; }, checkRate),
      numberKey<P>(
          "impact_marker_lifetime", [](P& p) -> double& { return p.markers.impact_lifetime; },
          checkDuration),
      numberKey<P>(
          "impulse_marker_scale", [](P& p) -> double& { return p.markers.impulse_scale; },
          checkPositive),
      numberKey<P>(
          "force_marker_scale", [](P& p) -> double& { return p.markers.force_scale; },
          checkPositive),
      numberKey<P>(
          "plane_marker_size", [](P& p) -> double& { return p.markers.plane_size; }, checkPositive),
      numberKey<P>(
          "contact_marker_diameter", [](P& p) -> double& { return p.markers.contact_diameter; },
          checkPositive),
      numberKey<P>(
          "diagnostic_period", [](P& p) -> double& { return p.diagnostic_period; }, checkDuration),
      typeOnly("detection", XmlRpc::XmlRpcValue::TypeString, "a string"),
      typeOnly("restitution_threshold", XmlRpc::XmlRpcValue::TypeDouble, "a number"),
      typeOnly("restitution_combine", XmlRpc::XmlRpcValue::TypeString, "a string"),
      numberKey<P>(
          "prediction_cpu_budget", [](P& p) -> double& { return p.prediction_cpu_budget; },
          checkDurationOrZero),
      numberKey<P>(
          "calibration_window", [](P& p) -> double& { return p.calibration_window; },
          checkDurationOrZero),
  };
  return kKeys;
}

core::Expected<MonitorParams> MonitorParams::load(const XmlRpc::XmlRpcValue& tree,
                                                  const std::string& ns) {
  MonitorParams params;
  if (tree.getType() == XmlRpc::XmlRpcValue::TypeInvalid) return params;  // nothing set
  if (auto status = readKeys(tree, keys(), ns, params); !status) return status.error();
  return params;
}

core::Status checkBodyTopics(const core::Scene& scene, const std::string& node_namespace,
                             const std::string& array_topic, const std::string& field) {
  std::map<std::string, std::size_t> body_of_topic;  // resolved topic -> first body
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const std::string& topic = scene.bodies[i].topic;
    if (topic.empty()) continue;
    const std::string key = joinKey(indexKey(joinKey(field, "bodies"), i), "topic");
    std::string why;
    if (!ros::names::validate(topic, why)) {
      return core::Error{key, "'" + topic + "' is not a valid topic name: " + why};
    }
    if (topic.front() == '~') {
      return core::Error{key,
                         "'" + topic + "' is a private name: give a relative or global topic name"};
    }
    std::string resolved;
    try {
      resolved = ros::names::resolve(node_namespace, topic);
    } catch (const std::exception& error) {
      return core::Error{key, "'" + topic + "' is not a valid topic name: " + error.what()};
    }
    if (resolved == array_topic) {
      return core::Error{key, "'" + topic + "' is " + array_topic +
                                  ", the topic of every body's states (BodyStateArray): give "
                                  "the body a topic of its own (BodyState)"};
    }
    const auto [first, inserted] = body_of_topic.emplace(resolved, i);
    if (!inserted) {
      return core::Error{key, "'" + topic + "' (" + resolved + ") is already the topic of '" +
                                  scene.bodies[first->second].id + "' (bodies[" +
                                  std::to_string(first->second) +
                                  "]): each body needs its own topic"};
    }
  }
  return core::Ok{};
}

}  // namespace collision_response
