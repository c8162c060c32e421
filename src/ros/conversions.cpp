#include "collision_response/ros/conversions.h"

#include <tf2_eigen/tf2_eigen.h>

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

core::Body toCore(const collision_response::Body& msg) {
  core::Body body;
  body.id = msg.id;
  body.mass = msg.mass;
  body.radius = msg.radius;
  body.material = msg.material;
  body.position = toEigen(msg.position);
  body.velocity = toEigen(msg.velocity);
  body.angular_velocity = toEigen(msg.angular_velocity);
  return body;
}

}  // namespace collision_response
