// The narrow phase: every question that depends on a shape's kind, answered by one dispatch on
// the shape (shape.h) per question. Outside this room nothing branches on the kind of obstacle:
// a new shape adds an alternative to Shape and a branch to each function here (and, in the ROS
// layer, its scene keys and its marker).
//  - placement: an obstacle's shape from its scene entry, placed fixed or on a moving frame;
//  - shapeAt: a placed shape moved on (straight on) to an instant;
//  - contactGeometry: a ball and a shape at one instant (normal, gap, point, curvature, the
//    surface's velocity at the point);
//  - firstContact: the first contact along a ball's motion (time_of_impact.h's closed forms, and
//    finite_shapes.h's certified roots for boxes, cylinders and capsules);
//  - mayReach, mayReachMoving: whether a box may reach a fixed or a moving shape (the broad
//    phase's test).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>

#include "collision_response/core/expected.h"
#include "collision_response/core/scene.h"
#include "collision_response/core/shape.h"
#include "geometry/broadphase.h"
#include "geometry/motion.h"

namespace collision_response::core {

/// Where a ball and a shape are relative to each other at one instant.
struct ContactGeometry {
  Eigen::Vector3d normal;  ///< unit, ball -> shape
  double gap = 0.0;        ///< m, surface to surface along the normal; < 0 overlapping
  double tolerance = 0.0;  ///< m, |gap| within it is touching
  bool valid = false;      ///< false: coincident centres and no approach: no line of impact
  /// 1/m: how the line of contact turns as the ball moves across it, 1 / (the distance between
  /// the centres) for a ball on a sphere, 0 on a flat shape.
  double curvature = 0.0;
  /// m: 1 / curvature where it is not 0, computed as the distance itself (a sphere's gap plus
  /// both radii), so that |v_perp|^2 / turning_radius is the same bits as before finite shapes.
  double turning_radius = INFINITY;
  /// Where the normal turns only across a direction (a ball on an edge, a cylinder's side, a
  /// rim): that direction (unit; zero where it turns alike every way), along which it turns at
  /// `axial_share` of its rate across it (0 along a line).
  Eigen::Vector3d turning_axis = Eigen::Vector3d::Zero();
  double axial_share = 1.0;
  /// The contact is on a feature that ends (a finite shape's face, edge or side): a ball that
  /// moves along it may reach another feature, so its motion is followed step by step.
  bool bounded = false;
  /// The contact point: the middle of the gap along the normal, half-way between the ball's
  /// surface point and the shape's, summed so that it is the same bits whichever of two spheres
  /// is the ball (the stepped solve's order of contacts comes from these points, and renaming
  /// bodies swaps pairs' sides). Impacts, lasting contacts and stepped clusters record it.
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  /// m/s: the shape's surface at `point`, v + w x r (r from the shape's pose origin).
  Eigen::Vector3d surface_velocity = Eigen::Vector3d::Zero();

  /// The shape is flat here: the normal does not turn as the ball moves along it.
  bool flat() const { return curvature == 0; }
  /// m/s^2: how fast the normal's turning pulls the surfaces apart for a ball moving at `across`
  /// (perpendicular to the normal) relative to the shape, |across|^2 / d on a sphere; along a
  /// turning axis only the share of that component counts.
  double centripetal(const Eigen::Vector3d& across) const {
    if (flat()) return 0.0;
    if (turning_axis.isZero()) return across.squaredNorm() / turning_radius;
    const double along = turning_axis.dot(across);
    return (across.squaredNorm() - (1 - axial_share) * along * along) / turning_radius;
  }
  /// m: the band a bounce or a separation must rise out of under the pressing acceleration
  /// (restSpeed): the touching band, or the overlap where the pair overlaps deeper (a contact
  /// held where it is, or an impact that discrete detection found by overlap).
  double band() const { return std::max(tolerance, -gap); }
};

/// An obstacle's shape as its scene entry gives it, in its frame.
Shape shapeOf(const ObstacleSpec& spec);
/// Sets an obstacle's scene entry to `shape` (its kind and its numbers).
void setShape(ObstacleSpec& spec, const Shape& shape);
/// A shape's numbers are usable: finite, a plane's normal nonzero, a sphere's radius positive;
/// errors name the scene key `field(key)` ("normal", "offset", "position", "radius").
Status checkShape(const Shape& shape, const std::function<std::string(const char*)>& field);
/// The shape with a plane's normal scaled to unit length without under- or overflow
/// (validation.h, unitVector); other shapes as they are. For a shape checkShape accepted.
Shape normalized(const Shape& shape);
/// An obstacle in the fixed frame, at rest: placed where its scene entry says.
PlacedShape placeFixed(const ObstacleSpec& spec);
/// An obstacle given in a moving frame, placed where `frame` (the frame's motion) puts it.
PlacedShape place(const ObstacleSpec& spec, const RigidPose& frame);

/// The reference point of a placed shape at `time`, moving straight on.
inline Eigen::Vector3d originAt(const RigidPose& pose, double time) {
  return pose.transform.translation() + pose.velocity * (time - pose.time);
}

/// A placed shape moved on to `time`: its origin straight on at its pose's velocity, a finite
/// shape turned about its origin at its pose's angular velocity (a plane's and a sphere's
/// turning is not followed).
PlacedShape shapeAt(const PlacedShape& placed, double time);

/// m: how far from its pose's origin a shape's points turn with it: a finite shape's bounding
/// radius; 0 for a plane and a sphere, whose turning is not followed (shapeAt).
double turningReach(const Shape& shape);

/// contactGeometry against a sphere.
template <class Approach>
ContactGeometry sphereGeometry(const Eigen::Vector3d& centre, double radius, const Sphere& sphere,
                               const PlacedShape& placed, double contact_tolerance,
                               Approach&& approach) {
  constexpr double kEps = 2.220446049250313e-16;
  ContactGeometry result;
  const Eigen::Vector3d separation = sphere.centre - centre;
  const double distance = separation.norm();
  const double contact_distance = radius + sphere.radius;
  if (!(distance > 0)) {
    const Eigen::Vector3d direction = approach();
    if (!(direction.norm() > 0)) {
      result.curvature = INFINITY;  // the line of centres turns at any motion
      return result;
    }
    result.normal = direction.normalized();
  } else {
    result.normal = separation / distance;
  }
  result.gap = distance - contact_distance;
  result.tolerance = contact_tolerance * contact_distance +
                     16 * kEps *
                         (centre.lpNorm<Eigen::Infinity>() +
                          sphere.centre.lpNorm<Eigen::Infinity>() + contact_distance);
  result.valid = true;
  result.turning_radius = result.gap + radius + sphere.radius;
  result.curvature = 1.0 / result.turning_radius;
  result.point = 0.5 * (Eigen::Vector3d(centre + radius * result.normal) +
                        Eigen::Vector3d(sphere.centre - sphere.radius * result.normal));
  result.surface_velocity =
      placed.pose.velocityAt(result.point - placed.pose.transform.translation());
  return result;
}

/// contactGeometry against a finite shape at `pose`: the nearest point of its surface
/// (finite_shapes.h), the normal from the ball's centre to it (continuous from a face to an edge
/// to a corner), the normal's turning radius the centre's distance from the feature's core.
ContactGeometry finiteGeometry(const Eigen::Vector3d& centre, double radius, const Cuboid& box,
                               const RigidPose& pose, double contact_tolerance);
ContactGeometry finiteGeometry(const Eigen::Vector3d& centre, double radius,
                               const Cylinder& cylinder, const RigidPose& pose,
                               double contact_tolerance);
ContactGeometry finiteGeometry(const Eigen::Vector3d& centre, double radius, const Capsule& capsule,
                               const RigidPose& pose, double contact_tolerance);
ContactGeometry finiteGeometry(const Eigen::Vector3d& centre, double radius, const Mesh& mesh,
                               const RigidPose& pose, double contact_tolerance);

/// A ball at `centre` of `radius` and `placed` (at the same instant). `contact_tolerance`: the
/// touching band's share of the contact distance. Centres that coincide have no line of centres:
/// the normal is then `approach()` normalised (the direction the ball approaches in), and none
/// (valid false) if that is zero.
template <class Approach>
ContactGeometry contactGeometry(const Eigen::Vector3d& centre, double radius,
                                const PlacedShape& placed, double contact_tolerance,
                                Approach&& approach) {
  ContactGeometry result;
  const auto surfaceVelocity = [&](const Eigen::Vector3d& on_shape) {
    result.point = 0.5 * (Eigen::Vector3d(centre + radius * result.normal) + on_shape);
    result.surface_velocity =
        placed.pose.velocityAt(result.point - placed.pose.transform.translation());
  };
  if (const Plane* plane = std::get_if<Plane>(&placed.shape)) {
    result.normal = -plane->normal;  // from the ball into the plane
    result.gap = plane->normal.dot(centre) - plane->offset - radius;
    result.tolerance = touchingBand(radius, contact_tolerance, centre, plane->offset);
    result.valid = true;
    surfaceVelocity(centre + (result.gap + radius) * result.normal);
    return result;
  }
  if (const Sphere* sphere = std::get_if<Sphere>(&placed.shape)) {
    return sphereGeometry(centre, radius, *sphere, placed, contact_tolerance, approach);
  }
  return std::visit(
      [&](const auto& shape) -> ContactGeometry {
        using Kind = std::decay_t<decltype(shape)>;
        if constexpr (std::is_same_v<Kind, Plane> || std::is_same_v<Kind, Sphere>) {
          return result;  // answered above
        } else {
          return finiteGeometry(centre, radius, shape, placed.pose, contact_tolerance);
        }
      },
      placed.shape);
}

/// How a ball moves from an instant on: along a straight line, or (accelerates) a parabola.
struct BallMotion {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
};

/// The first contact of `ball` with `shape` (placed at the same instant, moving at
/// `shape_velocity` and accelerating at `shape_acceleration`) within `horizon`: straight lines
/// (timeOfImpactPlane, timeOfImpactSpheres), or with `accelerates` parabolas
/// (timeOfImpactPlaneBallistic, timeOfImpactSpheresAccelerated; a plane does not accelerate);
/// a finite shape by its features' polynomials (finite_shapes.h, firstContactFinite), or, where
/// it turns (its pose's angular velocity), by conservative advancement on the distance.
std::optional<double> firstContact(const BallMotion& ball, const PlacedShape& shape,
                                   const Eigen::Vector3d& shape_velocity,
                                   const Eigen::Vector3d& shape_acceleration, bool accelerates,
                                   double horizon);

/// Whether a box may reach a fixed shape placed at `placed` (the broad phase's test).
bool mayReach(const PlacedShape& placed, const Box& box);

/// Whether a box may reach a shape moving straight on from `placed` (shapeAt) at some instant of
/// [from, to]: at rest, mayReach; a sphere's or a finite shape's centre moves at the constant
/// speed |v| of its pose's origin (a screw keeps it), so its bounding sphere grown by |v| times
/// the longest time from the placement bounds it; a moving plane always may.
bool mayReachMoving(const PlacedShape& placed, const Box& box, double from, double to);

/// m: the size of a shape about its pose's origin that a ball's contact distance counts (a
/// sphere's radius; 0 for a plane, whose distance is along its normal, and for a finite shape,
/// whose distance is from the nearest point of its surface).
double contactRadius(const Shape& shape);

}  // namespace collision_response::core
