// Finite obstacles (boxes, cylinders, capsules) against a ball: the ball's centre against the
// shape grown by the ball's radius (their Minkowski sum), whose surface is made of features —
// a box's faces are planes, its edges cylinders and its corners spheres; a cylinder's side is a
// cylinder, its caps planes and its rims tori; a capsule's side is a cylinder and its ends
// spheres. Everything here is in the shape's own frame (its pose's origin and axes).
#pragma once

#include <Eigen/Core>
#include <optional>

#include "collision_response/core/shape.h"

namespace collision_response::core {

/// The point of a finite shape's surface nearest a point, and the kind of feature it is on.
struct NearestFeature {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< on the surface
  /// Unit: from the surface towards the point (the outward normal on a face, and where the point
  /// is inside, the outward normal of the nearest face).
  Eigen::Vector3d outward = Eigen::Vector3d::UnitZ();
  double distance = 0.0;  ///< m, > 0 outside, < 0 inside (the depth)
  /// The point's distance from the feature's core (an edge's line, a corner, a rim's circle, a
  /// cylinder's or capsule's axis): the radius of the normal's turning, 1 / curvature; infinite
  /// on a face. Where the normal turns only across `axis` (a line's direction, a rim's tangent),
  /// it turns along `axis` at `axial_share` of the rate across it (0 along a line).
  double turning_radius = INFINITY;
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  double axial_share = 1.0;
};

/// The nearest feature of a shape to `p` (shape frame).
NearestFeature nearestFeature(const Cuboid& box, const Eigen::Vector3d& p);
NearestFeature nearestFeature(const Cylinder& cylinder, const Eigen::Vector3d& p);
NearestFeature nearestFeature(const Capsule& capsule, const Eigen::Vector3d& p);
/// A mesh's: the nearest point of its triangles (TriangleMesh::nearest). A closed mesh's is
/// inside where the point is behind the pseudo-normal of the face, edge or vertex it is on
/// (Baerentzen and Aanaes); an open mesh (a surface) has no inside: the distance is the plain
/// distance, the normal from the nearest point to the point. An edge or vertex a ball cannot
/// touch first (between coplanar faces, in a closed mesh's groove) turns the normal no more than
/// a face does.
NearestFeature nearestFeature(const Mesh& mesh, const Eigen::Vector3d& p);

/// m: the radius of the smallest sphere about the shape's origin that holds it.
double boundingRadius(const Cuboid& box);
double boundingRadius(const Cylinder& cylinder);
double boundingRadius(const Capsule& capsule);
double boundingRadius(const Mesh& mesh);

/// The ball's motion relative to a finite shape, in the shape's frame: its centre at
/// centre + velocity t + (acceleration / 2) t^2 from the instant both were placed.
struct RelativeMotion {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// The first instant in [0, horizon] at which the ball comes into contact with the shape: the
/// least over the features of the first root of the feature's polynomial along the motion at
/// which the ball enters it, where the point reached is the feature's (a face's rectangle or
/// disc, an edge's or a side's length; a corner's sphere and a rim's torus lie inside the grown
/// shape whole). In a straight line a face's polynomial is linear, an edge's, corner's or
/// side's quadratic, a rim's quartic; accelerating, quadratic, quartic and degree 8. Each is
/// isolated by Descartes' rule and bisected to the last bits of the instant
/// (polynomial_roots.h): no root is missed, none invented. Empty when the ball overlaps the
/// shape already (beyond the rounding of its position) or does not reach it within `horizon`.
std::optional<double> firstContactFinite(const RelativeMotion& motion, const Cuboid& box,
                                         double horizon);
std::optional<double> firstContactFinite(const RelativeMotion& motion, const Cylinder& cylinder,
                                         double horizon);
std::optional<double> firstContactFinite(const RelativeMotion& motion, const Capsule& capsule,
                                         double horizon);
/// A mesh's features are its faces (each a plane, on its outer side, an open mesh's on its back
/// as well, within its triangle), the edges and vertices a ball can touch first (TriangleMesh),
/// those of the triangles near the ball's path only: the path is cut into pieces a few ball radii
/// long, looked at in order, each asking the hierarchy for the triangles within the ball's reach
/// of it, until a piece holds the first contact.
std::optional<double> firstContactFinite(const RelativeMotion& motion, const Mesh& mesh,
                                         double horizon);

}  // namespace collision_response::core
