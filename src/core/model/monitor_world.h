// The monitor's data, shared by the stages of a step: what the scene is (participants and their
// coefficients), what is known of each body (its track), and the step's working memory. Plain
// data with a few lookups; the stages (candidate_pairs, contact_schedule, instant_resolver) are
// functions over it, and monitor.cpp runs them in order.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "collision_response/core/friction.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"
#include "geometry/air_flight.h"
#include "geometry/broadphase.h"
#include "geometry/motion.h"
#include "geometry/narrow_phase.h"
#include "model/constrained_motion.h"
#include "model/obstacle_index.h"
#include "solver/cluster_solver.h"
#include "solver/contact_forces.h"

namespace collision_response::core::monitor {

inline constexpr double kEps = std::numeric_limits<double>::epsilon();
inline constexpr double kNever = -std::numeric_limits<double>::infinity();
/// A pair approaches when its normal relative velocity is below -64 ulps of the speeds: what a
/// resolved impact leaves behind by rounding (e = 0 gives d' = 0 only up to a few ulps) must not
/// count as a new approach.
inline constexpr double kApproachTolerance = 64 * kEps;
/// s: a state stamped this little after an impact is at the impact's instant (ROS stamps are
/// whole nanoseconds): one that lacks the impact there keeps the monitor's motion after it (taken,
/// the pair would strike again there and the impact be published twice).
inline constexpr double kSameInstant = 1e-9;

/// What the monitor knows of a body: a state from which its motion is predicted.
struct Track {
  bool known = false;
  double time = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  /// World from body, its last state's: carried, not yet followed nor read (a ball's does not
  /// matter; issue 42 gives bodies shapes).
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  /// Gravity, or (in lasting contact) what gravity and the contact forces leave.
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_acceleration = Eigen::Vector3d::Zero();  ///< rolling: from friction
  int group = -1;  ///< its group of lasting contact (World::groups), -1: none
  /// Curved lasting contact: the integrated step its motion follows (body `slot` of it); with
  /// the drag or magnus effect, a free body's flight through air (AirFlight). Either replaces the
  /// parabola; null otherwise.
  std::shared_ptr<const IntegratedMotion> constrained;
  std::size_t slot = 0;
  double integration_step = 0.0;  ///< the integrator's last step size, a guess for the next
  /// Its stepped cluster (World::stepping), -1: none. Its motion is then a straight line over
  /// the cluster's sub-step (acceleration 0: gravity is given as a velocity at the sub-step's
  /// start, stepped_contact.h).
  int stepped = -1;
  /// s: the end of the sub-step whose gravity its velocity holds already.
  double kicked_until = kNever;
  double last_state_time = kNever;
  double last_impact_time = kNever;
  /// World::steps of the step whose impact last changed its motion (0: none yet).
  std::uint64_t impact_step = 0;
  /// m/s: what the impacts at last_impact_time changed its velocity by (zero: none, or a state
  /// imposed): a state after it lacking half of that contradicts it (applyStates).
  Eigen::Vector3d impact_change = Eigen::Vector3d::Zero();
  /// Its flight through air (constrained) stalled and was reported (World::stalled).
  bool stall_reported = false;
  /// Its exact work ran over Scene::exact_work_budget: it is stepped with the bodies near it (in
  /// any number) until it is near none of them.
  bool over_budget = false;
};

struct ObstacleTrack {
  bool known = false;
  PlacedShape placed;
};

/// A body (index < bodyCount) and another participant: a body, or obstacle index + bodyCount.
using Pair = std::pair<std::size_t, std::size_t>;

/// Where two participants are relative to each other at one instant (the narrow phase's answer).
using Geometry = ContactGeometry;

/// A contact that lasts: the pair presses with a steady force (ContactForce), at `time`.
struct GroupContact {
  Pair pair;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  ///< unit, a -> other
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  ContactForce force;
  double since = 0.0;  ///< s, the instant it began to last
};

/// Bodies that rest, slide or roll on each other and on obstacles (lasting contact), and the
/// motion their contact forces give them from `time` on, until `next_event` (a slip that stops).
struct ContactGroup {
  bool alive = false;
  double time = 0.0;
  std::vector<std::size_t> bodies;     ///< sorted
  std::vector<GroupContact> contacts;  ///< the pressed ones, in the canonical order of pairs
  double next_event = std::numeric_limits<double>::infinity();
  bool curved = false;  ///< its motion is integrated, up to World::step_end
  /// Curved: its integrated motion, and how far its bodies' pairs were scheduled along it (the
  /// frontier: an event, integrateFurther). Where its mode changed, its end is an event too,
  /// until taken (integratedEvent).
  std::shared_ptr<const ConstrainedStep> step;
  double scheduled_to = std::numeric_limits<double>::infinity();
  bool step_event_taken = false;
  /// Of its step's solves (ConstrainedStep::solves), those charged to its bodies' work already.
  std::size_t charged = 0;
};

/// A contact of a stepped cluster over its sub-step.
struct SteppedClusterContact {
  Pair pair;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  ///< unit, a -> other
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double keeping_impulse = 0.0;   ///< N s over the sub-step: a force of impulse / its length
  double friction_impulse = 0.0;  ///< N s, on other along friction_direction
  Eigen::Vector3d friction_direction = Eigen::Vector3d::Zero();
  bool sticking = false;
};

/// Bodies near each other advanced together by time steps (stepped_contact.h): from `start`,
/// each moves in a straight line until `end`, the next instant of the grid, or earlier where
/// the solve fell short (then it is solved again there).
struct SteppedCluster {
  std::vector<std::size_t> bodies;              ///< sorted
  std::vector<SteppedClusterContact> contacts;  ///< in the canonical order of their pairs
  double start = 0.0;
  double end = 0.0;
  bool stale = false;  ///< a member's state was replaced within the sub-step: solve again
};

/// The stepped clusters (doc/model.md, "Lasting contact"): with gravity, at the start of every
/// step and every `time_step` at most within it (the step's interval split into equal sub-steps, so
/// that a source stepping at the same instants, the scene player, moves its clusters by the
/// same sub-steps), the bodies near each other (within what they can move in a sub-step) form
/// connected sets; a set of at least `min_bodies` is advanced by a sub-step of
/// solveSteppedSubstep, the others stay with the exact model.
struct Stepping {
  std::size_t min_bodies = 0;  ///< 0: never
  double time_step = 0.01;     ///< s, a sub-step (one of up to 1.25 times it is not split)
  /// The step being taken: [begin, end] in `substeps` equal sub-steps; `next` the sub-step to
  /// start next (0 at the step's start). The instant `end` starts the next step's first one.
  double begin = 0.0, end = 0.0;
  long substeps = 0, next = 0;
  std::vector<SteppedCluster> clusters;
  /// Per pair, the force that kept its gap over its last sub-step: the next one starts there.
  std::map<Pair, double> keeping_force;
  /// Per pair, the friction force (N, on its b) of its last sub-step: the next one's friction
  /// sweeps start there.
  std::map<Pair, Eigen::Vector3d> friction_force;
  /// Per pair that came into contact in the last sub-step, the speed it closed at (m/s): its
  /// bounce, at the next sub-step, is e times that.
  std::map<Pair, double> arrival_speed;
  /// Sub-steps whose solve could not keep the gaps at all (every body held still).
  std::size_t held = 0;

  bool enabled() const { return min_bodies > 0; }
  /// Sub-step k's start (k = substeps: the step's end).
  double instant(long k) const {
    return k >= substeps
               ? end
               : begin + (end - begin) * static_cast<double>(k) / static_cast<double>(substeps);
  }
  /// Starts a step over [from, to].
  void beginStep(double from, double to) {
    begin = from;
    end = to;
    // An update a little later than the rate time_step names (timer jitter) is not split: up
    // to 1.25 time_step is one sub-step.
    substeps = static_cast<long>(std::ceil((to - from) / (1.25 * time_step)));
    substeps = std::max(substeps, 1L);
    next = 0;
  }
};

/// Working memory of a step, kept so that steps do not allocate once it has grown. A copy of the
/// monitor starts with none.
struct Scratch {
  Scratch() = default;
  Scratch(const Scratch&) {}
  Scratch& operator=(const Scratch&) { return *this; }
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
  ObstacleIndex obstacles;  ///< candidatePairs' (the obstacles' reach over its span)
};

struct World {
  /// The scene as given, tuned (ImpactMonitor::scene): shared by a monitor's copies (a
  /// prediction copies its models often), replaced whole when tuned.
  std::shared_ptr<const Scene> scene;
  MonitorSettings settings;
  Detection detection = Detection::kContinuous;
  double restitution_threshold = 0.0;
  std::vector<BodySpec> bodies;         // sorted by id
  std::vector<ObstacleSpec> obstacles;  // sorted by id
  std::unordered_map<std::string, std::size_t> body_index;
  std::vector<double> radius;        // per participant
  std::vector<double> inverse_mass;  // per body
  std::vector<double> spin_factor;   // per body, 1/k, 0 without spin
  Effects effects;                   // what this build runs of the scene's (runnableEffects)
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  // zero without the gravity effect
  double integration_tolerance = 1e-9;                // curved lasting contact
  std::vector<AirFactors> air;                        // per body; empty without drag or magnus
  double flight_tolerance = 1e-9;                     // flight through air
  FrictionModel friction_model;                       // empty without the friction effect
  std::vector<std::string> material_names;            // the scene's materials, indexed
  std::vector<std::size_t> material;                  // per participant, into restitution
  std::vector<std::vector<double>> restitution;       // material x material
  std::vector<std::vector<double>> friction;          // material x material
  std::vector<Track> tracks;
  std::vector<ObstacleTrack> obstacle_tracks;
  std::set<Pair> overlapping;        // discrete: pairs overlapping at the previous step
  std::vector<ContactGroup> groups;  // lasting contact (gravity)
  Stepping stepping;                 // stepped clusters (gravity)
  std::vector<std::vector<std::size_t>> partners;  // per body: its lasting contacts' others
  std::map<Pair, double> contact_since;            // every lasting pair's start, and those the
                                                   // rest rule set to begin at an instant
  bool groups_current = false;                     // the groups hold for the tracks at `now`
  /// Per body, what the exact model spent on it in the step being taken: an instant at which its
  /// motion changed (an impact, its group formed again) is 1, and so is each solve of the
  /// contact forces integrating its group's curved motion.
  std::vector<std::size_t> work;
  std::size_t work_total = 0;   // the sum of `work`
  bool work_all_spent = false;  // work_total ran over the step's budget in all (monitor.cpp)
  std::size_t work_budget = 0;  // Scene::exact_work_budget; 0: none
  /// What the impact clusters' joint solves spent in the step being taken (contact iterations:
  /// MonitorSettings::max_impact_work_per_step).
  std::size_t impact_work = 0;
  /// What the stepped clusters' solves spent in the step being taken (contact iterations:
  /// MonitorSettings::max_stepped_work_per_step).
  std::size_t stepped_work = 0;
  Scratch scratch;
  bool started = false;
  double now = 0.0;
  /// Steps taken (ImpactMonitor::step from the start on): the current one while it runs.
  std::uint64_t steps = 0;
  /// Flights through air that stalled since the last step's report (noteStall).
  std::vector<StalledFlight> stalled;
  double step_end = 0.0;  // the end of the step being taken (curved motion is integrated to it)
  double sample_period = 0.0;  // discrete: the time from the step before to this one

  std::size_t bodyCount() const { return bodies.size(); }
  bool isObstacle(std::size_t participant) const { return participant >= bodies.size(); }
  /// An obstacle participant's shape where it was last placed.
  const PlacedShape& placedShape(std::size_t participant) const {
    return obstacle_tracks[participant - bodies.size()].placed;
  }
  /// An obstacle participant's motion from its last placement on.
  const RigidPose& obstaclePose(std::size_t participant) const {
    return placedShape(participant).pose;
  }
  bool known(std::size_t participant) const {
    return isObstacle(participant) ? obstacle_tracks[participant - bodies.size()].known
                                   : tracks[participant].known;
  }
  double inverseMassOf(std::size_t participant) const {
    return isObstacle(participant) ? 0.0 : inverse_mass[participant];
  }
  double restitutionOf(const Pair& pair) const {
    return restitution[material[pair.first]][material[pair.second]];
  }
  double frictionOf(const Pair& pair) const {
    return friction[material[pair.first]][material[pair.second]];
  }
  /// m: the band a bounce or a separation of the pair of `g` must rise out of under the
  /// pressing acceleration `pressing` not to be held (restSpeed): the pair's band
  /// (Geometry::band), and under discrete detection also the rise of an arc that stays out of it
  /// for one sample period T, pressing T^2 / 8. A bounce from the overlap at w is out of it for
  /// 2 sqrt(w^2 - 2 a band) / a; shorter than T, no sample may see it out, and it falls back in
  /// deeper, a pair that overlapped at the sample before (no new impact): so it rests.
  double riseBand(const Geometry& g, double pressing) const {
    const double arc = detection == Detection::kDiscrete && pressing > 0
                           ? pressing * sample_period * sample_period / 8
                           : 0.0;
    return g.band() + arc;
  }
  bool stepped(std::size_t participant) const {
    return !isObstacle(participant) && tracks[participant].stepped >= 0;
  }
  /// A body of the pair is in a stepped cluster: its cluster's sub-steps keep the pair apart.
  bool steppedPair(const Pair& pair) const { return stepped(pair.first) || stepped(pair.second); }
  /// The pair is a lasting contact: its motion keeps it touching (no first contact to look for),
  /// or a stepped cluster keeps it apart.
  bool lasting(const Pair& pair) const {
    if (steppedPair(pair)) return true;
    if (partners.empty()) return false;
    const std::vector<std::size_t>& others = partners[pair.first];
    return std::find(others.begin(), others.end(), pair.second) != others.end();
  }
};

/// An impact at `time` changes a body's velocity by `change`: summed over the rounds of one
/// instant in one step (a cradle's ball struck twice), from zero at a new instant.
inline void noteImpactChange(const World& world, Track& track, double time,
                             const Eigen::Vector3d& change) {
  const bool same_instant = track.last_impact_time == time && track.impact_step == world.steps;
  track.impact_change = (same_instant ? track.impact_change : Eigen::Vector3d::Zero()) + change;
}

/// A body's flight through air that has stalled (as far as it was asked), not reported yet,
/// noted in World::stalled.
inline void noteStall(World& world, std::size_t body) {
  Track& track = world.tracks[body];
  if (!track.constrained || !track.constrained->free() || track.stall_reported) return;
  const double stalled = track.constrained->stalledAt();
  if (!(stalled < std::numeric_limits<double>::infinity())) return;
  track.stall_reported = true;
  world.stalled.push_back({body, stalled});
}

/// With the drag or magnus effect, a movable body that moves freely from its track's state on
/// (not in a stepped cluster) flies through air from there: its track follows an AirFlight from
/// its position, velocity and spin. Without either effect nothing changes: the parabola (or the
/// straight line) is its motion, and no flight is ever made.
inline void startFlight(World& world, std::size_t body) {
  if (world.air.empty()) return;
  Track& track = world.tracks[body];
  noteStall(world, body);  // the flight it leaves
  track.stall_reported = false;
  if (world.inverse_mass[body] == 0.0 || track.stepped >= 0) return;
  track.constrained = std::make_shared<AirFlight>(track.time, track.position, track.velocity,
                                                  track.angular_velocity, world.gravity,
                                                  world.air[body], world.flight_tolerance);
}

}  // namespace collision_response::core::monitor
