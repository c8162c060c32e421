// The shapes an obstacle may have and where it is: a shape placed in the fixed frame and the
// rigid motion it moves with. The contact geometry of a ball and a shape, and the first contact
// along a ball's motion, are one dispatch on the shape (src/core/geometry/narrow_phase.h): a new
// shape is a new alternative here and a branch of each query there.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <variant>

namespace collision_response::core {

/// A plane {x : normal.x = offset}, free on the side `normal` (unit) points to.
struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
};

/// A sphere (a solid ball) about `centre`.
struct Sphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// A box (scene type `box`) about its pose's origin, its edges along the pose's axes.
struct Cuboid {
  Eigen::Vector3d half_size = Eigen::Vector3d::Zero();  ///< m, half the lengths of its edges
};

/// A solid cylinder about its pose's origin, its axis the pose's z.
struct Cylinder {
  double radius = 0.0;       ///< m
  double half_length = 0.0;  ///< m, from the origin to each cap
};

/// A capsule: the points within `radius` of the segment along the pose's z from -half_length to
/// half_length.
struct Capsule {
  double radius = 0.0;       ///< m
  double half_length = 0.0;  ///< m, of the segment (the capsule is 2 (half_length + radius) long)
};

class TriangleMesh;  // collision_response/core/triangle_mesh.h

/// A triangle mesh (scene type `mesh`) in its pose's frame, shared: a million triangles are not
/// copied with each placement.
struct Mesh {
  std::shared_ptr<const TriangleMesh> triangles;
};

/// Planes and spheres are given in the fixed frame; the finite shapes (Cuboid, Cylinder, Capsule,
/// Mesh) in their pose's frame (PlacedShape::pose).
using Shape = std::variant<Plane, Sphere, Cuboid, Cylinder, Capsule, Mesh>;

/// A rigid motion at one instant: the pose (fixed <- moving) at `time`, the velocity of the
/// pose's origin and the angular velocity, both in the fixed frame.
struct RigidPose {
  double time = 0.0;
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          ///< m/s, of the origin
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< rad/s

  /// The velocity of the point at `offset` from the origin (in the fixed frame): v + w x r.
  Eigen::Vector3d velocityAt(const Eigen::Vector3d& offset) const {
    return velocity + angular_velocity.cross(offset);
  }
};

/// An obstacle where it is: its shape in the fixed frame at `pose.time`, and the motion it has
/// from there (straight on: the monitor moves obstacles in straight lines between placements).
/// The pose's origin is the shape's reference point (a sphere's centre, a point of a plane, a
/// finite shape's centre, its axes the pose's).
struct PlacedShape {
  Shape shape;
  RigidPose pose;
};

/// m: the radius about a placed shape's pose origin of a sphere that holds the shape (a sphere's
/// own radius, a box's half diagonal, ...); infinite for a plane.
double boundingRadiusOf(const Shape& shape);

}  // namespace collision_response::core
