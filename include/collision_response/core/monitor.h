// The impact monitor: body states in, impacts with their post-impact velocities out. No ROS.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "collision_response/core/broadphase.h"
#include "collision_response/core/motion.h"
#include "collision_response/core/scene.h"
#include "collision_response/core/simultaneous.h"

namespace collision_response::core {

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
};

/// A body's state at one instant, in the fixed frame.
struct BodyStateSample {
  std::size_t body = 0;  ///< index (ImpactMonitor::bodyIndex)
  double time = 0.0;     ///< s, on the monitor's time line
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
};

/// Where a (tf-attached) obstacle is at `time` and how it moves: a straight line from there.
struct ObstaclePose {
  double time = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< sphere: centre
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< plane: unit normal
  double offset = 0.0;                                 ///< plane: normal.x = offset at `time`
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
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

struct StepReport {
  std::vector<ImpactRecord> impacts;
  std::size_t stale_states = 0;  ///< states not newer than their body's last one: dropped
  bool truncated = false;        ///< a guard of MonitorSettings stopped the step
};

/// Watches the scene's bodies and obstacles and finds their impacts.
///
/// Time is a line of doubles (s) chosen by the caller. Each body has a track: a state (time,
/// position, velocity) from which its motion is predicted in a straight line. step(T, states)
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
/// - a state older than its body's track, or a state right after an impact that the monitor
///   applied to that body, does not replace the track (the monitor's post-impact motion is the
///   newer knowledge); the next state does.
class ImpactMonitor {
 public:
  ImpactMonitor(const Scene& scene, const MonitorSettings& settings);

  std::size_t bodyCount() const { return bodies_.size(); }
  std::size_t obstacleCount() const { return obstacles_.size(); }
  const BodySpec& body(std::size_t index) const { return bodies_[index]; }
  const ObstacleSpec& obstacle(std::size_t index) const { return obstacles_[index]; }
  std::optional<std::size_t> bodyIndex(const std::string& id) const;

  /// Where a tf-attached obstacle is, from `pose.time` on. Fixed obstacles are set from the scene.
  void setObstaclePose(std::size_t obstacle, const ObstaclePose& pose);
  /// Where an obstacle was last placed; empty for a tf-attached one not placed yet.
  std::optional<ObstaclePose> obstaclePose(std::size_t obstacle) const;

  /// Live tuning (dynamic_reconfigure): the detection mode, the restitution threshold and the
  /// materials' coefficients (a new combine rule) from the next step on. The tracks are kept;
  /// after a change of detection mode, a pair that overlaps at that instant may be reported
  /// once more. The caller validates the values (as validateScene does).
  void tune(Detection detection, double restitution_threshold, const MaterialTable& materials);

  /// Advances the monitor to `time` with the states given (each at its own time <= `time`;
  /// states after `time` are the caller's error). See the class comment.
  StepReport step(double time, const std::vector<BodyStateSample>& states);

  /// Forgets every track and the time line (after a clock jump back).
  void reset();

  bool started() const { return started_; }
  double now() const { return now_; }
  std::size_t trackedBodies() const;
  /// The plane obstacle a body rests on (gravity), if any.
  std::optional<std::size_t> restingOn(std::size_t body) const;
  /// A body's predicted position and velocity at `time`; empty when it is not tracked.
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> predictedState(std::size_t body,
                                                                            double time) const;

 private:
  static constexpr double kNever = -std::numeric_limits<double>::infinity();

  struct Track {
    bool known = false;
    double time = 0.0;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  ///< gravity, or its part along a plane
    int resting_on = -1;                                     ///< obstacle index, -1: none
    double last_state_time = kNever;
    double last_impact_time = kNever;
  };
  /// Motion models, chosen once per step: no per-pair branch on gravity.
  struct StraightLine {
    static constexpr bool kAccelerates = false;
  };
  struct UnderGravity {
    static constexpr bool kAccelerates = true;
  };
  struct ObstacleTrack {
    bool known = false;
    ObstaclePose pose;
  };
  /// A body (index < bodyCount) and another participant: a body, or obstacle index + bodyCount.
  using Pair = std::pair<std::size_t, std::size_t>;
  struct Geometry {
    Eigen::Vector3d normal;  ///< unit, a -> other
    double gap = 0.0;        ///< m, surface to surface along the normal; < 0 overlapping
    double tolerance = 0.0;  ///< m, |gap| within it is touching
    bool valid = false;      ///< false: coincident centres and no approach: no line of impact
  };

  bool isObstacle(std::size_t participant) const { return participant >= bodies_.size(); }
  bool isPlane(std::size_t participant) const;
  bool known(std::size_t participant) const;
  double inverseMassOf(std::size_t participant) const;
  template <class Motion>
  Eigen::Vector3d positionAt(std::size_t participant, double time) const;
  template <class Motion>
  Eigen::Vector3d velocityAt(std::size_t participant, double time) const;
  Eigen::Vector3d angularVelocityOf(std::size_t participant) const;
  template <class Motion>
  Geometry geometry(const Pair& pair, double time) const;
  template <class Motion>
  std::optional<double> timeOfImpact(const Pair& pair, double from, double horizon) const;
  template <class Motion>
  bool approaching(const Pair& pair, const Eigen::Vector3d& normal, double time) const;
  double restitutionOf(const Pair& pair) const;
  bool resting(const Pair& pair) const;
  /// After a body's velocity changed: does it now rest on a fixed plane (gravity)?
  void updateResting(std::size_t body);

  /// Pairs worth testing in (from, to]: both tracked, not both immovable.
  void candidatePairs(std::vector<Pair>& pairs) const;
  /// The same, those whose boxes swept over [from, to] overlap (the broadphase), sorted.
  template <class Motion>
  void broadphasePairs(double from, double to, std::vector<Pair>& pairs);
  /// After `body` changed at `from`: pairs its new motion over [from, to] may form that are
  /// not candidates yet, appended to `pairs`; their indices.
  template <class Motion>
  std::vector<std::size_t> addReachablePairs(std::size_t body, double from, double to,
                                             std::vector<Pair>& pairs,
                                             const std::vector<std::vector<std::size_t>>& pairs_of);
  /// Whether a body's swept box may reach a (fixed) obstacle; moving obstacles always may.
  template <class Motion>
  bool mayReachObstacle(const Box& box, std::size_t obstacle) const;
  /// The box a body sweeps over [from, to], padded by its radius.
  template <class Motion>
  Box sweptBox(std::size_t body, double from, double to) const;

  /// Resolves, in rounds, the pairs of `touching` that approach at `time`; the bodies whose
  /// motion changed are added to `changed`.
  template <class Motion>
  bool resolveInstant(double time, const std::vector<Pair>& touching, StepReport& report,
                      std::vector<std::size_t>& changed);
  void applyStates(const std::vector<BodyStateSample>& states, StepReport& report);
  void forgetStaleBodies(double time);
  template <class Motion>
  StepReport stepContinuous(double time, const std::vector<BodyStateSample>& states);
  template <class Motion>
  StepReport stepDiscrete(double time, const std::vector<BodyStateSample>& states);

  MonitorSettings settings_;
  Detection detection_;
  double restitution_threshold_;
  std::vector<BodySpec> bodies_;         // sorted by id
  std::vector<ObstacleSpec> obstacles_;  // sorted by id
  std::unordered_map<std::string, std::size_t> body_index_;
  std::vector<double> radius_;        // per participant
  std::vector<double> inverse_mass_;  // per body
  std::vector<double> spin_factor_;   // per body, 1/k, 0 without spin
  Effects effects_;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();  // zero without the gravity effect
  ClusterFrictionStep friction_step_ = nullptr;        // null without the friction effect
  std::vector<Plane> fixed_planes_;                    // for resting, with their obstacles:
  std::vector<std::size_t> fixed_plane_obstacle_;
  /// Fills restitution_ and friction_ from the materials' table.
  void computePairCoefficients(const MaterialTable& materials);

  std::vector<std::string> material_names_;       // the scene's materials, indexed
  std::vector<std::size_t> material_;             // per participant, into restitution_
  std::vector<std::vector<double>> restitution_;  // material x material
  std::vector<std::vector<double>> friction_;     // material x material
  std::vector<Track> tracks_;
  std::vector<ObstacleTrack> obstacle_tracks_;
  std::set<Pair> overlapping_;  // discrete: pairs overlapping at the previous step
  /// Working memory of a step, kept so that steps do not allocate.
  struct Scratch {
    std::vector<Pair> pairs;
    std::vector<std::vector<std::size_t>> pairs_of;
    std::vector<double> next_contact;
    std::vector<Geometry> geometry;
    std::vector<char> queued;
    std::vector<Box> boxes;
    std::vector<char> active;
    SpatialHash hash;
    std::vector<std::pair<std::size_t, std::size_t>> body_pairs;
    std::vector<std::pair<double, std::size_t>> events;
    std::vector<std::pair<std::size_t, Box>> changed_boxes;
    std::vector<std::size_t> found;
  };
  Scratch scratch_;
  bool started_ = false;
  double now_ = 0.0;
};

}  // namespace collision_response::core
