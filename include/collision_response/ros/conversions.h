// Message <-> core conversions (tf2_eigen for the vectors).
#pragma once

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Vector3.h>
#include <Eigen/Core>

#include "collision_response/Body.h"
#include "collision_response/core/body.h"

namespace collision_response {

Eigen::Vector3d toEigen(const geometry_msgs::Point& point);
Eigen::Vector3d toEigen(const geometry_msgs::Vector3& vector);
geometry_msgs::Vector3 toVector3Msg(const Eigen::Vector3d& vector);
geometry_msgs::Point toPointMsg(const Eigen::Vector3d& point);

/// Copies every field; validation is the core's (core::checkBody).
core::Body toCore(const collision_response::Body& msg);

}  // namespace collision_response
