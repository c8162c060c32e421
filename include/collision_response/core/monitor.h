// The impact monitor: body states in, impacts with their post-impact velocities out. No ROS.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "collision_response/core/scene.h"
#include "collision_response/core/shape.h"

namespace collision_response::core {
namespace monitor {
struct World;
struct ShapedRoom;
using BallPositions = std::function<std::optional<Eigen::Vector3d>(std::size_t body)>;
}  // namespace monitor

struct MonitorSettings {
  /// Two surfaces closer than this fraction of their contact distance (r_a + r_b, or r against a
  /// plane) touch: such contacts at one instant are resolved together (simultaneous contacts).
  /// The rounding of the positions is added, so large coordinates do not defeat it.
  double contact_tolerance = 1e-9;
  /// s: a body with no state for this long is forgotten until its next state.
  double body_timeout = 1.0;
  /// Guards against endless impacts (a ball squeezed between two walls): at most this many
  /// rounds at one instant and this many instants of impact per step; past them the step is
  /// reported truncated.
  int max_rounds_per_instant = 10000;
  int max_instants_per_step = 10000;
  /// Candidate pairs from a spatial hash of the bodies' swept boxes (about linear in the
  /// bodies); false: every pair (for tests that compare the two).
  bool broadphase = true;
  /// false: the monitor moves its bodies (free flight, lasting contact) but looks for no
  /// impacts; impacts come in as states imposed at their instants (advance()). What Playback
  /// moves a scene with.
  bool detect_impacts = true;
  /// What the joint solves of the impact clusters (their normal impulses, then their friction)
  /// may spend in one step, in contact iterations (WorkBound: an iteration over n contacts
  /// counts n, a dense factorisation of n contacts 1 + n^2 / 4 + n^3 / 400). A friction solve
  /// that would pass it stops where it got to (within mu J, no energy added); a cluster whose
  /// normal solve would pass it, and every later one of the step, is locked together with what
  /// touches it (one velocity: its centre of mass's, or its fixed obstacles'), and the bodies are
  /// named in StepReport::over_impact_work (doc/model.md, "Simultaneous contacts"). 0: no bound.
  std::size_t max_impact_work_per_step = 100000;
  /// What the stepped clusters' sub-step solves may spend in one step, in contact iterations
  /// (each iteration of a complementarity solve, and each friction sweep, counts the contacts
  /// of its cluster): a sub-step's solves together get what the step has left, so the step's
  /// total never passes it. A solve stopped there ends its sub-step early, before any contact
  /// closes past its band, or where that is too soon (or nothing is left) holds the cluster's
  /// movable bodies still over it (the stepped clusters' fallback: no body goes into another, no
  /// energy gained), and they are named in StepReport::over_stepped_work (doc/model.md,
  /// "Lasting contact"). 0: no bound.
  std::size_t max_stepped_work_per_step = 6000000;
};

/// A body's state at one instant, in the fixed frame.
struct BodyStateSample {
  std::size_t body = 0;  ///< index (ImpactMonitor::bodyIndex)
  double time = 0.0;     ///< s, on the monitor's time line
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  /// World from body, a unit quaternion: a shaped body's motion starts from it (a ball's is
  /// carried into its track, and does not matter).
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

/// One impact found and resolved.
struct ImpactRecord {
  double time = 0.0;       ///< s, the instant of impact
  std::size_t body_a = 0;  ///< a body index
  std::size_t other = 0;   ///< a body index, or an obstacle index when other_is_obstacle
  bool other_is_obstacle = false;
  Eigen::Vector3d contact_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  ///< unit, a -> other
  double restitution = 0.0;
  double impulse = 0.0;           ///< N s, normal
  double friction_impulse = 0.0;  ///< N s, tangential (friction effect), against b's slip
  double energy_lost = 0.0;       ///< J, normal closed form plus the friction's work
  bool oblique = false;
  Eigen::Vector3d velocity_a_before, velocity_a_after, velocity_b_before, velocity_b_after;
  Eigen::Vector3d angular_velocity_a_before, angular_velocity_a_after;
  Eigen::Vector3d angular_velocity_b_before, angular_velocity_b_after;
};

/// How a lasting contact carries its force.
enum class ContactState {
  kResting,  ///< no slip and no relative motion
  kSliding,  ///< the surfaces slip (frictionless contacts slide as soon as they move)
  kRolling,  ///< no slip at the contact point while the bodies move (static friction)
};
const char* toString(ContactState state);

/// A contact that lasts (gravity): a body rests, slides or rolls on another or on an obstacle.
struct ContactRecord {
  double time = 0.0;       ///< s, the instant the forces below hold
  std::size_t body_a = 0;  ///< a body index
  std::size_t other = 0;   ///< a body index, or an obstacle index when other_is_obstacle
  bool other_is_obstacle = false;
  Eigen::Vector3d contact_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();         ///< unit, a -> other
  double normal_force = 0.0;                                 ///< N, >= 0, on other along the normal
  Eigen::Vector3d friction_force = Eigen::Vector3d::Zero();  ///< N, on other (a: opposite)
  ContactState state = ContactState::kResting;
  double since = 0.0;  ///< s, the instant the contact began to last
};

/// A state taken after an impact that the monitor applied to its body, which lacks that impact
/// (StepReport::contradicted).
struct ContradictedImpact {
  std::size_t body = 0;
  double impact_time = 0.0;  ///< s: the impact's instant (the impact was reported)
  double state_time = 0.0;   ///< s: the state's
  /// m/s: how much of the impact's velocity change the state lacks, along it (more than half).
  double missing = 0.0;
};

/// A contact of a shaped body that the model does not carry yet (issue 42): a lasting contact
/// lastingOnFace refuses, or a shaped body touching a ball or another shaped body.
struct UnmodelledContact {
  std::size_t body = 0;   ///< the shaped body
  std::size_t other = 0;  ///< a body index, or an obstacle index when other_is_obstacle
  bool other_is_obstacle = false;
  double time = 0.0;  ///< s, when it began
  std::string what;   ///< why, e.g. lastingOnFace's message
};

/// A body's flight through air that its integrator could not carry on (StepReport::stalled).
struct StalledFlight {
  std::size_t body = 0;
  double stalled = 0.0;  ///< s: from here the body is held where its flight got to
};

struct StepReport {
  std::vector<ImpactRecord> impacts;
  /// The lasting contacts at the step's time (with the gravity effect), in the order of their
  /// pairs; then each shaped body's, one record per point of its manifold.
  std::vector<ContactRecord> contacts;
  std::size_t stale_states = 0;  ///< states not newer than their body's last one: dropped
  /// States of shaped bodies whose motion cannot start from them (an orientation that is not a
  /// rotation, a value not finite): dropped, the track kept. The node's intake refuses such
  /// states first, naming the field.
  std::size_t refused_states = 0;
  /// States older than their body's motion in the monitor (it starts at an impact or a change
  /// of lasting contact found after the state's instant, within the same step): set aside, the
  /// motion kept.
  std::size_t states_set_aside = 0;
  /// States taken although they lack an impact found since their body's previous state: the
  /// body's velocity falls short of the model's after the impact by more than half the impact's
  /// change, back towards before it. The state is the body's track; the impact stays reported.
  /// (A source that applies the impacts samples the state after one before it hears of it; any
  /// other source says the impact did not happen.)
  std::vector<ContradictedImpact> contradicted;
  /// Flights through air (drag, magnus) that stalled in this step (a speed or an air factor
  /// too large for the integrator, or its steps run out): the body is held where the flight got
  /// to until its motion starts again (a state, an impact). Each flight once.
  std::vector<StalledFlight> stalled;
  /// A guard of MonitorSettings ran out (rounds at an instant, instants in the step).
  bool truncated = false;
  /// What the fallbacks did when a guard ran out, so that no body goes into another: a cluster
  /// resolved as one inelastic cluster, the step's bodies held where they were, or a stepped
  /// cluster held still over a sub-step its solve could not keep the gaps of.
  std::size_t fallbacks = 0;
  /// Bodies in stepped clusters at the step's end (doc/model.md, "Lasting contact").
  std::size_t stepped_bodies = 0;
  /// Bodies whose exact work ran over the scene's exact_work_budget in this step: from that
  /// instant they (and the bodies near them) are stepped. Each also counts in `fallbacks`.
  std::vector<std::size_t> over_budget;
  /// What the exact model spent in this step, in all (World::work's units: an instant a body's
  /// motion changed, a solve of its curved lasting contact); with the gravity effect.
  std::size_t exact_work = 0;
  /// What the impact clusters' joint solves spent in this step, in contact iterations: at most
  /// MonitorSettings::max_impact_work_per_step.
  std::size_t impact_work = 0;
  /// Bodies of the impact clusters the step's impact work bound cut short (sorted, each once):
  /// a joint friction solve stopped where it got to, or the cluster and what touches it locked
  /// together (MonitorSettings::max_impact_work_per_step). No energy gained, momentum kept (where
  /// no obstacle takes part), no contact among them left approaching.
  std::vector<std::size_t> over_impact_work;
  /// What the stepped clusters' solves spent in this step, in contact iterations: at most
  /// MonitorSettings::max_stepped_work_per_step.
  std::size_t stepped_work = 0;
  /// Bodies of stepped clusters held still over a sub-step (or what was left of it) because the
  /// step's stepped work was spent (sorted, each once; MonitorSettings::
  /// max_stepped_work_per_step). Not counted in `fallbacks`.
  std::vector<std::size_t> over_stepped_work;
  /// Contacts of shaped bodies the model does not carry yet, each once, when it begins (a held
  /// body's with its obstacle; a shaped body touching a ball or another shaped body at the
  /// step's end): the shaped body is held where it is (an obstacle's), or not resolved (a
  /// body's), never moved through silently.
  std::vector<UnmodelledContact> unmodelled;
};

/// Watches the scene's bodies and obstacles and finds their impacts.
///
/// Time is a line of doubles (s) chosen by the caller. Each body has a track: a state (time,
/// position, velocity) from which its motion is predicted in a straight line (a parabola under
/// gravity). A shaped body (a box, cylinder or capsule) is moved by its own exact motion from its
/// last state, orientation included, among the obstacles (doc/model.md, "Shaped bodies in the
/// monitor"): its impacts with obstacles and its lasting contacts on one flat face are reported
/// as a ball's, what the model does not carry yet in StepReport::unmodelled. step(T, states)
/// looks for impacts over (now, T] along the predicted motion, resolves them (updating the
/// tracks with the post-impact velocities), and then takes the states at T as the new tracks.
///
/// - continuous: the exact instant of first contact of every pair (timeOfImpact*), earliest
///   first; impacts that the source already applied are found too, and a pair found in contact
///   is not found again while it overlaps (an impact is found when contact begins).
/// - discrete: overlap tested at T only, between approaching pairs that did not already overlap
///   at the previous step.
/// - simultaneous contacts: at an instant of impact, every pair that touches (within
///   contact_tolerance) and approaches is resolved with resolveSimultaneous, in rounds, until
///   none approaches: a cradle's impact travels ball by ball; balls striking one ball from both
///   sides at once share the impulse symmetrically. Bodies are indexed by sorted id, so nothing
///   depends on the order of the scene's list or of the states.
/// - effects (chosen once, from the scene): gravity makes the motion parabolic (the instants of
///   contact from the ballistic roots) and lets a body rest on a fixed plane; friction and spin
///   act at impacts (applyFriction). An effect that is off is not on any path: the motion model
///   is a template parameter chosen once per step, the friction step a function chosen at
///   construction.
/// - a state newer than its body's last one replaces its track (a monitor follows its input),
///   but for one older than the track's motion (an impact or a change of lasting contact found
///   after the state's instant in the same step), which is set aside and counted. A state that
///   lacks an impact found since its body's previous state is taken and reported
///   (StepReport::contradicted); the impact stays reported.
class ImpactMonitor {
 public:
  ImpactMonitor(const Scene& scene, const MonitorSettings& settings);
  ImpactMonitor(const ImpactMonitor& other);
  ImpactMonitor& operator=(const ImpactMonitor& other);
  ImpactMonitor(ImpactMonitor&&) noexcept;
  ImpactMonitor& operator=(ImpactMonitor&&) noexcept;
  ~ImpactMonitor();

  std::size_t bodyCount() const;
  std::size_t obstacleCount() const;
  const BodySpec& body(std::size_t index) const;
  const ObstacleSpec& obstacle(std::size_t index) const;
  std::optional<std::size_t> bodyIndex(const std::string& id) const;
  /// The scene it watches, as given (its lists in the scene's order), with what tune changed.
  const Scene& scene() const;

  /// Where a tf-attached obstacle's frame is (`frame`: the frame's motion, fixed <- frame), from
  /// `frame.time` on: its shape is placed there and moves straight on. Fixed obstacles are set
  /// from the scene.
  void setObstaclePose(std::size_t obstacle, const RigidPose& frame);
  /// Places an obstacle's shape where `placed` says, moving on as it says (another monitor's
  /// obstaclePose: a prediction starts where the live monitor's obstacles are).
  void placeObstacle(std::size_t obstacle, const PlacedShape& placed);
  /// Where an obstacle was last placed (its shape in the fixed frame, and its motion); empty for
  /// a tf-attached one not placed yet.
  std::optional<PlacedShape> obstaclePose(std::size_t obstacle) const;

  /// Live tuning (dynamic_reconfigure): the detection mode, the restitution threshold and the
  /// materials' coefficients (a new combine rule) from the next step on. The tracks are kept;
  /// after a change of detection mode, a pair that overlaps at that instant may be reported
  /// once more. The caller validates the values (as validateScene does). scene() says them.
  void tune(Detection detection, double restitution_threshold, const MaterialTable& materials);

  /// Advances the monitor to `time` with the states given (each at its own time <= `time`;
  /// states after `time` are the caller's error). See the class comment.
  StepReport step(double time, const std::vector<BodyStateSample>& states);

  /// Advances the monitor to `time` by its own motion, without states, imposing each of
  /// `imposed` (a body's position and velocities at an instant in (now, time], in time order)
  /// at its instant: the body continues from there, and its lasting contacts are formed again.
  /// An imposed state is the motion just after an impact: the body keeps its orientation.
  StepReport advance(double time, const std::vector<BodyStateSample>& imposed);

  /// Forgets every track and the time line (after a clock jump back).
  void reset();

  bool started() const;
  double now() const;
  std::size_t trackedBodies() const;
  /// The plane obstacle a body rests on (gravity), if any.
  std::optional<std::size_t> restingOn(std::size_t body) const;
  /// A body's predicted position and velocity at `time`; empty when it is not tracked.
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> predictedState(std::size_t body,
                                                                            double time) const;
  /// The instant a body's predicted motion holds from (its last state, impact, or change of
  /// lasting contact): predictedState is that one motion from there on.
  double motionSince(std::size_t body) const;
  /// A body's predicted angular velocity at `time` (zero when it is not tracked).
  Eigen::Vector3d predictedAngularVelocity(std::size_t body, double time) const;
  /// The orientation of a body's last state (identity when it is not tracked).
  Eigen::Quaterniond lastOrientation(std::size_t body) const;
  /// A body's predicted orientation at `time` (world from body; identity when it is not
  /// tracked): a shaped body's followed by its motion (flight, impacts, lasting contact); a
  /// ball's is its last state's (a ball's does not matter).
  Eigen::Quaterniond predictedOrientation(std::size_t body, double time) const;
  /// Whether the body is moved as a shaped body (issue 42; doc/model.md, "Shaped bodies in the
  /// monitor"): a shaped body, or a ball among shaped bodies ("Balls among shaped bodies").
  bool shaped(std::size_t body) const;

 private:
  /// step() for the balls alone (the shaped bodies' states left out).
  StepReport stepBalls(double time, const std::vector<BodyStateSample>& states);
  /// Where each tracked ball is at `time` (for a shaped body's unmodelled contact with one).
  monitor::BallPositions ballsAt(double time) const;

  std::unique_ptr<monitor::World> world_;  // the scene, the tracks and a step's working memory
  std::unique_ptr<monitor::ShapedRoom> shaped_;  // the shaped bodies' tracks
};

}  // namespace collision_response::core
