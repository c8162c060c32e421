// A shaped body's lasting contact with one flat face (issue 42, build step 6): a box, cylinder or
// capsule resting, sliding or rolling on a plane or on a face of a box obstacle, under gravity,
// by closed forms; a box (or a hull) touching at one corner or along one edge, rocking or
// spinning on a face, or whose centre of pressure leaves its face, by its tipping motion
// (shaped_pivot.h). What is not modelled yet (a cylinder leaning on its rim, a capsule on one
// end, a cylinder rolling with its axis not across the slope) is refused by name, so that the
// caller says so instead of moving the body through the face.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/monitor.h"
#include "geometry/convex_distance.h"

namespace collision_response::core {

/// m: the touching band: the body's lowest point is within it of the face (as TumblingContact's
/// manifold band).
constexpr double kLastingBand = 1e-9;
/// m/s: a speed below it counts as none: a slide, a slip, a spin about the face's normal (|w_n|
/// times the body's reach), as the balls' slips (doc/model.md, "Lasting contact").
constexpr double kLastingStillSpeed = 1e-9;
/// Of the body's reach: a body whose every point's normal motion could lift it by no more than
/// this (an elastic rise u^2 / (2 g_n)), as the shaped motion's rule for a contact that lasts, has
/// settled: its manifold is its points within max(kLastingBand, kLastingSettled reach) of its
/// lowest, and that normal motion (the points' approach or parting, a rocking turn) is dropped,
/// as the bounces it would make accumulate (energy is lost, never gained).
constexpr double kLastingSettled = 1e-6;
/// Of |g_t| + g_n: gravity's part across a slide (or along a rolling side's axis, or across a
/// resting side's) below it counts as none.
constexpr double kLastingAcrossGravity = 1e-12;

/// The body at the instant its contact begins to last, in its principal frame (as
/// PrincipalBody: its shape about its centre of mass along its principal axes).
struct LastingBody {
  ConvexShape shape;
  Eigen::Vector3d moments = Eigen::Vector3d::Ones();  ///< kg m^2, principal, about x, y, z
  double mass = 0.0;                                  ///< kg
  double time = 0.0;                                  ///< s
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();   ///< m, the centre of mass
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();       ///< rad/s, world
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< world from principal
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();                ///< m/s^2
};

/// The fixed flat face it lasts on: a plane obstacle (unbounded), or a face of a box obstacle
/// (bounded: `half_extent` along `along_u` and `along_v` about `point`).
struct FlatFace {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    ///< on the face
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, out of the face, towards the body
  double friction = 0.0;                              ///< the pair's mu (0: frictionless)
  bool bounded = false;
  Eigen::Vector3d along_u = Eigen::Vector3d::UnitX();  ///< unit, in the face (bounded only)
  Eigen::Vector3d along_v = Eigen::Vector3d::UnitY();
  Eigen::Vector2d half_extent = Eigen::Vector2d::Zero();  ///< m (bounded only)
};

/// One point of the contact's manifold and what it carries.
struct SupportForce {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();           ///< on the face, world
  double normal_force = 0.0;                                 ///< N, >= 0, on the body along n
  Eigen::Vector3d friction_force = Eigen::Vector3d::Zero();  ///< N, on the body, in the face
  /// Unit, towards the body, where the contact's normal is not the face's (the body's own face
  /// on the face's edge: normal_force along it, friction_force at right angles to it); zero: n.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  /// Which of lastingOnFaces' faces it is on (0: the one face of lastingOnFace).
  std::size_t face = 0;
};

/// What an integrated lasting motion (LastingPath) gives at an instant.
struct PathState {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< world from principal
  ContactState state = ContactState::kRolling;  ///< every point sticking, or one sliding
  std::vector<SupportForce> forces;             ///< at the points touching
};

/// A lasting motion with no closed form, integrated to a stated tolerance with dense output:
/// a body tipping over its corners (pivotOnFace) or over the face's edge (tipOverFaceEdge).
class LastingPath {
 public:
  virtual ~LastingPath() = default;
  /// The state at `t` (clamped to [start, until]); the points touching exactly on the face.
  virtual PathState stateAt(double t) const = 0;
  virtual double start() const = 0;
  virtual double until() const = 0;
  /// The accepted steps of the integration (its cost).
  virtual std::size_t steps() const = 0;
};

/// A lasting motion on one face, in closed form over [start, until].
struct LastingMotion {
  ContactState state = ContactState::kResting;
  double start = 0.0;  ///< s
  /// s: where this motion ends (sliding stops, a roll reaches the face's edge, ...); +inf: never.
  double until = std::numeric_limits<double>::infinity();
  /// What happens at `until` (empty for never): "stops" (the caller asks lastingOnFace again
  /// from the state there), or why it is no longer modelled ("reaches the face's edge").
  std::string ends;
  // The state at t in [start, until]: the centre's parabola and the turn, by the closed form.
  Eigen::Vector3d centre0 = Eigen::Vector3d::Zero(), velocity0 = Eigen::Vector3d::Zero(),
                  acceleration = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity0 = Eigen::Vector3d::Zero(),
                  angular_acceleration = Eigen::Vector3d::Zero();    ///< about a fixed axis
  Eigen::Quaterniond orientation0 = Eigen::Quaterniond::Identity();  ///< world from principal
  /// The contact's points (the manifold) and their forces, at `start`; forcesAt gives them at t.
  std::vector<SupportForce> forces;
  /// A body tipping over a corner or an edge of its own (pivotOnFace) or over the face's edge
  /// (tipOverFaceEdge): its integrated path, which the state and the forces at t come from
  /// instead of the closed form.
  std::shared_ptr<const LastingPath> pivot;
  /// A closed-form motion whose manifold changes as it goes (a support cut by the face's edge):
  /// its points and forces at t; empty where they move with the centre.
  std::function<std::vector<SupportForce>(double)> forces_over;

  /// The motion along an integrated `path` from its start to `until`, ending as `ends` says.
  static LastingMotion integrated(std::shared_ptr<const LastingPath> path, double until,
                                  std::string ends);

  Eigen::Vector3d centreAt(double t) const;
  Eigen::Vector3d velocityAt(double t) const;
  Eigen::Vector3d angularVelocityAt(double t) const;
  Eigen::Quaterniond orientationAt(double t) const;
  std::vector<SupportForce> forcesAt(double t) const;
  /// Resting, sliding or rolling at t (a tipping body's points stick or slide as it goes).
  ContactState stateAt(double t) const;
};

/// The lasting motion that starts from `body` touching `face` (its lowest point within
/// kLastingBand of it, its normal motion settled: kLastingSettled), or an Error whose message
/// says what is not modelled yet, for the caller to report (e.g. "not yet: tipping: a cylinder
/// leaning on its rim"), or which input is wrong (`body.mass`, `face.normal`, ...), or that the
/// contact is no lasting one (field `body.velocity`: its points near the face approach or leave
/// it faster than a settled body's). The body does not gain energy (a settled normal motion is
/// dropped), and no point of it goes below the face. The normal forces are the least-norm ones
/// >= 0 that balance m (a - g) and the moment about the centre of mass; each point's friction is
/// in proportion to its normal force (doc/model.md, "Lasting contact of a shaped body"). A box
/// or hull touching at one corner or along one edge, rocking or spinning on a face, or tipping
/// off it, moves by pivotOnFace (integrated to `tolerance`). Points near the face that approach
/// or leave it faster than a settled body's are not of the support (they strike or part).
Expected<LastingMotion> lastingOnFace(const LastingBody& body, const FlatFace& face,
                                      double tolerance = 1e-9);

/// The lasting motion that starts from `body` touching several fixed flat faces at once (a box
/// on the floor against a wall, in a bin's corner, a plank leaning on a wall), each face with its
/// own mu: lastingOnFace's for one face; for several, a box's or a hull's corners within
/// kLastingBand of each face, each sticking, sliding or leaving its face by pivotOnFaces' law,
/// at rest where it is still and they hold it. A cylinder or a capsule against several faces is
/// refused by name (not yet).
Expected<LastingMotion> lastingOnFaces(const LastingBody& body, const std::vector<FlatFace>& faces,
                                       double tolerance = 1e-9);

/// Bounces on one face that accumulate: a body landing flat on a face or a side (every point of
/// its manifold approaching at the same speed u, no slip, no spin about the normal), which the
/// joint frictionless rule sends back at e u, lands again and again under gravity's component
/// into the face g_n; the series ends 2 e u / (g_n (1 - e)) after `body.time` (as a ball's,
/// doc/model.md "Coming to rest"), where the body rests on the face. Empty where the landing is
/// not such a flat one, or e is 1.
std::optional<double> flatBouncesEnd(const LastingBody& body, const FlatFace& face,
                                     double restitution);

}  // namespace collision_response::core
