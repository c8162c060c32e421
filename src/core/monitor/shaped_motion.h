// The motion of a shaped body among obstacles (issue 42): a box, cylinder or capsule (or a sphere
// given a tensor) moved by its exact flight (its centre's parabola, its torque-free rotation:
// free_rotation.h), its certified first contacts (tumbling_contact.h) and its impacts with
// rotation (rigid_impact.h), until its contact with an obstacle would last. One engine, which the
// shaped body's prediction (shaped_prediction.h: its samples, crossing and budgets) and the
// monitor (monitor.cpp: a shaped body's track) both run.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"
#include "contact/shaped_lasting.h"
#include "geometry/convex_distance.h"
#include "geometry/tumbling_contact.h"

namespace collision_response::core {

/// A body in its principal frame: its shape about its centre of mass, along the axes of its
/// principal moments, and where that frame is in the body's own.
struct PrincipalBody {
  ConvexShape shape;
  Eigen::Vector3d moments = Eigen::Vector3d::Ones();  ///< kg m^2, about the frame's x, y, z
  double mass = 0.0;                                  ///< kg
  /// The body's frame from the principal frame (a rotation), and the centre of mass in the
  /// body's frame.
  Eigen::Quaterniond body_from_principal = Eigen::Quaterniond::Identity();
  Eigen::Vector3d centre_of_mass = Eigen::Vector3d::Zero();
};

/// A shaped body's principal frame from its shape and mass (bodyMassProperties). A tensor with
/// products of inertia turns the frame: a box then becomes the hull of its corners; a cylinder
/// or a capsule given such a tensor is refused (`field`.inertia: not yet). A mesh body is the
/// convex hull of its vertices (convexHull; `field`.resource names a mesh not loaded or of no
/// volume).
Expected<PrincipalBody> principalBody(const BodySpec& body, const std::string& field);

/// The body `body` (a flight of `principal`) as the impact solvers see it at `time`: 1 / m, its
/// inverse inertia tensor in the world (R J^-1 R^T), its velocities.
SolverBody solverBodyOf(const PrincipalBody& principal, const TumblingBody& body, double time);

/// m/s and rad/s: bounds on the centre's speed and the turning speed, over `span` seconds from
/// a state (`velocity`; `angular_velocity` in the world; `orientation` world from principal), of
/// a body that gains no energy but gravity's (impacts and lasting contact with fixed obstacles):
/// its kinetic energy K(s) <= K + m |g| V span, so V <= |g| span + sqrt((|g| span)^2 + 2 K / m),
/// and |w| <= sqrt(2 K_max / J_min) (a margin of 1e-6 of the energy for a tipping's integration).
std::pair<double, double> energySpeedBounds(const PrincipalBody& principal,
                                            const Eigen::Vector3d& velocity,
                                            const Eigen::Vector3d& angular_velocity,
                                            const Eigen::Quaterniond& orientation,
                                            const Eigen::Vector3d& gravity, double span);

/// An obstacle the shaped body may meet: the model's index and where it is placed.
struct ShapedObstacle {
  std::size_t obstacle = 0;
  PlacedShape placed;
};

/// What the shaped body's motion needs of the scene.
struct ShapedScene {
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  ///< gravity, or zero
  double restitution_threshold = 0.0;                      ///< m/s, as the scene's
  /// The pair's coefficients with an obstacle (by its model index); an Error ends the motion.
  std::function<Expected<double>(std::size_t obstacle)> restitution;
  std::function<Expected<double>(std::size_t obstacle)> friction;
  std::size_t body = 0;  ///< the body index its impact records name
  /// The tolerance a tipping body's motion is integrated to (pivotOnFace): the scene's
  /// contact_integration_tolerance.
  double integration_tolerance = 1e-9;
  /// What the air does to the body in flight (drag, magnus: bodyAirFactors, on its mean
  /// cross-section; zero where the scene has neither), integrated to `flight_tolerance` (the
  /// scene's flight_integration_tolerance). Lasting contact moves without air, as a ball's.
  AirFactors air;
  double flight_tolerance = 1e-9;
};

/// The hand-overs of a body's tipping to its events ("resumes", shaped_pivot.h) its motion takes:
/// one at an instant, and at most kMaxResumes within kResumeWindow seconds; more, it chatters
/// between supports (a cube at the edge of tipping, mu h = w / 2), which is not modelled yet.
class ResumeGuard {
 public:
  static constexpr int kMaxResumes = 50;
  static constexpr double kResumeWindow = 1e-3;  ///< s
  /// Empty where a hand-over at `time` may go on; else why not.
  std::optional<std::string> refuse(double time) {
    if (time == last_) return std::string("its tipping ends where it starts");
    last_ = time;
    if (!(time - window_start_ <= kResumeWindow)) {
      window_start_ = time;
      count_ = 0;
    }
    if (++count_ > kMaxResumes) {
      return std::string("its tipping chatters between supports (over 50 hand-overs within 1 ms)");
    }
    return std::nullopt;
  }

 private:
  double last_ = -std::numeric_limits<double>::infinity();
  double window_start_ = -std::numeric_limits<double>::infinity();
  int count_ = 0;
};

/// A shaped body moving among obstacles from a state, flight by flight. next() finds the next
/// event up to a horizon: no contact (a free flight), an impact (resolved: the records appended,
/// the flight after it started; then leave() looks for where the struck points are apart), a
/// graze (touching without approaching, apart again at once), or a contact that lasts.
class ShapedMotion {
 public:
  enum class Event { kFree, kImpact, kGrazed, kLasting };
  struct Found {
    Event event = Event::kFree;
    double time = 0.0;  ///< s: the event's instant (kFree: the horizon)
  };

  /// The body from `state` (its time, centre, velocities and the body frame's orientation).
  static Expected<ShapedMotion> create(PrincipalBody principal, std::vector<ShapedObstacle> placed,
                                       ShapedScene scene, const BodyStateSample& state);

  /// The flight the body is on, from time() on.
  const TumblingBody& flight() const { return flight_; }
  double time() const { return time_; }
  const PrincipalBody& principal() const { return principal_; }
  std::size_t body() const { return scene_.body; }
  double integrationTolerance() const { return scene_.integration_tolerance; }

  /// The body's events go on from `state` (a lasting motion that ends with "resumes": another
  /// point reaches the face, or the body leaves it), every obstacle looked at from there.
  Status restartFrom(const BodyStateSample& state);

  /// The body's state at `time` on `flight` (a flight of this body): its centre's, and the body
  /// frame's orientation.
  BodyStateSample stateOn(const TumblingBody& flight, double time) const;

  /// The first obstacle (model index) the body is inside at its start, by more than the touching
  /// band (kLastingBand: a box set flush on a table is not).
  std::optional<std::size_t> insideAtStart() const;

  /// The next event up to `horizon`: the impacts' records appended to `impacts`. `through`: the
  /// horizon is a step's end that the motion goes on past (the monitor's): a contact at the
  /// horizon itself is found too (a state given touching an obstacle), and an obstacle found apart
  /// up to it is looked at from there on (kFree), not from its older instant again.
  Expected<Found> next(double horizon, std::vector<ImpactRecord>& impacts, bool through = false);
  /// After an impact (next() said kImpact): whether the points struck leave their obstacles
  /// (they are looked at again from there); false: the contact lasts (lastingWith()). Struck at
  /// several obstacles at once, those whose points part on their own are looked at again once
  /// apart, and the contact lasts with the others.
  bool leave(double horizon);

  /// A contact found to last that is none (lastingOnFace: its points near the face all leave or
  /// approach it faster than a settled body's, Error field "body.velocity"): its obstacles are
  /// looked at again from the first instant their gap is open, by doubling steps from the
  /// separation's (up to 1 ms); false where it does not open (the caller holds the body).
  bool part(double horizon);

  /// Another obstacle meeting the body in its lasting motion: when, which (its model index), and
  /// whether it strikes (its gap closing faster than a settled body's, kLastingSettled) or only
  /// touches.
  struct Strike {
    double time = 0.0;
    std::size_t obstacle = 0;
    bool closing = false;
  };
  /// A lasting motion (`lasting`, on the faces of the obstacles `resting_on`: shaped_lasting.h)
  /// watches its faces alone: the first instant in [from, until] at which another obstacle, fixed
  /// or moving, touches the body moving so (certified as firstContact, by a BoundedMotion: its
  /// centre's and its turn's speeds at either end of the span where they are closed forms, a
  /// tipping's by its energy); empty where none does.
  std::optional<Strike> struckWhileLasting(const LastingMotion& lasting,
                                           const std::vector<std::size_t>& resting_on, double from,
                                           double until) const;
  /// The obstacles as placed now (a tf frame's link moved: the monitor's revisions), looked at
  /// from `time` on; the motion found so far is kept.
  void placeObstacles(std::vector<ShapedObstacle> placed, double time);

  /// The obstacles (model indices) of the contact found to last, and its manifold.
  std::vector<std::size_t> lastingWith() const;
  /// The contact found to last as the body on flat faces there, for lastingOnFaces: one per
  /// obstacle of lastingWith() (in its order), each a fixed plane or a box whose face the
  /// manifold lies on (within its band); else an Error naming what is not modelled yet.
  Expected<std::pair<LastingBody, std::vector<FlatFace>>> lastingFaces() const;
  /// After an impact (kImpact): the instant a flat landing's bounces accumulate on the face
  /// struck (flatBouncesEnd, from the body as it landed), if they do; none through air (its
  /// closed form is the parabola's).
  std::optional<double> flatBouncesEnd() const;

  /// The instant friction at several points struck at once was first left out (where the joint
  /// law does not apply: resolveRigidSimultaneous's frictionless_rule), if ever.
  std::optional<double> frictionlessAt() const { return frictionless_at_; }

  /// s: where its present flight through air stalled (its integrator could go no further: a
  /// speed or an air factor too large for it), the body held where it got to from there; infinite
  /// where it has not (so far as it was integrated). A flight that stalls within its first
  /// millisecond (a throw at 1e50 m/s) is held still there at once: its speed would bound its
  /// first contact's steps to nothing.
  double stalledAt() const;

 private:
  /// A contact of the body with one obstacle at an instant.
  struct ObstacleContact {
    std::size_t obstacle = 0;  ///< the model's index
    std::size_t slot = 0;      ///< in obstacles_
    TumblingContact contact;
  };
  /// After an impact whose contact lasts: the obstacles the body touches there without having
  /// struck them join the lasting contact (lasting_).
  void addTouching();
  /// An obstacle placed, and from when it is looked at: no contact with it before clear_from;
  /// parted: clear_from is where the body was found apart from it after touching it.
  struct Watched {
    ShapedObstacle placed;
    double clear_from = 0.0;
    bool parted = false;
  };

  ShapedMotion(PrincipalBody principal, ShapedScene scene, TumblingBody flight, double time)
      : principal_(std::move(principal)),
        scene_(std::move(scene)),
        flight_(std::move(flight)),
        time_(time) {}

  std::vector<ObstacleContact> firstContacts(const TumblingBody& body, double horizon,
                                             bool through) const;
  SolverBody solverBody(const TumblingBody& body, double time) const;
  void clearUntil(double time, const std::vector<ObstacleContact>& contacts, double apart);
  /// The flight just started at `time` held still where it stalls within kStallProbe (stalledAt).
  void holdIfStalled(double time);
  Expected<bool> resolve(const TumblingBody& body, SolverBody& moving,
                         const std::vector<ObstacleContact>& contacts, double time,
                         std::vector<ImpactRecord>& impacts);
  ImpactRecord recordOf(const ClusterContact& point, std::size_t obstacle, double time,
                        const SolverBody& other) const;
  std::optional<double> separation(const TumblingBody& body, double time,
                                   const std::vector<ObstacleContact>& left, double horizon) const;
  Expected<std::pair<LastingBody, FlatFace>> faceOf(const std::vector<ObstacleContact>& contacts,
                                                    const TumblingBody& body, double time) const;

  PrincipalBody principal_;
  ShapedScene scene_;
  TumblingBody flight_;
  double time_ = 0.0;
  std::vector<Watched> obstacles_;
  std::vector<ObstacleContact> struck_;   // the last impact's, until leave()
  std::vector<ObstacleContact> lasting_;  // the contact found to last
  double lasting_time_ = 0.0;             // and when
  std::optional<TumblingBody> landed_;    // the flight the last impact ended
  std::optional<double> frictionless_at_;
  std::optional<double> stalled_at_;  // the flight that stalled at once, held still (stalledAt)
};

}  // namespace collision_response::core
