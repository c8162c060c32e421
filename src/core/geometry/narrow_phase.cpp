#include "geometry/narrow_phase.h"

#include "collision_response/core/time_of_impact.h"
#include "collision_response/core/validation.h"

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

}  // namespace

Shape shapeOf(const ObstacleSpec& spec) {
  switch (spec.shape) {
    case ObstacleShape::kPlane:
      return Plane{spec.normal, spec.offset};
    case ObstacleShape::kSphere:
      return Sphere{spec.position, spec.radius};
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
               }},
      shape);
}

Shape normalized(const Shape& shape) {
  return std::visit(Dispatch{[](const Plane& plane) -> Shape {
                               return Plane{unitVector(plane.normal), plane.offset};
                             },
                             [](const Sphere& sphere) -> Shape { return sphere; }},
                    shape);
}

PlacedShape placeFixed(const ObstacleSpec& spec) {
  PlacedShape placed;
  placed.pose.transform.translation() = spec.position;
  placed.shape = std::visit(Dispatch{[](const Plane& plane) -> Shape {
                                       return Plane{plane.normal.normalized(), plane.offset};
                                     },
                                     [](const Sphere& sphere) -> Shape { return sphere; }},
                            shapeOf(spec));
  return placed;
}

PlacedShape place(const ObstacleSpec& spec, const RigidPose& frame) {
  return std::visit(
      Dispatch{[&](const Plane& plane) {
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
               }},
      shapeOf(spec));
}

PlacedShape shapeAt(const PlacedShape& placed, double time) {
  PlacedShape moved = placed;
  moved.pose.time = time;
  moved.pose.transform.translation() = originAt(placed.pose, time);
  std::visit(Dispatch{[&](Plane& plane) {
                        plane.offset +=
                            plane.normal.dot(placed.pose.velocity) * (time - placed.pose.time);
                      },
                      [&](Sphere& sphere) { sphere.centre = moved.pose.transform.translation(); }},
             moved.shape);
  return moved;
}

std::optional<double> firstContact(const BallMotion& ball, const Shape& shape,
                                   const Eigen::Vector3d& shape_velocity,
                                   const Eigen::Vector3d& shape_acceleration, bool accelerates,
                                   double horizon) {
  const Eigen::Vector3d relative_velocity = shape_velocity - ball.velocity;
  return std::visit(
      Dispatch{[&](const Plane& plane) -> std::optional<double> {
                 const double gap = plane.normal.dot(ball.centre) - plane.offset - ball.radius;
                 const double rate = -plane.normal.dot(relative_velocity);
                 if (accelerates) {
                   return timeOfImpactPlaneBallistic(gap, rate, plane.normal.dot(ball.acceleration),
                                                     horizon);
                 }
                 return timeOfImpactPlane(gap, rate, horizon);
               },
               [&](const Sphere& sphere) -> std::optional<double> {
                 const Eigen::Vector3d separation = sphere.centre - ball.centre;
                 const double contact_distance = ball.radius + sphere.radius;
                 if (accelerates) {
                   // Two bodies under the same gravity keep the straight-line relative problem.
                   return timeOfImpactSpheresAccelerated(separation, relative_velocity,
                                                         shape_acceleration - ball.acceleration,
                                                         contact_distance, horizon);
                 }
                 return timeOfImpactSpheres<double>(separation, relative_velocity, contact_distance,
                                                    horizon);
               }},
      shape);
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
                             }},
                    placed.shape);
}

double contactRadius(const Shape& shape) {
  return std::visit(Dispatch{[](const Plane&) { return 0.0; },
                             [](const Sphere& sphere) { return sphere.radius; }},
                    shape);
}

}  // namespace collision_response::core
