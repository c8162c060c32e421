#include "collision_response/ros/frame_motion.h"

#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>

namespace collision_response {

Eigen::Vector3d FrameMotion::velocity(const Eigen::Vector3d& in_frame,
                                      const Eigen::Vector3d& velocity_in_frame) const {
  const Eigen::Vector3d offset = pose.linear() * in_frame;
  return pose.linear() * velocity_in_frame + linear_velocity + angular_velocity.cross(offset);
}

core::Expected<FrameMotion> lookupFrameMotion(const tf2::BufferCore& buffer,
                                              const std::string& fixed_frame,
                                              const std::string& frame, const ros::Time& stamp,
                                              const ros::Duration& interval) {
  FrameMotion motion;
  if (frame.empty() || frame == fixed_frame) return motion;
  try {
    const Eigen::Isometry3d now =
        tf2::transformToEigen(buffer.lookupTransform(fixed_frame, frame, stamp));
    const ros::Time earlier_stamp =
        stamp > ros::Time(0) + interval ? stamp - interval : ros::Time(0) + ros::Duration(1e-9);
    const Eigen::Isometry3d earlier =
        tf2::transformToEigen(buffer.lookupTransform(fixed_frame, frame, earlier_stamp));
    const double dt = (stamp - earlier_stamp).toSec();
    motion.pose = now;
    motion.linear_velocity = (now.translation() - earlier.translation()) / dt;
    // R_now = exp([w] dt) R_earlier: the rotation between the two, as an angle-axis, over dt.
    const Eigen::AngleAxisd turn(now.linear() * earlier.linear().transpose());
    motion.angular_velocity = turn.axis() * (turn.angle() / dt);
    return motion;
  } catch (const tf2::TransformException& error) {
    return core::Error{frame, "no transform to '" + fixed_frame + "' at " +
                                  std::to_string(stamp.toSec()) + ": " + error.what()};
  }
}

}  // namespace collision_response
