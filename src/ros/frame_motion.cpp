#include "collision_response/ros/frame_motion.h"

#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>

#include <algorithm>

namespace collision_response {

Eigen::Vector3d FrameMotion::velocity(const Eigen::Vector3d& in_frame,
                                      const Eigen::Vector3d& velocity_in_frame) const {
  const Eigen::Vector3d offset = pose.linear() * in_frame;
  return pose.linear() * velocity_in_frame + linear_velocity + angular_velocity.cross(offset);
}

std::string tfErrorText(const std::string& what) {
  constexpr std::size_t kMaxLength = 300;
  const std::size_t end = what.find_last_not_of(" \n");
  const std::string whole = end == std::string::npos ? "" : what.substr(0, end + 1);
  std::string text = whole.substr(0, std::min(whole.find('\n'), kMaxLength));
  if (text.size() < whole.size()) text += " ... (tf's text cut here)";
  return text;
}

namespace {

/// The chord velocities of a frame between two of its poses `dt` apart: its origin's, and its
/// turning's (R_later = exp([w] dt) R_earlier: the rotation between them, as an angle-axis).
void chord(const Eigen::Isometry3d& later, const Eigen::Isometry3d& earlier, double dt,
           Eigen::Vector3d& linear, Eigen::Vector3d& angular) {
  linear = (later.translation() - earlier.translation()) / dt;
  const Eigen::AngleAxisd turn(later.linear() * earlier.linear().transpose());
  angular = turn.axis() * (turn.angle() / dt);
}

}  // namespace

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
    chord(now, earlier, dt, motion.linear_velocity, motion.angular_velocity);
    // A chord's velocity is the frame's half an interval back: with the chord before it, the
    // velocity now to second order in the interval, v1 + (v1 - v2) / 2 (exact at constant
    // velocity; a frame that accelerates, as a swinging arm's links do, is off by a third of its
    // jerk times the interval squared instead of half its acceleration times the interval).
    // Where tf has no pose that far back yet, the chord alone.
    if (earlier_stamp > ros::Time(0) + ros::Duration(dt)) {
      const ros::Time earliest_stamp = earlier_stamp - ros::Duration(dt);
      if (buffer.canTransform(fixed_frame, frame, earliest_stamp)) {
        const Eigen::Isometry3d earliest =
            tf2::transformToEigen(buffer.lookupTransform(fixed_frame, frame, earliest_stamp));
        Eigen::Vector3d linear_before, angular_before;
        chord(earlier, earliest, dt, linear_before, angular_before);
        motion.linear_velocity += 0.5 * (motion.linear_velocity - linear_before);
        motion.angular_velocity += 0.5 * (motion.angular_velocity - angular_before);
      }
    }
    return motion;
  } catch (const tf2::TransformException& error) {
    return core::Error{frame, "no transform to '" + fixed_frame + "' at " +
                                  std::to_string(stamp.toSec()) + ": " + tfErrorText(error.what())};
  }
}

}  // namespace collision_response
