#include "collision_response/ros/frame_motion.h"

#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>

#include <algorithm>
#include <unordered_set>

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

namespace {

/// A frame's motion from its poses: `pose_at(t)` (fixed <- frame at t; throws
/// tf2::TransformException when there is none) at `stamp`, `stamp - interval` and, where
/// `has(t)`, `stamp - 2 interval`: see lookupFrameMotion.
template <class PoseAt, class Has>
FrameMotion motionFrom(PoseAt pose_at, Has has, const ros::Time& stamp,
                       const ros::Duration& interval) {
  FrameMotion motion;
  const Eigen::Isometry3d now = pose_at(stamp);
  const ros::Time earlier_stamp =
      stamp > ros::Time(0) + interval ? stamp - interval : ros::Time(0) + ros::Duration(1e-9);
  const Eigen::Isometry3d earlier = pose_at(earlier_stamp);
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
    if (has(earliest_stamp)) {
      const Eigen::Isometry3d earliest = pose_at(earliest_stamp);
      Eigen::Vector3d linear_before, angular_before;
      chord(earlier, earliest, dt, linear_before, angular_before);
      motion.linear_velocity += 0.5 * (motion.linear_velocity - linear_before);
      motion.angular_velocity += 0.5 * (motion.angular_velocity - angular_before);
    }
  }
  return motion;
}

}  // namespace

core::Expected<FrameMotion> lookupFrameMotion(const tf2::BufferCore& buffer,
                                              const std::string& fixed_frame,
                                              const std::string& frame, const ros::Time& stamp,
                                              const ros::Duration& interval) {
  if (frame.empty() || frame == fixed_frame) return FrameMotion{};
  try {
    return motionFrom(
        [&](const ros::Time& t) {
          return tf2::transformToEigen(buffer.lookupTransform(fixed_frame, frame, t));
        },
        [&](const ros::Time& t) { return buffer.canTransform(fixed_frame, frame, t); }, stamp,
        interval);
  } catch (const tf2::TransformException& error) {
    return core::Error{frame, "no transform to '" + fixed_frame + "' at " +
                                  std::to_string(stamp.toSec()) + ": " + tfErrorText(error.what())};
  }
}

FrameChains::FrameChains(const tf2::BufferCore& buffer, std::string fixed_frame)
    : buffer_(buffer), fixed_frame_(std::move(fixed_frame)) {}

const FrameChains::Rooted& FrameChains::rooted(const std::string& frame, const ros::Time& stamp) {
  Poses& poses = poses_[stamp.toNSec()];
  // Up to a frame known at this stamp, or the root; then down again, one hop each.
  std::vector<std::pair<std::string, std::string>> path;  // (frame, its parent)
  std::unordered_set<std::string> walked{frame};
  std::string at = frame;
  while (poses.count(at) == 0) {
    std::string parent;
    if (!buffer_._getParent(at, stamp, parent) || parent.empty()) {
      poses[at] = Rooted{at, Eigen::Isometry3d::Identity()};  // a root
      break;
    }
    if (!walked.insert(parent).second) {
      poses[at] = Rooted{"", Eigen::Isometry3d::Identity()};  // a loop: rooted nowhere
      break;
    }
    path.emplace_back(at, parent);
    at = parent;
  }
  for (auto hop = path.rbegin(); hop != path.rend(); ++hop) {
    const Rooted& above = poses.at(hop->second);
    Rooted here{"", Eigen::Isometry3d::Identity()};
    if (!above.root.empty()) {
      try {
        here = Rooted{above.root, above.pose * tf2::transformToEigen(buffer_.lookupTransform(
                                                   hop->second, hop->first, stamp))};
      } catch (const tf2::TransformException&) {
      }
    }
    poses[hop->first] = here;
  }
  return poses.at(frame);
}

bool FrameChains::wholeStatic(const std::string& frame) {
  std::vector<std::string> path;
  std::unordered_set<std::string> walked;
  std::string at = frame;
  bool whole = true;
  while (true) {
    const auto known = static_.find(at);
    if (known != static_.end()) {
      whole = known->second;
      break;
    }
    if (!walked.insert(at).second) {
      whole = false;  // a loop: no chain to a root, static or not
      break;
    }
    std::string parent;
    if (!buffer_._getParent(at, ros::Time(0), parent) || parent.empty()) {
      static_[at] = true;  // a root
      break;
    }
    bool hop_static = false;
    try {
      hop_static = buffer_.lookupTransform(parent, at, ros::Time(0)).header.stamp.isZero();
    } catch (const tf2::TransformException&) {
    }
    path.push_back(at);
    if (!hop_static) {
      whole = false;
      break;
    }
    at = parent;
  }
  // Every frame walked has the hop found moving, or the known frame's chain, above it.
  for (const std::string& below : path) static_[below] = whole;
  return static_.at(frame);
}

core::Expected<FrameMotion> FrameChains::motion(const std::string& frame, const ros::Time& stamp,
                                                const ros::Duration& interval) {
  if (frame.empty() || frame == fixed_frame_) return FrameMotion{};
  // Not connected at the stamp (a frame tf does not have): said without an exception.
  const std::string root = rooted(frame, stamp).root;
  if (root.empty() || root != rooted(fixed_frame_, stamp).root) {
    return core::Error{frame, "no transform to '" + fixed_frame_ + "' at " +
                                  std::to_string(stamp.toSec()) + ": not connected hop by hop"};
  }
  const auto pose_at = [&](const ros::Time& t) {
    const Rooted link = rooted(frame, t);
    const Rooted fixed = rooted(fixed_frame_, t);
    if (link.root.empty() || link.root != fixed.root) {
      throw tf2::LookupException("'" + frame + "' and '" + fixed_frame_ +
                                 "' are not connected hop by hop at " + std::to_string(t.toSec()));
    }
    return Eigen::Isometry3d(fixed.pose.inverse() * link.pose);
  };
  const auto has = [&](const ros::Time& t) {
    try {
      pose_at(t);
      return true;
    } catch (const tf2::TransformException&) {
      return false;
    }
  };
  try {
    return motionFrom(pose_at, has, stamp, interval);
  } catch (const tf2::TransformException& error) {
    return core::Error{frame, "no transform to '" + fixed_frame_ + "' at " +
                                  std::to_string(stamp.toSec()) + ": " + error.what()};
  }
}

}  // namespace collision_response
