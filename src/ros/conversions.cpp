#include "collision_response/ros/conversions.h"

#include <tf2_eigen/tf2_eigen.h>

#include "collision_response/core/body_shape.h"

#include <cstdio>

namespace collision_response {

Eigen::Vector3d toEigen(const geometry_msgs::Point& point) {
  Eigen::Vector3d result;
  tf2::fromMsg(point, result);
  return result;
}

Eigen::Vector3d toEigen(const geometry_msgs::Vector3& vector) {
  Eigen::Vector3d result;
  tf2::fromMsg(vector, result);
  return result;
}

geometry_msgs::Vector3 toVector3Msg(const Eigen::Vector3d& vector) {
  geometry_msgs::Vector3 result;
  tf2::toMsg(vector, result);
  return result;
}

geometry_msgs::Point toPointMsg(const Eigen::Vector3d& point) { return tf2::toMsg(point); }

Eigen::Quaterniond toEigen(const geometry_msgs::Quaternion& quaternion) {
  return Eigen::Quaterniond(quaternion.w, quaternion.x, quaternion.y, quaternion.z);
}

geometry_msgs::Quaternion toQuaternionMsg(const Eigen::Quaterniond& quaternion) {
  geometry_msgs::Quaternion result;
  result.x = quaternion.x();
  result.y = quaternion.y();
  result.z = quaternion.z();
  result.w = quaternion.w();
  return result;
}

core::Body toCore(const collision_response::Body& msg) {
  core::Body body;
  body.id = msg.id;
  body.mass = msg.mass;
  body.radius = msg.radius;
  body.material = msg.material;
  body.position = toEigen(msg.position);
  body.velocity = toEigen(msg.velocity);
  body.angular_velocity = toEigen(msg.angular_velocity);
  body.size = toEigen(msg.size);
  body.length = msg.length;
  body.orientation = toEigen(msg.orientation);
  if (isGiven(msg.inertia_tensor)) {
    const InertiaTensor& given = msg.inertia_tensor;
    core::InertiaTensor tensor;
    tensor.ixx = given.ixx;
    tensor.iyy = given.iyy;
    tensor.izz = given.izz;
    tensor.ixy = given.ixy;
    tensor.ixz = given.ixz;
    tensor.iyz = given.iyz;
    body.inertia_tensor = tensor;
  }
  return body;
}

core::Expected<core::Body> bodyFromMessage(const collision_response::Body& msg,
                                           const std::string& prefix) {
  if (!msg.inertia.empty() && isGiven(msg.inertia_tensor)) {
    return core::Error{prefix + ".inertia", "is '" + msg.inertia + "' while " + prefix +
                                                ".inertia_tensor is given: give one (leave "
                                                "inertia empty; the tensor says how the mass is "
                                                "spread)"};
  }
  core::Body body = toCore(msg);
  const auto inertia = core::parseInertia(msg.inertia, prefix + ".inertia");
  if (!inertia) return inertia.error();
  body.inertia = *inertia;
  if (msg.shape.empty()) return body;
  const auto shape = core::parseBodyShape(msg.shape, prefix + ".shape");
  if (!shape) return shape.error();
  body.shape = *shape;
  return body;
}

bool isGiven(const InertiaTensor& tensor) {
  return !(tensor.ixx == 0.0 && tensor.iyy == 0.0 && tensor.izz == 0.0 && tensor.ixy == 0.0 &&
           tensor.ixz == 0.0 && tensor.iyz == 0.0);
}

std::optional<core::ImpactRecord> toImpactRecord(const Impact& impact,
                                                 const core::ImpactMonitor& monitor, double time) {
  const auto a = monitor.bodyIndex(impact.body_a);
  if (!a) return std::nullopt;
  core::ImpactRecord record;
  record.time = time;
  record.body_a = *a;
  const auto b = monitor.bodyIndex(impact.body_b);
  record.other_is_obstacle = !b;
  record.other = b ? *b : 0;
  record.contact_point = toEigen(impact.contact_point);
  record.normal = toEigen(impact.normal);
  record.restitution = impact.restitution;
  record.impulse = impact.impulse;
  record.friction_impulse = impact.friction_impulse;
  record.energy_lost = impact.energy_lost;
  record.oblique = impact.oblique;
  record.velocity_a_before = toEigen(impact.velocity_a_before.linear);
  record.velocity_a_after = toEigen(impact.velocity_a_after.linear);
  record.velocity_b_before = toEigen(impact.velocity_b_before.linear);
  record.velocity_b_after = toEigen(impact.velocity_b_after.linear);
  record.angular_velocity_a_before = toEigen(impact.velocity_a_before.angular);
  record.angular_velocity_a_after = toEigen(impact.velocity_a_after.angular);
  record.angular_velocity_b_before = toEigen(impact.velocity_b_before.angular);
  record.angular_velocity_b_after = toEigen(impact.velocity_b_after.angular);
  return record;
}

std::string formatStamp(const ros::Time& stamp) {
  char text[32];
  std::snprintf(text, sizeof text, "%u.%09u", stamp.sec, stamp.nsec);
  return text;
}

}  // namespace collision_response
