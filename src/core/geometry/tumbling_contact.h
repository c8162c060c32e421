// The first contact of a tumbling body, certified (issue 42, build step 5): a shaped body's
// impacts with obstacles in the monitor, the scene player and its prediction
// (src/core/monitor/shaped_motion.h).
//
// A tumbling body is a convex shape (convex_distance.h: a sphere, box, cylinder, capsule or
// convex hull) in its body frame, whose origin is the centre of mass and whose axes are the
// principal axes; its centre on its parabola (position, velocity, constant acceleration) and
// its orientation the exact torque-free rotation (free_rotation.h).
//
// Its gap to what it may meet (the signed distance of the surfaces, certified from below and
// above, the closest points, the normal and each side's lever arm): a plane exactly by the
// body's support function; a sphere (a ball), a box, a cylinder, a capsule and another tumbling
// body by GJK on the exact support functions (convexDistance, to `distance_tolerance`); a
// triangle mesh (concave: the unsigned distance to its triangles) by GJK against the triangles
// near the body, found by the mesh's hierarchy. Obstacles fixed or moving as a PlacedShape does
// (narrow_phase.h, shapeAt: straight on, a finite shape on the screw of its pose's twist: a robot
// link on a tf frame is such).
//
// firstContact: conservative advancement (Mirtich, "Impulse-based dynamic simulation of rigid
// body systems", PhD thesis, Berkeley, 1996) on the certified lower bound g of the gap. Over a
// step of length s from t no material point of either side moves relative to the other by more
// than V s + A s^2 / 2, with V = |v_a(t) - v_b(t)| + Omega_a rho_a + Omega_b rho_b (the centres'
// relative velocity, and each side's bound on |w| times its farthest point from its centre) and
// A = |a_a - a_b| + |w_o| |v_o| (the centres' relative acceleration; an obstacle's origin on its
// screw turns its velocity at |w_o|; a body flying through air adds the air's bound, drag and
// lift times its speed bound squared, air_flight.h). The gap, a distance between the two sets,
// changes no faster than the points move, so it has no root before
// s = 2 g / (V + sqrt(V^2 + 2 A g)). |w| of a free rotation is bounded for all time by
// sqrt(2 E / J_min), E its kinetic energy (2 E = sum J_i w_i^2 >= J_min |w|^2). Against a plane
// a second bound, along its normal n, where that steps further (planeStep in the source, proved
// there): the centre's height moves exactly on its parabola (through air, within the air's
// bound of it), and how far the body reaches below its centre, h = R cos(theta) (R its reach),
// rises only as theta falls, no faster than |n x w| (exactly where w is fixed, else bounded by
// sqrt(2 E / J_min)): a body sliding along the plane or turning steadily about its normal, or a
// corner straight below its centre, takes long steps. The advancement stops where a step falls
// below `time_tolerance` (1e-12 s by default, with the rounding of the instant) or g reaches 0:
// every instant before the one returned is certified apart (never missed), and the gap there is
// >= 0 (never inside) and at most V time_tolerance plus the GJK tolerance; the true first contact
// is after it by at most that gap over the closing speed.
//
// At the instant found, the contact manifold: the points of either side that may touch first
// (contactCandidates: a box's corners, a hull's vertices, a cylinder's rim points, a capsule's
// ends) whose distance to the other side is within `manifold_band` of the closest gap, and the
// closest pair itself where no candidate is near it, reduced to at most 4 (the deepest, the
// farthest from it, the largest triangle, the largest quadrilateral): a box landing flat on a
// plane gives its four corners. Points where edges cross inside two faces are not yet candidates
// (two boxes face to face, turned, give the corners of each inside the other only).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/shape.h"
#include "geometry/air_flight.h"
#include "geometry/convex_distance.h"
#include "geometry/free_rotation.h"

namespace collision_response::core {

/// A convex body in flight: its centre on a parabola (or flying through air: throughAir) and its
/// exact free rotation.
class TumblingBody {
 public:
  /// `shape` in the body frame (the principal axes about the centre of mass, the moments
  /// `principal_moments` about x, y and z); at `time` its centre at `position` moving at
  /// `velocity`, accelerating at `acceleration` throughout, its orientation `orientation` (world
  /// from body) and its angular velocity `angular_velocity` (world). Refused by name: a shape
  /// whose numbers are not finite and positive ("shape.radius", "shape.half_size.x", a hull of
  /// fewer than 4 vertices or one that is not finite: "shape.vertices[3]"), a position, velocity
  /// or acceleration that is not finite ("velocity.z"), the time not finite ("time"), and what
  /// FreeRotation::create refuses.
  static Expected<TumblingBody> create(const ConvexShape& shape,
                                       const Eigen::Vector3d& principal_moments, double time,
                                       const Eigen::Vector3d& position,
                                       const Eigen::Vector3d& velocity,
                                       const Eigen::Vector3d& acceleration,
                                       const Eigen::Quaterniond& orientation,
                                       const Eigen::Vector3d& angular_velocity);

  /// The same body flying through air (the drag and magnus effects, doc/model.md, "Effects in
  /// detail"): its centre's flight integrated (AirFlight, to `tolerance`) under its acceleration
  /// as gravity, drag and the Magnus force of its own turning, w(t) of its free rotation; the air
  /// puts no torque on it (its rotation stays torque-free). Itself where both factors are 0.
  TumblingBody throughAir(const AirFactors& air, double tolerance) const;

  const ConvexShape& shape() const { return shape_; }
  Eigen::Vector3d positionAt(double time) const {
    if (air_) return air_->position(0, time);
    const double dt = time - time_;
    return position_ + dt * (velocity_ + (0.5 * dt) * acceleration_);
  }
  Eigen::Vector3d velocityAt(double time) const {
    if (air_) return air_->velocity(0, time);
    return velocity_ + (time - time_) * acceleration_;
  }
  /// m/s^2: gravity (its parabola's acceleration; through air, the part besides the air's).
  const Eigen::Vector3d& acceleration() const { return acceleration_; }
  /// m/s^2: the air's part of its centre's acceleration never exceeds it over [from, to]
  /// (AirFlight::airAccelerationBound); 0 on a parabola.
  double airAccelerationBound(double from, double to) const {
    return air_ ? air_->airAccelerationBound(acceleration_.norm(), from, to) : 0.0;
  }
  /// m/s^2: |a(t)| of its centre never exceeds it over [from, to].
  double accelerationBound(double from, double to) const {
    return acceleration_.norm() + airAccelerationBound(from, to);
  }
  /// s: where its flight through air stalled (AirFlight::stalledAt: held from there); infinite
  /// where it did not, or on a parabola.
  double stalledAt() const {
    return air_ ? air_->stalledAt() : std::numeric_limits<double>::infinity();
  }
  Eigen::Quaterniond orientationAt(double time) const {
    return rotation_.orientation(time - time_);
  }
  Eigen::Vector3d angularVelocityAt(double time) const {
    return rotation_.angularVelocity(time - time_);
  }
  /// The velocity at `time` of the body's material point at `point` (world).
  Eigen::Vector3d pointVelocityAt(double time, const Eigen::Vector3d& point) const {
    return velocityAt(time) + angularVelocityAt(time).cross(point - positionAt(time));
  }
  /// rad/s: |w| never exceeds it, sqrt(2 E / J_min) (with a few ulps).
  double angularSpeedBound() const { return angular_speed_bound_; }
  /// rad/s: |n x w| never exceeds it for the unit `n`: exactly so (with a few ulps) where w is
  /// fixed (at rest, an isotropic body, a steady turn about a principal axis), else
  /// angularSpeedBound().
  double spinAcrossBound(const Eigen::Vector3d& n) const {
    return steady_spin_ ? n.cross(angular_velocity_).norm() * (1 + 64 * 2.220446049250313e-16)
                        : angular_speed_bound_;
  }
  /// rad/s^2: |w'| never exceeds it: 0 where w is fixed, else, by Euler's equations
  /// (J_x w_x' = (J_y - J_z) w_y w_z, ...; |w_y w_z| <= |w|^2 / 2), angularSpeedBound()^2 / 2
  /// times the sum of |J_y - J_z| / J_x and its turns (with a few ulps).
  double angularAccelerationBound() const { return angular_acceleration_bound_; }
  /// m: the body's farthest point from its centre.
  double reach() const { return reach_; }
  /// The same motion of its shape shrunk by `distance` (>= 0) towards its centre: a sphere's,
  /// box's, cylinder's and capsule's sizes less `distance`, a hull's vertices scaled about the
  /// centre by 1 - distance / reach (never below half a size). No surface point moves in by more
  /// than `distance`: what overlaps an obstacle shrunk is inside it by more than that.
  TumblingBody shrunkBy(double distance) const;

 private:
  TumblingBody(const ConvexShape& shape, const FreeRotation& rotation)
      : shape_(shape), rotation_(rotation) {}
  ConvexShape shape_;
  FreeRotation rotation_;
  double time_ = 0.0;
  Eigen::Vector3d position_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d acceleration_ = Eigen::Vector3d::Zero();
  double angular_speed_bound_ = 0.0;
  double angular_acceleration_bound_ = 0.0;
  bool steady_spin_ = false;                                    // w fixed in the world
  Eigen::Vector3d angular_velocity_ = Eigen::Vector3d::Zero();  // w at time_ (world)
  double reach_ = 0.0;
  std::shared_ptr<const AirFlight> air_;  // through air: the centre's flight
};

/// The gap between a tumbling body (side a) and another side b at one instant.
struct SurfaceGap {
  /// m: the surfaces' distance is certainly in [gap, gap_upper]; overlapping: gap is -infinity.
  double gap = 0.0;
  double gap_upper = 0.0;
  bool overlapping = false;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, from a into b
  /// The closest points of a's and b's surfaces (world).
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();
  /// m: from each side's centre (a body's centre of mass; an obstacle's pose origin, as
  /// ContactGeometry's) to its point.
  Eigen::Vector3d lever_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d lever_b = Eigen::Vector3d::Zero();
  /// m/s: n . (v_a(point_a) - v_b(point_b)), > 0 closing.
  double approach_speed = 0.0;
};

/// One point of a contact manifold: where each side touches, their lever arms and the gap there.
struct ManifoldPoint {
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d lever_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d lever_b = Eigen::Vector3d::Zero();
  double gap = 0.0;  ///< m, from point_a to point_b along the normal
};

struct TumblingContact {
  double time = 0.0;
  SurfaceGap closest;                   ///< the closest points, the normal, the lever arms
  std::vector<ManifoldPoint> manifold;  ///< 1 to 4 points touching at once
};

struct FirstContactOptions {
  double time_tolerance = 1e-12;      ///< s: the advancement stops where a step is shorter
  double distance_tolerance = 1e-12;  ///< m: GJK's (upper - lower bound)
  double manifold_band = 1e-9;        ///< m: a point this near the closest gap touches too
  int max_steps = 1 << 16;
};

struct FirstContactResult {
  std::optional<TumblingContact> contact;  ///< none: no contact in [from, clear_until]
  /// No contact before it: from + horizon where there is none within the horizon; earlier
  /// where the step budget ran out first (a graze too slow to pass in max_steps), or `from`
  /// where the body started inside.
  double clear_until = 0.0;
  bool inside_at_start = false;  ///< the sides overlapped at `from`: no first contact
  int steps = 0;
};

/// A body whose motion is known at every instant but is no flight (a lasting contact's on a face,
/// a tipping: shaped_lasting.h): what it is at an instant, and bounds on its points' speeds over
/// the whole query, from which firstContact advances as for a flight (the header's comment, its
/// own acceleration 0: the speeds bounded throughout).
struct BoundedMotion {
  /// The body at `time` (its state there, no acceleration); empty where none is made (the query
  /// ends there, apart until then).
  std::function<std::optional<TumblingBody>(double time)> at;
  double centre_speed = 0.0;   ///< m/s: |v| of its centre never exceeds it in the query
  double angular_speed = 0.0;  ///< rad/s: |w| never exceeds it in the query
  double reach = 0.0;          ///< m: its farthest point from its centre
};

/// The gap between `body` and `obstacle` (moved to `time` by shapeAt) at `time`.
SurfaceGap gapAt(const TumblingBody& body, const PlacedShape& obstacle, double time,
                 double distance_tolerance = 1e-12);
/// Whether `body` is inside `obstacle` at `time` by more than `band`: overlapping it, and still
/// so shrunk by `band` (TumblingBody::shrunkBy; flush faces whose distance rounds below 0 touch).
/// The first contact (firstContact) counts such a start inside (inside_at_start), a touching one
/// its contact.
bool insideBeyond(const TumblingBody& body, const PlacedShape& obstacle, double time, double band);
/// The gap between two tumbling bodies at `time`.
SurfaceGap gapAt(const TumblingBody& a, const TumblingBody& b, double time,
                 double distance_tolerance = 1e-12);

/// The first instant in [from, from + horizon] at which `body` touches `obstacle` (certified:
/// the header's comment), and the contact there. Touching at `from` (within the tolerances) is
/// a contact at `from` whatever its approach speed (given in the contact: the caller knows).
FirstContactResult firstContact(const TumblingBody& body, const PlacedShape& obstacle, double from,
                                double horizon, const FirstContactOptions& options = {});
/// The same for a body moving as `body` says (BoundedMotion), certified by its bounds.
FirstContactResult firstContact(const BoundedMotion& body, const PlacedShape& obstacle, double from,
                                double horizon, const FirstContactOptions& options = {});
/// The same between two tumbling bodies (a ball is a tumbling sphere).
FirstContactResult firstContact(const TumblingBody& a, const TumblingBody& b, double from,
                                double horizon, const FirstContactOptions& options = {});

}  // namespace collision_response::core
