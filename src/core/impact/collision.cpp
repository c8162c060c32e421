#include "collision_response/core/collision.h"

#include <Eigen/Geometry>
#include <cmath>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/friction.h"
#include "collision_response/core/mass_properties.h"
#include "collision_response/core/rigid_impact.h"
#include "collision_response/core/scene.h"
#include "collision_response/core/validation.h"
#include "geometry/convex_distance.h"
#include "geometry/narrow_phase.h"
#include "solver/cluster_solver.h"

namespace collision_response::core {
namespace {

constexpr double kEps = 2.220446049250313e-16;

Expected<double> chooseRestitution(const CollisionRequest& request,
                                   const MaterialTable& materials) {
  const bool a_named = !request.a.material.empty();
  const bool b_named = !request.b.material.empty();
  if (a_named && b_named) {
    const auto pair =
        materials.restitution(request.a.material, request.b.material, "a.material", "b.material");
    if (!pair) return pair;
    if (request.restitution != 0.0) {
      return Error{"restitution",
                   "must be 0 when both bodies name a material: the pair's coefficient " +
                       formatNumber(*pair) + " is used, got " + formatNumber(request.restitution)};
    }
    return pair;
  }
  if (a_named != b_named) {
    const std::string named = a_named ? "a" : "b";
    const std::string unnamed = a_named ? "b" : "a";
    return Error{unnamed + ".material",
                 "is empty while " + named +
                     ".material is set: name both materials (their "
                     "pair's coefficient is used) or neither (restitution is used)"};
  }
  if (auto status = checkRestitution(request.restitution, "restitution"); !status) {
    return status.error();
  }
  return request.restitution;
}

Expected<Effects> parseEffects(const std::vector<std::string>& names) {
  Effects effects;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (auto status = addEffect(names[i], "effects[" + std::to_string(i) + "]", effects); !status) {
      return status.error();
    }
  }
  return effects;
}

Expected<double> chooseFriction(const CollisionRequest& request, const MaterialTable& materials) {
  if (!request.a.material.empty() && !request.b.material.empty()) {
    const auto pair =
        materials.friction(request.a.material, request.b.material, "a.material", "b.material");
    if (pair && request.friction != 0.0) {
      return Error{"friction",
                   "must be 0 when both bodies name a material: the pair's "
                   "coefficient " +
                       formatNumber(*pair) + " is used, got " + formatNumber(request.friction)};
    }
    return pair;
  }
  if (auto status = checkFriction(request.friction, "friction"); !status) return status.error();
  return request.friction;
}

/// A body of the request as the cluster solver sees it (with spin, its moment of inertia).
ClusterBody clusterBody(const Body& body, bool spin) {
  ClusterBody cluster_body;
  cluster_body.inverse_mass = inverseMass(body);
  cluster_body.velocity = body.velocity;
  cluster_body.angular_velocity = body.angular_velocity;
  cluster_body.radius = body.radius;
  if (spin)
    cluster_body.spin_factor = spinFactor(cluster_body.inverse_mass, body.radius, body.inertia);
  return cluster_body;
}

/// Where the request's bodies meet: the unit normal a -> b, the point, and each body's lever arm
/// from its centre to its own surface point there (ContactPoint, solver_body.h).
struct RequestContact {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d lever_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d lever_b = Eigen::Vector3d::Zero();
  /// m: two shaped bodies whose point was found: their surfaces' distance at the poses given.
  std::optional<double> surface_gap;
};

/// A shaped body's shape where it is: at its position, turned by its orientation.
PlacedShape placedShapeOf(const Body& body) {
  PlacedShape placed;
  placed.shape = shapeOf(shapeSpecOf(body));
  placed.pose.transform = Eigen::Translation3d(body.position) * body.orientation.normalized();
  placed.pose.velocity = body.velocity;
  placed.pose.angular_velocity = body.angular_velocity;
  return placed;
}

/// A given contact point must be within the shaped body's reach (its bounding sphere about its
/// centre, to the rounding of the positions): a lever arm longer than the body is no point of
/// it, most likely a point in another frame.
Status checkWithinReach(const Body& body, const Eigen::Vector3d& point, const std::string& side) {
  const double reach = boundingRadiusOf(shapeOf(shapeSpecOf(body)));
  const double distance = (point - body.position).norm();
  const double rounding =
      16 * kEps *
      (point.lpNorm<Eigen::Infinity>() + body.position.lpNorm<Eigen::Infinity>() + reach);
  if (distance <= reach + rounding) return Ok{};
  return Error{"contact_point",
               formatVector(point) + " is " + formatNumber(distance) + " m from " + side +
                   "'s centre, farther than any point of the " + toString(body.shape) + " " + side +
                   " (" + formatNumber(reach) +
                   " m at most): not a point of its surface (is it in the caller's frame?)"};
}

/// Two spheres: the line of impact (given, or centre to centre), their lever arms their radii
/// along it, the point in the middle of the gap. A given contact point is refused: it would be
/// ignored.
Expected<RequestContact> contactOfSpheres(const CollisionRequest& request) {
  if (request.contact_point) {
    return Error{"contact_point_given",
                 "is true for two spheres: their contact lies on the line of impact, at their "
                 "radii; a contact point is where a box, cylinder or capsule is struck"};
  }
  const auto line_of_impact = lineOfImpact(request.normal, request.a.position, request.b.position);
  if (!line_of_impact) return line_of_impact.error();
  RequestContact contact;
  contact.normal = *line_of_impact;
  contact.lever_a = request.a.radius * contact.normal;  // the balls' lever arms
  contact.lever_b = -request.b.radius * contact.normal;
  // Halves first: two surface points near the largest doubles have a midpoint too.
  contact.point = 0.5 * Eigen::Vector3d(request.a.position + contact.lever_a) +
                  0.5 * Eigen::Vector3d(request.b.position + contact.lever_b);
  return contact;
}

/// Two shaped bodies count as touching, and a face or an edge as lying flat, within this share
/// of their reaches (plus the rounding of their positions): 2^-30, about 1e-9.
constexpr double kTouchingShare = 0x1p-30;

/// A shaped body's convex shape in its own frame (a mesh is refused before: checkBodyShape).
ConvexShape convexShapeOf(const Body& body) {
  const Shape shape = shapeOf(shapeSpecOf(body));
  if (const auto* box = std::get_if<Cuboid>(&shape)) return *box;
  if (const auto* cylinder = std::get_if<Cylinder>(&shape)) return *cylinder;
  if (const auto* capsule = std::get_if<Capsule>(&shape)) return *capsule;
  return std::get<Sphere>(shape);
}

/// The part of a shape farthest along a direction, to within a band: a point (a box's corner, a
/// cylinder's rim point, a capsule's round end, a sphere's point), a segment (a box's edge, a
/// cylinder's or a capsule's side: `length` long along `along`) or a face (a box's face, a
/// cylinder's cap).
struct TouchingFeature {
  int dimension = 0;  ///< 0 a point, 1 a segment, 2 a face
  Eigen::Vector3d along = Eigen::Vector3d::Zero();
  double length = 0.0;
  const char* name = "point";
  /// A corner, an edge or a rim: its surface has no one normal there (a face, a cap, a round
  /// side or end has).
  bool sharp = false;
  /// Unit, world: a sharp curve's direction at the point (an edge's, a rim's tangent); zero at a
  /// corner.
  Eigen::Vector3d tangent = Eigen::Vector3d::Zero();
};

/// The feature of `shape` (turned by `turn`, world from shape) farthest along the unit world
/// direction `direction`: the two ends of an edge of a box across axis i differ along it by
/// 2 h_i |d_i| (d the direction in the shape's frame), a cylinder's cap's rim points by
/// 2 r |d_xy|, a side's ends by 2 h |d_z|; within `band` they are equally far.
TouchingFeature touchingFeature(const ConvexShape& shape, const Eigen::Matrix3d& turn,
                                const Eigen::Vector3d& direction, double band) {
  const Eigen::Vector3d d = turn.transpose() * direction;
  TouchingFeature feature;
  const auto segment = [&](const Eigen::Vector3d& along, double length, const char* name) {
    feature.dimension = 1;
    feature.along = along;
    feature.length = length;
    feature.name = name;
  };
  if (const auto* box = std::get_if<Cuboid>(&shape)) {
    int flat = 0;
    for (int i = 0; i < 3; ++i) {
      if (2 * box->half_size[i] * std::abs(d[i]) <= band) {
        ++flat;
        segment(turn.col(i), 2 * box->half_size[i], "edge");
      }
    }
    feature.sharp = flat < 2;
    if (flat == 1) feature.tangent = feature.along;
    if (flat == 0) feature.name = "corner";
    if (flat >= 2) {
      feature.dimension = 2;
      feature.name = "face";
    }
  } else if (const auto* cylinder = std::get_if<Cylinder>(&shape)) {
    if (2 * cylinder->radius * std::hypot(d.x(), d.y()) <= band) {
      feature.dimension = 2;
      feature.name = "cap";
    } else if (2 * cylinder->half_length * std::abs(d.z()) <= band) {
      segment(turn.col(2), 2 * cylinder->half_length, "side");
    } else {
      feature.name = "rim";
      feature.sharp = true;
      // The rim point's radial direction is d's across the axis; its tangent z x that.
      feature.tangent = turn * Eigen::Vector3d(-d.y(), d.x(), 0.0).normalized();
    }
  } else if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    if (2 * capsule->half_length * std::abs(d.z()) <= band) {
      segment(turn.col(2), 2 * capsule->half_length, "side");
    } else {
      feature.name = "end";
    }
  }
  return feature;
}

/// Whether two features touch at one point: one of them a point, or two segments that cross
/// (not parallel: the shorter one's ends part from the other's line by more than the band).
bool touchAtOnePoint(const TouchingFeature& a, const TouchingFeature& b, double band) {
  if (a.dimension == 0 || b.dimension == 0) return true;
  if (a.dimension == 1 && b.dimension == 1) {
    return a.along.cross(b.along).norm() * std::min(a.length, b.length) > band;
  }
  return false;
}

/// Whether two touching features have one normal: one of them a face or round (a cap, a round
/// side or end), or two sharp curves that cross (edges or rims: the normal across both
/// tangents, which part by more than the band over the smaller body's reach). A corner on
/// anything sharp, or two such curves along each other, has a cone of normals: any plane through
/// the point between them separates them.
bool touchWithOneNormal(const TouchingFeature& a, const TouchingFeature& b, double band,
                        double reach) {
  if (!a.sharp || !b.sharp) return true;
  return a.tangent.cross(b.tangent).norm() * reach > band;
}

/// Where two shaped bodies are nearest: the unit normal a -> b along their closest points, the
/// closest point of each surface, and their surfaces' distance (0 touching).
struct ClosestPoints {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();
  double gap = 0.0;
};

/// The closest points of two shaped bodies at their positions and orientations (convexDistance:
/// GJK on their exact support functions), for a contact point or normal not given (`missing`:
/// the field whose refusal it is, `unset` what it is, "is false"; `give`: what the caller should
/// give instead). Touching: their
/// distance is within the band (kTouchingShare of their reaches), or they overlap by so little
/// that moving b from a by the band along the line of their centres parts them. Where they touch,
/// the closest points alone give no direction (their difference is rounding): b is moved from a
/// along the normal so far found by `lift` (1/16 of the smaller reach), the normal taken from the
/// closest points there, until it settles; the true normal is such a search's fixed point (both
/// bodies lie on either side of the plane through their closest points across it, so moving b
/// along it moves the closest points apart along it and no nearer pair appears), reached at once
/// where either side touches with a face, a flat side or a margin (a capsule's or a sphere's).
/// Refused by name: bodies that overlap by more, and where the point is missing, bodies that
/// touch along a face or an edge (a box flat on a box, a cylinder on its side): their contact is
/// not one point.
Expected<ClosestPoints> closestPointsOfShapes(const CollisionRequest& request,
                                              const std::string& missing, const std::string& unset,
                                              const std::string& give, bool need_point,
                                              bool need_normal) {
  const Body& a = request.a;
  const Body& b = request.b;
  const ConvexShape shape_a = convexShapeOf(a);
  const ConvexShape shape_b = convexShapeOf(b);
  const Eigen::Matrix3d turn_a = a.orientation.normalized().toRotationMatrix();
  const Eigen::Matrix3d turn_b = b.orientation.normalized().toRotationMatrix();
  const double reach_a = reachOf(shape_a);
  const double reach_b = reachOf(shape_b);
  const double scale = a.position.lpNorm<Eigen::Infinity>() + b.position.lpNorm<Eigen::Infinity>() +
                       reach_a + reach_b;
  const double band = kTouchingShare * (reach_a + reach_b) + 16 * kEps * scale;
  const double tolerance = 16 * kEps * scale;
  const PlacedConvex placed_a(shape_a, turn_a, a.position);
  const auto distanceMovingB = [&](const Eigen::Vector3d& shift) {
    return convexDistance(placed_a, PlacedConvex(shape_b, turn_b, b.position + shift), tolerance);
  };
  const std::string pair =
      std::string("the ") + toString(a.shape) + " a and the " + toString(b.shape) + " b";
  const ConvexDistance given = distanceMovingB(Eigen::Vector3d::Zero());
  Eigen::Vector3d normal = given.normal;
  const bool touching = given.overlapping || given.upper <= band;
  if (touching) {
    const Eigen::Vector3d centres = b.position - a.position;
    if (centres == Eigen::Vector3d::Zero()) {
      return Error{missing, unset + ", but a and b overlap (their centres are both at " +
                                formatVector(a.position) + "): " + give};
    }
    const Eigen::Vector3d line = centres.normalized();
    const ConvexDistance moved = distanceMovingB(band * line);
    if (moved.overlapping || moved.upper < 0) {
      // How far b must move from a along the line of their centres to part from it: at most
      // the overlap of their shadows on that line (moved that far, the shadows part), found by
      // bisection to 2^-40 of it (an upper bound: the end that is apart).
      const PlacedConvex placed_b(shape_b, turn_b, b.position);
      double apart = line.dot(placed_a.support(line)) + placed_a.margin() -
                     line.dot(placed_b.support(-line)) + placed_b.margin();
      double inside = 0.0;
      for (int halving = 0; halving < 40; ++halving) {
        const double middle = 0.5 * (inside + apart);
        const ConvexDistance there = distanceMovingB(middle * line);
        (there.overlapping || there.upper < 0 ? inside : apart) = middle;
      }
      return Error{missing, unset + ", but a and b overlap by " + formatNumber(apart) +
                                " m along the line of their centres (" + pair +
                                " intersect at the positions and orientations given; b moved " +
                                "that far from a parts them): " + give};
    }
    normal = moved.normal;
  }
  ClosestPoints closest;
  closest.gap = given.overlapping ? 0.0 : std::max(given.upper, 0.0);
  const double lift = std::min(reach_a, reach_b) / 16;
  for (int round = 0; round < 64; ++round) {
    const Eigen::Vector3d shift = lift * normal;
    const ConvexDistance apart = distanceMovingB(shift);
    const bool settled = (apart.normal - normal).norm() <= 16 * kEps;
    normal = apart.normal;
    closest.point_a = apart.point_a;
    closest.point_b = apart.point_b - shift;
    if (settled) break;
  }
  closest.normal = normal;
  const TouchingFeature on_a = touchingFeature(shape_a, turn_a, normal, band);
  const TouchingFeature on_b = touchingFeature(shape_b, turn_b, -normal, band);
  if (need_point) {
    if (!touchAtOnePoint(on_a, on_b, band)) {
      return Error{missing, unset + ", but the " + on_a.name + " of the " + toString(a.shape) +
                                " a meets the " + on_b.name + " of the " + toString(b.shape) +
                                " b flat (within " + formatNumber(band) +
                                " m): their contact is not one point; give the contact point"};
    }
  }
  if (need_normal && touching &&
      !touchWithOneNormal(on_a, on_b, band, std::min(reach_a, reach_b))) {
    return Error{"normal", "is zero, but the " + std::string(on_a.name) + " of the " +
                               toString(a.shape) + " a touches the " + on_b.name + " of the " +
                               toString(b.shape) +
                               " b: there the normal is not one direction (any plane between "
                               "them through the point separates them); give the normal"};
  }
  return closest;
}

/// A sphere and a shaped body, or two shaped bodies: the normal given or (a sphere and a shaped
/// body) the narrow phase's, the point given or the narrow phase's, a sphere's lever arm its
/// radius along the normal, a shaped body's from its centre to the point (given) or to its own
/// surface point (found).
Expected<RequestContact> contactOfShapes(const CollisionRequest& request) {
  const Body& a = request.a;
  const Body& b = request.b;
  if (auto status = checkFinite(request.normal, "normal"); !status) return status.error();
  if (request.contact_point) {
    if (auto status = checkFinite(*request.contact_point, "contact_point"); !status) {
      return status.error();
    }
  }
  const bool given_normal = request.normal != Eigen::Vector3d::Zero();
  RequestContact contact;
  const bool a_sphere = a.shape == BodyShape::kSphere;
  const bool b_sphere = b.shape == BodyShape::kSphere;
  if (!a_sphere && !b_sphere) {
    // What is not given is found from the shapes: the normal along their closest points, the
    // point in the middle of them, each lever arm to the body's own closest point.
    if (!request.contact_point || !given_normal) {
      const bool need_point = !request.contact_point;
      const auto closest = closestPointsOfShapes(
          request, need_point ? "contact_point_given" : "normal",
          need_point ? "is false" : "is zero",
          need_point
              ? (given_normal ? "give the contact point" : "give the contact point and the normal")
              : "give the normal",
          need_point, !given_normal);
      if (!closest) return closest.error();
      contact.normal = closest->normal;
      if (need_point) {
        // Halves first, as for two spheres: the midpoint of points near the largest doubles.
        contact.point = 0.5 * closest->point_a + 0.5 * closest->point_b;
        contact.lever_a = closest->point_a - a.position;
        contact.lever_b = closest->point_b - b.position;
        contact.surface_gap = closest->gap;
      }
    }
    if (given_normal) contact.normal = unitVector(request.normal);
    if (request.contact_point) {
      contact.point = *request.contact_point;
      contact.lever_a = contact.point - a.position;
      contact.lever_b = contact.point - b.position;
    }
  } else {
    const Body& sphere = a_sphere ? a : b;
    const Body& shaped = a_sphere ? b : a;
    // The narrow phase's normal runs from the sphere into the shaped body: a -> b when the
    // sphere is a, b -> a when it is b.
    const double sphere_is_a = a_sphere ? 1.0 : -1.0;
    const ContactGeometry geometry =
        contactGeometry(sphere.position, sphere.radius, placedShapeOf(shaped), 0.0,
                        [] { return Eigen::Vector3d(Eigen::Vector3d::Zero()); });
    contact.normal = given_normal ? unitVector(request.normal) : sphere_is_a * geometry.normal;
    const Eigen::Vector3d sphere_lever = sphere.radius * (sphere_is_a * contact.normal);
    contact.point = request.contact_point ? *request.contact_point : geometry.point;
    const Eigen::Vector3d shaped_lever =
        request.contact_point ? Eigen::Vector3d(contact.point - shaped.position) : geometry.lever_b;
    contact.lever_a = a_sphere ? sphere_lever : shaped_lever;
    contact.lever_b = a_sphere ? shaped_lever : sphere_lever;
  }
  if (request.contact_point) {
    for (const auto& [body, side] : {std::pair<const Body*, const char*>{&a, "a"},
                                     std::pair<const Body*, const char*>{&b, "b"}}) {
      if (body->shape == BodyShape::kSphere) continue;
      if (auto status = checkWithinReach(*body, contact.point, side); !status) {
        return status.error();
      }
    }
  }
  return contact;
}

/// A side of a rigid impact as the solver sees it. A ball: its sphere's inverse inertia with the
/// spin effect (clusterBody), and without it no turning at all (its angular velocity neither
/// enters the contact's velocity nor changes). A shaped body: its world inverse inertia
/// R I^-1 R^T (its tensor, or the uniform solid of its shape; an immovable body none), turning
/// whatever the effects.
Expected<SolverBody> rigidSideOf(const Body& body, bool spin, const std::string& prefix) {
  if (isBall(body)) {
    SolverBody ball = clusterBody(body, spin);
    if (!spin) ball.angular_velocity = Eigen::Vector3d::Zero();
    return ball;
  }
  SolverBody side;
  side.inverse_mass = inverseMass(body);
  side.velocity = body.velocity;
  side.angular_velocity = body.angular_velocity;
  side.inertia_kind = InverseInertiaKind::kTensor;
  side.radius = body.radius;
  if (isImmovable(body)) return side;  // turned by no inertia of its own: I^-1 = 0
  Eigen::Matrix3d inertia;
  if (body.inertia_tensor) {
    inertia = body.inertia_tensor->matrix();
  } else {
    const auto solid = uniformMassProperties(shapeOf(shapeSpecOf(body)), body.mass, body.inertia,
                                             prefix + ".shape");
    if (!solid) return solid.error();
    inertia = solid->inertia;
  }
  side.inverse_inertia = worldInverseInertia(inertia, body.orientation);
  return side;
}

/// Two balls: a cluster of one contact, through the monitor's solver: friction and spin are
/// chosen in one place (frictionModelFor), and one contact alone is resolveImpact, exact to the
/// last bit.
CollisionOutcome resolveBalls(const CollisionRequest& request, const Eigen::Vector3d& normal,
                              double restitution, double friction, const Effects& runnable) {
  ClusterBody a = clusterBody(request.a, runnable.spin);
  ClusterBody b = clusterBody(request.b, runnable.spin);
  ClusterContact contact;
  contact.a = 0;
  contact.b = 1;
  contact.normal = normal;
  contact.lever_a = request.a.radius * contact.normal;  // the balls' lever arms
  contact.lever_b = -request.b.radius * contact.normal;
  contact.restitution = restitution;
  const ContactResolution solved =
      solveContact(a, b, contact, friction, frictionModelFor(runnable));

  CollisionOutcome outcome;
  outcome.line_of_impact = normal;
  outcome.restitution = restitution;
  outcome.impact.velocity_a = a.velocity;
  outcome.impact.velocity_b = b.velocity;
  outcome.impact.normal_impulse = solved.normal.impulse;
  outcome.impact.approach_speed = solved.normal.approach_speed;
  outcome.impact.approaching = solved.normal.approach_speed > 0;
  outcome.impact.energy_lost = solved.normal.energy_lost;
  outcome.oblique = hasObliqueComponent(request.a.velocity, outcome.line_of_impact) ||
                    hasObliqueComponent(request.b.velocity, outcome.line_of_impact);
  outcome.angular_velocity_a = a.angular_velocity;
  outcome.angular_velocity_b = b.angular_velocity;
  if (runnable.friction) {
    outcome.friction_impulse = solved.friction.impulse;
    outcome.sticking = solved.friction.sticking;
    outcome.impact.energy_lost += solved.friction.energy_lost;
  }
  return outcome;
}

/// One impact of two rigid bodies at `contact` (resolveRigidImpact: Chatterjee and Ruina's law,
/// Newton's e along the normal with the effective mass where frictionless); not approaching,
/// nothing changes. A ball without the spin effect keeps the angular velocity it was given.
Expected<CollisionOutcome> resolveRigid(const CollisionRequest& request,
                                        const RequestContact& contact, double restitution,
                                        double friction, bool spin) {
  const auto side_a = rigidSideOf(request.a, spin, "a");
  if (!side_a) return side_a.error();
  const auto side_b = rigidSideOf(request.b, spin, "b");
  if (!side_b) return side_b.error();
  SolverBody a = *side_a;
  SolverBody b = *side_b;
  ContactPoint point;
  point.a = 0;
  point.b = 1;
  point.normal = contact.normal;
  point.point = contact.point;
  point.lever_a = contact.lever_a;
  point.lever_b = contact.lever_b;
  const auto impact = resolveRigidImpact(a, b, point, restitution, friction);
  if (!impact) return impact.error();

  CollisionOutcome outcome;
  outcome.line_of_impact = contact.normal;
  outcome.restitution = restitution;
  outcome.impact.velocity_a = a.velocity;
  outcome.impact.velocity_b = b.velocity;
  outcome.impact.normal_impulse = impact->normal_impulse;
  outcome.impact.approach_speed = impact->approach_speed;
  outcome.impact.approaching = impact->approach_speed > 0;
  outcome.impact.energy_lost = impact->energy_lost;
  outcome.oblique = hasObliqueComponent(request.a.velocity, outcome.line_of_impact) ||
                    hasObliqueComponent(request.b.velocity, outcome.line_of_impact);
  const auto turned = [spin](const Body& body, const SolverBody& side) {
    return isBall(body) && !spin ? body.angular_velocity : side.angular_velocity;
  };
  outcome.angular_velocity_a = turned(request.a, a);
  outcome.angular_velocity_b = turned(request.b, b);
  outcome.friction_impulse = impact->tangential_impulse.norm();  // 0 frictionless
  outcome.sticking = friction > 0 && outcome.impact.approaching && impact->sticking;
  return outcome;
}

}  // namespace

Expected<CollisionOutcome> computeCollision(const CollisionRequest& request,
                                            const MaterialTable& materials) {
  for (const auto& [body, prefix] : {std::pair<const Body*, const char*>{&request.a, "a"},
                                     std::pair<const Body*, const char*>{&request.b, "b"}}) {
    if (auto status = checkBody(*body, prefix); !status) return status.error();
    if (auto status = checkBodyShape(*body, prefix); !status) return status.error();
  }
  if (isImmovable(request.a) && isImmovable(request.b)) {
    return Error{"b.mass",
                 "a and b are both immovable (mass .inf): at least one body must have "
                 "a finite mass"};
  }
  if (!request.a.id.empty() && request.a.id == request.b.id) {
    return Error{"b.id",
                 "is the same as a.id ('" + request.a.id + "'): a body cannot collide with itself"};
  }
  const auto effects = parseEffects(request.effects);
  if (!effects) return effects.error();
  const bool balls = isBall(request.a) && isBall(request.b);
  const bool spheres =
      request.a.shape == BodyShape::kSphere && request.b.shape == BodyShape::kSphere;
  const auto meeting = spheres ? contactOfSpheres(request) : contactOfShapes(request);
  if (!meeting) return meeting.error();
  const auto restitution = chooseRestitution(request, materials);
  if (!restitution) return restitution.error();
  if (!effects->friction && request.friction != 0.0) {
    return Error{"friction", "is " + formatNumber(request.friction) +
                                 " but the friction effect is not requested (add \"friction\" "
                                 "to effects)"};
  }
  const auto friction =
      effects->friction ? chooseFriction(request, materials) : Expected<double>(0.0);
  if (!friction) return friction.error();

  const Effects runnable = runnableEffects(*effects);
  CollisionOutcome outcome;
  if (balls) {
    outcome = resolveBalls(request, meeting->normal, *restitution, *friction, runnable);
  } else {
    auto rigid = resolveRigid(request, *meeting, *restitution, runnable.friction ? *friction : 0.0,
                              runnable.spin);
    if (!rigid) return rigid.error();
    outcome = *rigid;
  }
  outcome.contact_point = meeting->point;
  outcome.surface_gap = meeting->surface_gap;
  // Finite inputs whose answer is beyond the doubles (masses and speeds of 1e200: an energy of
  // 1e600 J) are refused by name rather than answered with an infinity.
  if (auto status =
          checkRepresentable({namedResult("velocity_a", outcome.impact.velocity_a),
                              namedResult("velocity_b", outcome.impact.velocity_b),
                              namedResult("angular_velocity_a", outcome.angular_velocity_a),
                              namedResult("angular_velocity_b", outcome.angular_velocity_b),
                              namedResult("impulse", outcome.impact.normal_impulse),
                              namedResult("friction_impulse", outcome.friction_impulse),
                              namedResult("energy_lost", outcome.impact.energy_lost),
                              namedResult("contact_point", outcome.contact_point)});
      !status) {
    return status.error();
  }
  return outcome;
}

}  // namespace collision_response::core
