// Where a tf frame is and how it moves, relative to the fixed frame: from tf2 over time.
#pragma once

#include <ros/time.h>
#include <tf2/buffer_core.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <unordered_map>

#include "collision_response/core/expected.h"

namespace collision_response {

/// A frame's pose in the fixed frame at one instant, and its velocity there.
struct FrameMotion {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();      ///< fixed <- frame
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   ///< m/s of the frame's origin
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< rad/s, in the fixed frame

  /// A point given in the frame, in the fixed frame.
  Eigen::Vector3d point(const Eigen::Vector3d& in_frame) const { return pose * in_frame; }
  /// The velocity in the fixed frame of a body at `in_frame` moving at `velocity_in_frame`
  /// relative to the frame (expressed in it): R v + v_origin + w x (R p).
  Eigen::Vector3d velocity(const Eigen::Vector3d& in_frame,
                           const Eigen::Vector3d& velocity_in_frame) const;
};

/// tf's error text, bounded: its first line, at most 300 characters (tf's text for a tree it
/// takes for a loop, a chain deeper than tf2::BufferCore::MAX_GRAPH_DEPTH, lists every frame).
std::string tfErrorText(const std::string& what);

/// Looks up `frame` in `fixed_frame` at `stamp`, `stamp - interval` and `stamp - 2 interval`:
/// the velocity is the backward finite difference of second order (exact for a frame moving at
/// constant velocity, as tf interpolates linearly between its samples; first order where tf has
/// no pose two intervals back yet). A frame equal to the fixed frame, or empty, is the identity at
/// rest. The error says which frames and why (not yet available, not connected, ...).
core::Expected<FrameMotion> lookupFrameMotion(const tf2::BufferCore& buffer,
                                              const std::string& fixed_frame,
                                              const std::string& frame, const ros::Time& stamp,
                                              const ros::Duration& interval);

/// Frames' motions relative to the fixed frame composed hop by hop, each frame's transform to
/// its parent looked up once a stamp and kept (clear() forgets them): a robot's chain of links
/// costs one hop a link, and a chain deeper than tf2 walks (tf2::BufferCore::MAX_GRAPH_DEPTH,
/// 1,000 frames, beyond which tf2 takes it for a loop) is followed to its end. Each hop is
/// interpolated at the stamp as tf2 interpolates it, so a pose is tf2's lookup, composed in
/// another order.
class FrameChains {
 public:
  FrameChains(const tf2::BufferCore& buffer, std::string fixed_frame);
  /// As lookupFrameMotion.
  core::Expected<FrameMotion> motion(const std::string& frame, const ros::Time& stamp,
                                     const ros::Duration& interval);
  /// Whether every hop from `frame` up to its root is static (on /tf_static: tf stamps its
  /// latest transform zero).
  bool wholeStatic(const std::string& frame);

 private:
  struct Rooted {
    std::string root;  ///< the chain's root frame; empty: not connected at that stamp
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< root <- frame
  };
  using Poses = std::unordered_map<std::string, Rooted>;
  const Rooted& rooted(const std::string& frame, const ros::Time& stamp);

  const tf2::BufferCore& buffer_;
  std::string fixed_frame_;
  std::unordered_map<std::uint64_t, Poses> poses_;  ///< by stamp (ns)
  std::unordered_map<std::string, bool> static_;    ///< wholeStatic, by frame
};

}  // namespace collision_response
