// The narrow phase: every question that depends on a shape's kind, answered by one dispatch on
// the shape (shape.h) per question. Outside this room nothing branches on the kind of obstacle:
// a new shape adds an alternative to Shape and a branch to each function here (and, in the ROS
// layer, its scene keys and its marker).
//  - placement: an obstacle's shape from its scene entry, placed fixed or on a moving frame;
//  - shapeAt: a placed shape moved on (straight on) to an instant;
//  - contactGeometry: two shapes at one instant (normal, gap, point, curvature, the surface's
//    velocity at the point);
//  - firstContact: the first contact along both shapes' motions (time_of_impact.h's closed
//    forms, and finite_shapes.h's certified roots for boxes, cylinders and capsules);
//  - mayReach, mayReachMoving: whether a box may reach a fixed or a moving shape (the broad
//    phase's test).
// contactGeometry and firstContact are tables over the kinds of both sides (as MuJoCo's
// mjCOLLISIONFUNC, Box2D v3's s_registers and Jolt's CollisionDispatch): an entry answers a pair
// of kinds in one order, the entry of the reversed order calls it with the sides swapped and
// reverses the contact. Every moving body is a ball today: the sphere's row (a ball against
// every kind) is filled, and its column by reversal; the other entries are not yet
// (narrowPhaseCovers says so, naming the kinds).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
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
  /// m: the lever arms r_a, r_b of the solvers' contact point (ContactPoint, solver_body.h): from
  /// each side's centre (a ball's, a sphere's; a plane's or finite shape's pose origin) to its
  /// own surface point at the contact. A ball's is R n; a sphere's on the other side -R n.
  Eigen::Vector3d lever_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d lever_b = Eigen::Vector3d::Zero();

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

/// The kinds of shape, Shape's alternatives in its order: the rows and columns of the narrow
/// phase's tables.
enum class ShapeKind : std::size_t { kPlane, kSphere, kBox, kCylinder, kCapsule, kMesh };
constexpr std::size_t kShapeKinds = std::variant_size_v<Shape>;
static_assert(kShapeKinds == static_cast<std::size_t>(ShapeKind::kMesh) + 1,
              "a kind per alternative of Shape");
inline ShapeKind kindOf(const Shape& shape) { return static_cast<ShapeKind>(shape.index()); }
/// The kind's scene name: "plane", "sphere", "box", "cylinder", "capsule", "mesh".
const char* kindName(ShapeKind kind);

/// The direction side a approaches side b in (a's velocity less b's), which contactGeometry asks
/// for only where the shapes give no line of contact (coincident sphere centres): a reference to
/// the caller's callable, which outlives the call (no copy, no allocation).
class ApproachDirection {
 public:
  template <class Callable,
            class = std::enable_if_t<!std::is_same_v<std::decay_t<Callable>, ApproachDirection>>>
  ApproachDirection(const Callable& callable)  // NOLINT: implicit, as a lambda is passed
      : callable_(&callable),
        call_([](const void* c) { return Eigen::Vector3d((*static_cast<const Callable*>(c))()); }) {
  }
  Eigen::Vector3d operator()() const { return call_(callable_); }

 private:
  const void* callable_;
  Eigen::Vector3d (*call_)(const void*);
};

/// A shape in motion from its placement's instant on: its origin moving at `velocity`,
/// accelerating at `acceleration` (read where the question accelerates), a finite shape turning
/// at its pose's angular velocity.
struct MovingShape {
  PlacedShape placed;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
};

/// An entry of the narrow phase's table for side a of one kind and side b of another.
struct NarrowPhaseEntry {
  /// Where a and b are relative to each other at their placements' (common) instant: the normal
  /// from a into b, the surface velocity b's at the point. `contact_tolerance`: the touching
  /// band's share of the contact distance.
  ContactGeometry (*contact)(const PlacedShape& a, const PlacedShape& b, double contact_tolerance,
                             ApproachDirection approach) = nullptr;
  /// The first contact of a and b (placed at the same instant) within `horizon` of it, along
  /// straight lines or, `accelerates`, parabolas.
  std::optional<double> (*first_contact)(const MovingShape& a, const MovingShape& b,
                                         bool accelerates, double horizon) = nullptr;
  /// The entry calls the one of the kinds in the other order, the sides swapped: the same gap,
  /// point, curvature and instant, the normal reversed, the surface velocity the other side's.
  bool reversed = false;
};

/// The table's entry for a side of kind `a` against one of kind `b`; its functions are null
/// where the pair is not yet answered (narrowPhaseCovers).
const NarrowPhaseEntry& narrowPhaseEntry(ShapeKind a, ShapeKind b);

/// Ok where the narrow phase answers a body of kind `a` against one of kind `b`; otherwise an
/// error naming `field` and both kinds ("not yet: ..."). A body of a kind it does not answer
/// against every kind it may meet is refused with this before it reaches the tables.
Status narrowPhaseCovers(ShapeKind a, ShapeKind b, const std::string& field);

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
  result.lever_a = radius * result.normal;
  result.lever_b = -sphere.radius * result.normal;
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

/// contactGeometry against a plane.
inline ContactGeometry planeGeometry(const Eigen::Vector3d& centre, double radius,
                                     const Plane& plane, const PlacedShape& placed,
                                     double contact_tolerance) {
  ContactGeometry result;
  result.normal = -plane.normal;  // from the ball into the plane
  result.gap = plane.normal.dot(centre) - plane.offset - radius;
  result.tolerance = touchingBand(radius, contact_tolerance, centre, plane.offset);
  result.valid = true;
  const Eigen::Vector3d on_shape = centre + (result.gap + radius) * result.normal;
  result.point = 0.5 * (Eigen::Vector3d(centre + radius * result.normal) + on_shape);
  result.lever_a = radius * result.normal;
  result.lever_b = on_shape - placed.pose.transform.translation();
  result.surface_velocity =
      placed.pose.velocityAt(result.point - placed.pose.transform.translation());
  return result;
}

/// The sphere's row of the contact table: a ball at `centre` of `radius` against `shape`, the
/// alternative `placed` holds.
template <class Kind, class Approach>
ContactGeometry ballGeometry(const Eigen::Vector3d& centre, double radius, const Kind& shape,
                             const PlacedShape& placed, double contact_tolerance,
                             Approach&& approach) {
  if constexpr (std::is_same_v<Kind, Plane>) {
    return planeGeometry(centre, radius, shape, placed, contact_tolerance);
  } else if constexpr (std::is_same_v<Kind, Sphere>) {
    return sphereGeometry(centre, radius, shape, placed, contact_tolerance, approach);
  } else {
    return finiteGeometry(centre, radius, shape, placed.pose, contact_tolerance);
  }
}

/// A ball at `centre` of `radius` and `placed` (at the same instant): the sphere's row of the
/// table, entered directly. `contact_tolerance`: the touching band's share of the contact
/// distance. Centres that coincide have no line of centres: the normal is then `approach()`
/// normalised (the direction the ball approaches in), and none (valid false) if that is zero.
template <class Approach>
ContactGeometry contactGeometry(const Eigen::Vector3d& centre, double radius,
                                const PlacedShape& placed, double contact_tolerance,
                                Approach&& approach) {
  return std::visit(
      [&](const auto& shape) {
        return ballGeometry(centre, radius, shape, placed, contact_tolerance, approach);
      },
      placed.shape);
}

/// Two placed shapes at one instant, by the table (narrowPhaseEntry): the normal from a into b,
/// the surface velocity b's at the point; `approach()` is a's velocity less b's. A pair the
/// table does not yet answer (narrowPhaseCovers) has no contact geometry: valid false.
ContactGeometry contactGeometry(const PlacedShape& a, const PlacedShape& b,
                                double contact_tolerance, ApproachDirection approach);

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
/// it turns (its pose's angular velocity), by conservative advancement on the distance. The
/// sphere's row of the table, entered directly.
std::optional<double> firstContact(const BallMotion& ball, const PlacedShape& shape,
                                   const Eigen::Vector3d& shape_velocity,
                                   const Eigen::Vector3d& shape_acceleration, bool accelerates,
                                   double horizon);

/// The first contact of two moving shapes (placed at the same instant) within `horizon`, by the
/// table (narrowPhaseEntry). A pair the table does not yet answer (narrowPhaseCovers) has none.
std::optional<double> firstContact(const MovingShape& a, const MovingShape& b, bool accelerates,
                                   double horizon);

/// Whether a box may reach a fixed shape placed at `placed` (the broad phase's test).
bool mayReach(const PlacedShape& placed, const Box& box);

/// Whether a box may reach a shape moving straight on from `placed` (shapeAt) at some instant of
/// [from, to]: at rest, mayReach; a sphere's or a finite shape's centre moves at the constant
/// speed |v| of its pose's origin (a screw keeps it), so its bounding sphere grown by |v| times
/// the longest time from the placement bounds it; a moving plane always may.
bool mayReachMoving(const PlacedShape& placed, const Box& box, double from, double to);

/// m: how far from its pose's origin at its placement a moving shape's points may be over
/// [from, to]: its bounding radius (boundingRadiusOf) grown by |v| times the longest time from the
/// placement (the origin moves at |v|: shapeAt). Infinite for a plane.
double reachOver(const PlacedShape& placed, double from, double to);

/// m: the size of a shape about its pose's origin that a ball's contact distance counts (a
/// sphere's radius; 0 for a plane, whose distance is along its normal, and for a finite shape,
/// whose distance is from the nearest point of its surface).
double contactRadius(const Shape& shape);

}  // namespace collision_response::core
