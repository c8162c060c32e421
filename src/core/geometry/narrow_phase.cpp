#include "geometry/narrow_phase.h"

#include <array>
#include <limits>
#include <utility>

#include "collision_response/core/time_of_impact.h"
#include "collision_response/core/validation.h"
#include "geometry/finite_shapes.h"

namespace collision_response::core {

namespace {

/// A visitor from lambdas, one per alternative.
template <class... Branches>
struct Dispatch : Branches... {
  using Branches::operator()...;
};
template <class... Branches>
Dispatch(Branches...) -> Dispatch<Branches...>;

/// A placed shape whose pose's origin is `origin`, turned by `rotation`, moving with `frame`.
RigidPose poseAt(const RigidPose& frame, const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& velocity) {
  RigidPose pose;
  pose.time = frame.time;
  pose.transform.linear() = frame.transform.linear();
  pose.transform.translation() = origin;
  pose.velocity = velocity;
  pose.angular_velocity = frame.angular_velocity;
  return pose;
}

/// The velocity in the fixed frame of a point at `in_frame` fixed in `frame`: R 0 + v + w x (R p)
/// (the frame's motion, as the ROS layer's FrameMotion::velocity evaluates it).
Eigen::Vector3d pointVelocity(const RigidPose& frame, const Eigen::Vector3d& in_frame) {
  const Eigen::Vector3d offset = frame.transform.linear() * in_frame;
  return frame.transform.linear() * Eigen::Vector3d::Zero() + frame.velocity +
         frame.angular_velocity.cross(offset);
}

/// A finite shape's length or radius: finite and > 0 (a zero one has no inside).
Status positiveLength(double value, const std::string& field) {
  if (!std::isfinite(value) || !(value > 0)) {
    return Error{field, "must be a finite number > 0 m (a shape of zero size has no inside), got " +
                            formatNumber(value)};
  }
  return Ok{};
}

}  // namespace

Shape shapeOf(const ObstacleSpec& spec) {
  switch (spec.shape) {
    case ObstacleShape::kPlane:
      return Plane{spec.normal, spec.offset};
    case ObstacleShape::kSphere:
      return Sphere{spec.position, spec.radius};
    case ObstacleShape::kBox:
      return Cuboid{0.5 * spec.size};
    case ObstacleShape::kCylinder:
      return Cylinder{spec.radius, 0.5 * spec.length};
    case ObstacleShape::kCapsule:
      return Capsule{spec.radius, 0.5 * spec.length};
    case ObstacleShape::kMesh:
      return Mesh{spec.mesh};
  }
  return Plane{};
}

void setShape(ObstacleSpec& spec, const Shape& shape) {
  std::visit(Dispatch{[&](const Plane& plane) {
                        spec.shape = ObstacleShape::kPlane;
                        spec.normal = plane.normal;
                        spec.offset = plane.offset;
                      },
                      [&](const Sphere& sphere) {
                        spec.shape = ObstacleShape::kSphere;
                        spec.position = sphere.centre;
                        spec.radius = sphere.radius;
                      },
                      [&](const Cuboid& box) {
                        spec.shape = ObstacleShape::kBox;
                        spec.size = 2 * box.half_size;
                      },
                      [&](const Cylinder& cylinder) {
                        spec.shape = ObstacleShape::kCylinder;
                        spec.radius = cylinder.radius;
                        spec.length = 2 * cylinder.half_length;
                      },
                      [&](const Capsule& capsule) {
                        spec.shape = ObstacleShape::kCapsule;
                        spec.radius = capsule.radius;
                        spec.length = 2 * capsule.half_length;
                      },
                      [&](const Mesh& mesh) {
                        spec.shape = ObstacleShape::kMesh;
                        spec.mesh = mesh.triangles;
                      }},
             shape);
}

Status checkShape(const Shape& shape, const std::function<std::string(const char*)>& field) {
  return std::visit(
      Dispatch{[&](const Plane& plane) -> Status {
                 if (auto status = checkFinite(plane.normal, field("normal")); !status) {
                   return status;
                 }
                 if (plane.normal == Eigen::Vector3d::Zero()) {
                   return Error{field("normal"), "must not be zero"};
                 }
                 return checkFinite(plane.offset, field("offset"));
               },
               [&](const Sphere& sphere) -> Status {
                 if (auto status = checkFinite(sphere.centre, field("position")); !status) {
                   return status;
                 }
                 return checkRadius(sphere.radius, field("radius"));
               },
               [&](const Cuboid& box) -> Status {
                 if (auto status = checkFinite(box.half_size, field("size")); !status) {
                   return status;
                 }
                 for (int i = 0; i < 3; ++i) {
                   if (!(box.half_size[i] > 0)) {
                     return Error{field("size"),
                                  "every edge length must be > 0 m (a box of zero size has no "
                                  "inside), got " +
                                      formatNumber(2 * box.half_size[i]) + " along " + "xyz"[i]};
                   }
                 }
                 return Ok{};
               },
               [&](const Cylinder& cylinder) -> Status {
                 if (auto status = positiveLength(cylinder.radius, field("radius")); !status) {
                   return status;
                 }
                 return positiveLength(2 * cylinder.half_length, field("length"));
               },
               [&](const Capsule& capsule) -> Status {
                 if (auto status = positiveLength(capsule.radius, field("radius")); !status) {
                   return status;
                 }
                 if (!(capsule.half_length >= 0) || !std::isfinite(capsule.half_length)) {
                   return Error{field("length"),
                                "must be a finite number >= 0 m (0: a sphere), got " +
                                    formatNumber(2 * capsule.half_length)};
                 }
                 return Ok{};
               },
               [&](const Mesh& mesh) -> Status {
                 // (Its vertices and triangles were checked as it was built: TriangleMesh::build.)
                 if (!mesh.triangles) return Error{field("resource"), "names no loaded mesh"};
                 return Ok{};
               }},
      shape);
}

Shape normalized(const Shape& shape) {
  return std::visit(Dispatch{[](const Plane& plane) -> Shape {
                               return Plane{unitVector(plane.normal), plane.offset};
                             },
                             [](const auto& other) -> Shape { return other; }},
                    shape);
}

PlacedShape placeFixed(const ObstacleSpec& spec) {
  PlacedShape placed;
  placed.pose.transform.translation() = spec.position;
  placed.shape = std::visit(Dispatch{[](const Plane& plane) -> Shape {
                                       return Plane{plane.normal.normalized(), plane.offset};
                                     },
                                     [](const auto& other) -> Shape { return other; }},
                            shapeOf(spec));
  if (spec.shape != ObstacleShape::kPlane && spec.shape != ObstacleShape::kSphere) {
    placed.pose.transform.linear() = spec.orientation.normalized().toRotationMatrix();
  }
  return placed;
}

PlacedShape place(const ObstacleSpec& spec, const RigidPose& frame) {
  return std::visit(
      Dispatch{
          [&](const Plane& plane) {
            // Through its point nearest the frame's origin (in the frame), turned with it.
            const Eigen::Vector3d unit_normal = plane.normal.stableNormalized();
            const Eigen::Vector3d point_in_frame = unit_normal * plane.offset;
            const Eigen::Vector3d normal = frame.transform.linear() * unit_normal;
            const Eigen::Vector3d point = frame.transform * point_in_frame;
            return PlacedShape{Plane{normal, normal.dot(point)},
                               poseAt(frame, point, pointVelocity(frame, point_in_frame))};
          },
          [&](const Sphere& sphere) {
            const Eigen::Vector3d centre = frame.transform * sphere.centre;
            return PlacedShape{Sphere{centre, sphere.radius},
                               poseAt(frame, centre, pointVelocity(frame, sphere.centre))};
          },
          [&](const auto& finite) {
            // Its centre and axes turned with the frame.
            const Eigen::Vector3d centre = frame.transform * spec.position;
            PlacedShape placed{finite, poseAt(frame, centre, pointVelocity(frame, spec.position))};
            placed.pose.transform.linear() =
                frame.transform.linear() * spec.orientation.normalized().toRotationMatrix();
            return placed;
          }},
      shapeOf(spec));
}

PlacedShape shapeAt(const PlacedShape& placed, double time) {
  PlacedShape moved = placed;
  moved.pose.time = time;
  moved.pose.transform.translation() = originAt(placed.pose, time);
  std::visit(
      Dispatch{
          [&](Plane& plane) {
            plane.offset += plane.normal.dot(placed.pose.velocity) * (time - placed.pose.time);
          },
          [&](Sphere& sphere) { sphere.centre = moved.pose.transform.translation(); },
          [&](auto&) {
            // A finite shape moves as its frame does at a constant twist: the
            // velocity field v + w x (x - c) of the placement stays put, so the shape
            // turns by |w| dt about w and its origin moves on the screw about the
            // field's axis (for a hinge, the circle about it), v's part along w
            // straight on. In closed form, stable as w -> 0: c(dt) = c + v_par dt +
            // (sin a / |w|) v_perp + (2 sin^2(a / 2) / |w|) (w / |w|) x v, a = |w| dt.
            const Eigen::Vector3d& w = placed.pose.angular_velocity;
            const double speed = w.norm();
            const double dt = time - placed.pose.time;
            const double angle = speed * dt;
            if (angle == 0.0) return;
            const Eigen::Vector3d axis = w / speed;
            const Eigen::Vector3d& v = placed.pose.velocity;
            const Eigen::Vector3d along = axis.dot(v) * axis;
            const double half = std::sin(0.5 * angle);
            const Eigen::Vector3d moved_by = along * dt + (std::sin(angle) / speed) * (v - along) +
                                             (2 * half * half / speed) * axis.cross(v);
            moved.pose.transform.translation() = placed.pose.transform.translation() + moved_by;
            moved.pose.velocity = v + w.cross(moved_by);
            moved.pose.transform.linear() =
                Eigen::AngleAxisd(angle, axis).toRotationMatrix() * placed.pose.transform.linear();
          }},
      moved.shape);
  return moved;
}

double turningReach(const Shape& shape) {
  return std::visit(Dispatch{[](const Plane&) { return 0.0; }, [](const Sphere&) { return 0.0; },
                             [](const auto& finite) { return boundingRadius(finite); }},
                    shape);
}

namespace {

/// The first contact of a ball with a finite shape that turns (its pose's angular velocity w,
/// its origin moving at `shape_velocity`): its placement turns by |w| t about w at its origin,
/// and the distance along both motions is no polynomial. Conservative advancement (Mirtich,
/// "Impulse-based dynamic simulation of rigid body systems", 1996) on the gap g(t), each step as
/// far as g cannot reach 0, so that no contact is passed:
///  - |g'| <= L = |v_ball| + |a| T + |v| + |w| R (the surface's points move at v + w x r,
///    |r| <= R the shape's bounding radius, v turning with the shape), so g has no root before
///    g / L;
///  - for a convex shape the distance to it is a convex function of the ball's centre in the
///    shape's frame, q = R(t)^T (p - c), so g'' >= -|q''| >= -(|a| + |w| |v| + 2 |w| |u'| +
///    |w|^2 |u|), u = p - c, and g has no root while g - k s - B s^2 / 2 > 0 (k the closing speed,
///    g's exact slope: the normal's component of the ball's velocity less the surface point's).
/// It stops where the step falls below 1e-13 s (with the rounding of the instant): the contact to
/// 1e-13 s times L / k.
template <class Finite>
std::optional<double> firstContactTurning(const BallMotion& ball, const Finite& shape,
                                          const PlacedShape& placed,
                                          const Eigen::Vector3d& shape_velocity, bool accelerates,
                                          double horizon) {
  constexpr bool kConvex = !std::is_same_v<Finite, Mesh>;
  constexpr double kEps = 2.220446049250313e-16;
  constexpr int kMaxSteps = 1 << 16;
  PlacedShape moving = placed;
  moving.pose.velocity = shape_velocity;
  const Eigen::Vector3d acceleration = accelerates ? ball.acceleration : Eigen::Vector3d::Zero();
  const auto centreAt = [&](double t) -> Eigen::Vector3d {
    return ball.centre + t * (ball.velocity + (0.5 * t) * acceleration);
  };
  const auto geometryAt = [&](double t) {
    const PlacedShape there = shapeAt(moving, placed.pose.time + t);
    return finiteGeometry(centreAt(t), ball.radius, shape, there.pose, 0.0);
  };
  const double w = placed.pose.angular_velocity.norm();
  const double reach = boundingRadius(shape);
  // The shape's origin keeps its speed |v| but turns (shapeAt): u = p - c changes at most at
  // |p'| + |v|, and c'' = w x c'.
  const double speed = ball.velocity.norm() + acceleration.norm() * horizon + shape_velocity.norm();
  const double lipschitz = speed + w * reach;
  const double farthest =
      (ball.centre - placed.pose.transform.translation()).norm() + speed * horizon;
  const double bend =
      acceleration.norm() + w * shape_velocity.norm() + 2 * w * speed + w * w * farthest;
  const double stop = 1e-13 + 4 * kEps * horizon;
  // The rounding of a gap computed in the shape's frame.
  const double slack =
      16 * kEps *
      ((ball.centre - placed.pose.transform.translation()).norm() + reach + ball.radius);
  ContactGeometry g = geometryAt(0.0);
  const auto closing = [&](double t, const ContactGeometry& at) {
    return at.normal.dot(Eigen::Vector3d(ball.velocity + t * acceleration) - at.surface_velocity);
  };
  if (g.gap <= slack) {
    // Inside (its impact was when it began), or touching: an impact now if approaching.
    if (g.gap < -slack || !(closing(0.0, g) > 0)) return std::nullopt;
    return 0.0;
  }
  double t = 0.0;
  for (int k = 0; k < kMaxSteps; ++k) {
    double step = g.gap / lipschitz;
    if constexpr (kConvex) {
      const double k_closing = std::max(0.0, closing(t, g));
      step = std::max(
          step, 2 * g.gap / (k_closing + std::sqrt(k_closing * k_closing + 2 * bend * g.gap)));
    }
    if (step <= stop) return t;
    t += step;
    if (!(t <= horizon)) return std::nullopt;
    g = geometryAt(t);
    if (g.gap <= 0) return t;  // by rounding only: no step passes a root
  }
  return std::nullopt;  // a graze too slow to pass in kMaxSteps (doc/model.md, "Finite obstacles")
}

/// The sphere's row of the first-contact table: `ball` against `shape`, the alternative
/// `placed` holds.
template <class Kind>
std::optional<double> ballFirstContact(const BallMotion& ball, const Kind& shape,
                                       const PlacedShape& placed,
                                       const Eigen::Vector3d& shape_velocity,
                                       const Eigen::Vector3d& shape_acceleration, bool accelerates,
                                       double horizon) {
  const Eigen::Vector3d relative_velocity = shape_velocity - ball.velocity;
  if constexpr (std::is_same_v<Kind, Plane>) {
    const Plane& plane = shape;
    const double gap = plane.normal.dot(ball.centre) - plane.offset - ball.radius;
    const double rate = -plane.normal.dot(relative_velocity);
    if (accelerates) {
      return timeOfImpactPlaneBallistic(gap, rate, plane.normal.dot(ball.acceleration), horizon);
    }
    return timeOfImpactPlane(gap, rate, horizon);
  } else if constexpr (std::is_same_v<Kind, Sphere>) {
    const Sphere& sphere = shape;
    const Eigen::Vector3d separation = sphere.centre - ball.centre;
    const double contact_distance = ball.radius + sphere.radius;
    if (accelerates) {
      // Two bodies under the same gravity keep the straight-line relative problem.
      return timeOfImpactSpheresAccelerated(separation, relative_velocity,
                                            shape_acceleration - ball.acceleration,
                                            contact_distance, horizon);
    }
    return timeOfImpactSpheres<double>(separation, relative_velocity, contact_distance, horizon);
  } else {
    // A finite shape: the ball's motion in the shape's frame (the shape moves straight on).
    // A shape that turns by more than the rounding of its placement within the horizon.
    if (placed.pose.angular_velocity.norm() * horizon > 2.220446049250313e-16) {
      return firstContactTurning(ball, shape, placed, shape_velocity, accelerates, horizon);
    }
    const Eigen::Matrix3d to_shape = placed.pose.transform.linear().transpose();
    RelativeMotion motion;
    motion.centre = to_shape * (ball.centre - placed.pose.transform.translation());
    motion.velocity = to_shape * -relative_velocity;
    if (accelerates) motion.acceleration = to_shape * (ball.acceleration - shape_acceleration);
    motion.radius = ball.radius;
    return firstContactFinite(motion, shape, horizon);
  }
}

/// The table's entries. The sphere's row: a ball (side a, a Sphere) against each kind.
template <class Kind>
ContactGeometry sphereContact(const PlacedShape& a, const PlacedShape& b, double contact_tolerance,
                              ApproachDirection approach) {
  const Sphere& ball = std::get<Sphere>(a.shape);
  return ballGeometry(ball.centre, ball.radius, std::get<Kind>(b.shape), b, contact_tolerance,
                      approach);
}

template <class Kind>
std::optional<double> sphereFirstContact(const MovingShape& a, const MovingShape& b,
                                         bool accelerates, double horizon) {
  const Sphere& sphere = std::get<Sphere>(a.placed.shape);
  BallMotion ball;
  ball.centre = sphere.centre;
  ball.radius = sphere.radius;
  ball.velocity = a.velocity;
  ball.acceleration = a.acceleration;
  return ballFirstContact(ball, std::get<Kind>(b.placed.shape), b.placed, b.velocity,
                          b.acceleration, accelerates, horizon);
}

/// A reversed entry: the entry of the kinds in the other order, the sides swapped (and the
/// approach with them); the normal then points from b into a and is reversed, the surface
/// velocity at the point is a's and becomes b's (its pose's v + w x r, as every entry gives it).
ContactGeometry reversedContact(const PlacedShape& a, const PlacedShape& b,
                                double contact_tolerance, ApproachDirection approach);
std::optional<double> reversedFirstContact(const MovingShape& a, const MovingShape& b,
                                           bool accelerates, double horizon);

using Table = std::array<std::array<NarrowPhaseEntry, kShapeKinds>, kShapeKinds>;
constexpr std::size_t kSphereKind = static_cast<std::size_t>(ShapeKind::kSphere);

template <std::size_t kKind>
constexpr void addSphereEntries(Table& table) {
  using Kind = std::variant_alternative_t<kKind, Shape>;
  table[kSphereKind][kKind] = {&sphereContact<Kind>, &sphereFirstContact<Kind>, false};
  if constexpr (kKind != kSphereKind) {
    table[kKind][kSphereKind] = {&reversedContact, &reversedFirstContact, true};
  }
}

template <std::size_t... kKinds>
constexpr Table makeTable(std::index_sequence<kKinds...>) {
  Table table{};
  (addSphereEntries<kKinds>(table), ...);
  return table;
}

/// Rows: side a's kind; columns: side b's. Entries left empty are not yet answered.
constexpr Table kTable = makeTable(std::make_index_sequence<kShapeKinds>());

const NarrowPhaseEntry& entryOf(const Shape& a, const Shape& b) {
  return kTable[a.index()][b.index()];
}

ContactGeometry reversedContact(const PlacedShape& a, const PlacedShape& b,
                                double contact_tolerance, ApproachDirection approach) {
  const auto back = [&] { return Eigen::Vector3d(-approach()); };
  ContactGeometry result = entryOf(b.shape, a.shape).contact(b, a, contact_tolerance, back);
  if (result.valid) {
    result.normal = -result.normal;
    std::swap(result.lever_a, result.lever_b);
    result.surface_velocity = b.pose.velocityAt(result.point - b.pose.transform.translation());
  }
  return result;
}

std::optional<double> reversedFirstContact(const MovingShape& a, const MovingShape& b,
                                           bool accelerates, double horizon) {
  return entryOf(b.placed.shape, a.placed.shape).first_contact(b, a, accelerates, horizon);
}

}  // namespace

const char* kindName(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::kPlane:
      return "plane";
    case ShapeKind::kSphere:
      return "sphere";
    case ShapeKind::kBox:
      return "box";
    case ShapeKind::kCylinder:
      return "cylinder";
    case ShapeKind::kCapsule:
      return "capsule";
    case ShapeKind::kMesh:
      return "mesh";
  }
  return "unknown";
}

const NarrowPhaseEntry& narrowPhaseEntry(ShapeKind a, ShapeKind b) {
  return kTable[static_cast<std::size_t>(a)][static_cast<std::size_t>(b)];
}

Status narrowPhaseCovers(ShapeKind a, ShapeKind b, const std::string& field) {
  const NarrowPhaseEntry& entry = narrowPhaseEntry(a, b);
  if (entry.contact != nullptr && entry.first_contact != nullptr) return Ok{};
  return Error{field, std::string("not yet: the contact of a ") + kindName(a) + " with a " +
                          kindName(b) + " (only a ball's contacts are answered yet)"};
}

ContactGeometry contactGeometry(const PlacedShape& a, const PlacedShape& b,
                                double contact_tolerance, ApproachDirection approach) {
  const NarrowPhaseEntry& entry = entryOf(a.shape, b.shape);
  if (entry.contact == nullptr) return ContactGeometry{};  // not yet (narrowPhaseCovers)
  return entry.contact(a, b, contact_tolerance, approach);
}

std::optional<double> firstContact(const MovingShape& a, const MovingShape& b, bool accelerates,
                                   double horizon) {
  const NarrowPhaseEntry& entry = entryOf(a.placed.shape, b.placed.shape);
  if (entry.first_contact == nullptr) return std::nullopt;  // not yet (narrowPhaseCovers)
  return entry.first_contact(a, b, accelerates, horizon);
}

std::optional<double> firstContact(const BallMotion& ball, const PlacedShape& placed,
                                   const Eigen::Vector3d& shape_velocity,
                                   const Eigen::Vector3d& shape_acceleration, bool accelerates,
                                   double horizon) {
  return std::visit(
      [&](const auto& shape) {
        return ballFirstContact(ball, shape, placed, shape_velocity, shape_acceleration,
                                accelerates, horizon);
      },
      placed.shape);
}

namespace {

template <class Finite>
ContactGeometry finiteGeometryOf(const Eigen::Vector3d& centre, double radius, const Finite& shape,
                                 const RigidPose& pose, double contact_tolerance) {
  constexpr double kEps = 2.220446049250313e-16;
  const Eigen::Matrix3d& axes = pose.transform.linear();
  const Eigen::Vector3d& origin = pose.transform.translation();
  const NearestFeature nearest = nearestFeature(shape, axes.transpose() * (centre - origin));
  ContactGeometry result;
  result.normal = -(axes * nearest.outward);  // from the ball into the shape
  result.gap = nearest.distance - radius;
  result.tolerance = contact_tolerance * radius +
                     16 * kEps *
                         (centre.lpNorm<Eigen::Infinity>() + origin.lpNorm<Eigen::Infinity>() +
                          boundingRadius(shape) + radius);
  result.valid = true;
  result.bounded = true;
  if (std::isfinite(nearest.turning_radius) && nearest.turning_radius > 0) {
    result.turning_radius = nearest.turning_radius;
    result.curvature = 1.0 / nearest.turning_radius;
    result.turning_axis = axes * nearest.axis;
    result.axial_share = nearest.axial_share;
  }
  const Eigen::Vector3d on_shape = origin + axes * nearest.point;
  result.point = 0.5 * (Eigen::Vector3d(centre + radius * result.normal) + on_shape);
  result.surface_velocity = pose.velocityAt(result.point - origin);
  result.lever_a = radius * result.normal;
  result.lever_b = axes * nearest.point;
  return result;
}

}  // namespace

ContactGeometry finiteGeometry(const Eigen::Vector3d& centre, double radius, const Cuboid& box,
                               const RigidPose& pose, double contact_tolerance) {
  return finiteGeometryOf(centre, radius, box, pose, contact_tolerance);
}
ContactGeometry finiteGeometry(const Eigen::Vector3d& centre, double radius,
                               const Cylinder& cylinder, const RigidPose& pose,
                               double contact_tolerance) {
  return finiteGeometryOf(centre, radius, cylinder, pose, contact_tolerance);
}
ContactGeometry finiteGeometry(const Eigen::Vector3d& centre, double radius, const Capsule& capsule,
                               const RigidPose& pose, double contact_tolerance) {
  return finiteGeometryOf(centre, radius, capsule, pose, contact_tolerance);
}
ContactGeometry finiteGeometry(const Eigen::Vector3d& centre, double radius, const Mesh& mesh,
                               const RigidPose& pose, double contact_tolerance) {
  return finiteGeometryOf(centre, radius, mesh, pose, contact_tolerance);
}

bool mayReach(const PlacedShape& placed, const Box& box) {
  return std::visit(Dispatch{[&](const Plane& plane) {
                               // The box's lowest point along the normal: does it reach the plane?
                               const Eigen::Vector3d centre = 0.5 * (box.low + box.high);
                               const Eigen::Vector3d half = 0.5 * (box.high - box.low);
                               return plane.normal.dot(centre) -
                                          plane.normal.cwiseAbs().dot(half) <=
                                      plane.offset;
                             },
                             [&](const Sphere& sphere) {
                               const Box post{sphere.centre.array() - sphere.radius,
                                              sphere.centre.array() + sphere.radius};
                               return post.overlaps(box);
                             },
                             [&](const auto& finite) {
                               // Its bounding sphere's box, Box::about's written out: with
                               // Box::about this visit took 4 instructions a call more.
                               const Eigen::Vector3d& centre = placed.pose.transform.translation();
                               const double reach = boundingRadius(finite);
                               const Box bound{centre.array() - reach, centre.array() + reach};
                               return bound.overlaps(box);
                             }},
                    placed.shape);
}

double boundingRadiusOf(const Shape& shape) {
  return std::visit(Dispatch{[](const Plane&) { return std::numeric_limits<double>::infinity(); },
                             [](const Sphere& sphere) { return sphere.radius; },
                             [](const auto& finite) { return boundingRadius(finite); }},
                    shape);
}

bool mayReachMoving(const PlacedShape& placed, const Box& box, double from, double to) {
  const RigidPose& pose = placed.pose;
  if (pose.velocity.isZero() && pose.angular_velocity.isZero()) return mayReach(placed, box);
  if (std::holds_alternative<Plane>(placed.shape)) return true;
  // The pose's origin is the shape's centre (a sphere's too) and moves at |v| (shapeAt).
  return Box::about(pose.transform.translation(), reachOver(placed, from, to)).overlaps(box);
}

double reachOver(const PlacedShape& placed, double from, double to) {
  const RigidPose& pose = placed.pose;
  return boundingRadiusOf(placed.shape) +
         pose.velocity.norm() * std::max(std::abs(from - pose.time), std::abs(to - pose.time));
}

double contactRadius(const Shape& shape) {
  return std::visit(
      Dispatch{[](const Plane&) { return 0.0; }, [](const Sphere& sphere) { return sphere.radius; },
               [](const auto&) { return 0.0; }},
      shape);
}

}  // namespace collision_response::core
