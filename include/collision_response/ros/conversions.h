// Message <-> core conversions (tf2_eigen for the vectors).
#pragma once

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Vector3.h>
#include <ros/time.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string>

#include "collision_response/Body.h"
#include "collision_response/Impact.h"
#include "collision_response/InertiaTensor.h"
#include "collision_response/core/body.h"
#include "collision_response/core/monitor.h"

namespace collision_response {

Eigen::Vector3d toEigen(const geometry_msgs::Point& point);
Eigen::Vector3d toEigen(const geometry_msgs::Vector3& vector);
geometry_msgs::Vector3 toVector3Msg(const Eigen::Vector3d& vector);
geometry_msgs::Point toPointMsg(const Eigen::Vector3d& point);
/// The quaternion as given (not normalised: an all-zero one stays zero, "not given").
Eigen::Quaterniond toEigen(const geometry_msgs::Quaternion& quaternion);
geometry_msgs::Quaternion toQuaternionMsg(const Eigen::Quaterniond& quaternion);

/// Copies every field but the strings parsed by name (`inertia`, `shape`: the caller's, which
/// can name their errors); an all-zero inertia_tensor is none (isGiven). Validation is the
/// core's (core::checkBody, core::checkBodyShape).
core::Body toCore(const collision_response::Body& msg);
/// A tensor with an entry other than 0 (a NaN too): given; all zero: not given.
bool isGiven(const InertiaTensor& tensor);
/// toCore, and the fields given by name parsed into it: `inertia` (empty: solid; must be empty
/// where inertia_tensor is given, which says how the mass is spread) and `shape` (empty: a
/// sphere), each error naming `prefix`.field. The values are not checked otherwise.
core::Expected<core::Body> bodyFromMessage(const collision_response::Body& msg,
                                           const std::string& prefix);

/// The record of an impact message, indexed as `monitor` indexes its bodies, at `time` on the
/// caller's time line: what core::Playback::applyImpact takes. Empty when body_a is not one of
/// the monitor's bodies; body_b may be an obstacle (or anything else that is not a body).
std::optional<core::ImpactRecord> toImpactRecord(const Impact& impact,
                                                 const core::ImpactMonitor& monitor, double time);

/// "1712345678.000000001": seconds and nanoseconds, exact.
std::string formatStamp(const ros::Time& stamp);

}  // namespace collision_response
