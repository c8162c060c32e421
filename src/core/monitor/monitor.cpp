// The impact monitor: the public API and the step, which reads as the algorithm. The stages it
// runs are in their own files: candidate_pairs (which pairs to look at), contact_schedule (the
// event queue of first contacts), instant_resolver (what happens at an instant of impact); the
// motion models and their small kernels in motion_model.h.
#include "collision_response/core/monitor.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "collision_response/core/body.h"
#include "contact/lasting_contact.h"
#include "contact/stepped_clusters.h"
#include "impact/instant_resolver.h"
#include "model/candidate_pairs.h"
#include "model/monitor_world.h"
#include "model/motion_model.h"
#include "monitor/contact_schedule.h"
#include "monitor/shaped_tracks.h"
#include "solver/cluster_solver.h"

namespace collision_response::core {

using monitor::ContactSchedule;
using monitor::Geometry;
using monitor::Pair;
using monitor::StraightLine;
using monitor::Track;
using monitor::UnderGravity;
using monitor::World;

namespace {

/// Calls `f` with the motion model the scene's effects call for: the one place it is chosen.
template <class F>
auto withMotionModel(const World& world, F&& f) {
  // Drag and Magnus without gravity accelerate too: their flights are integrated (AirFlight).
  return world.effects.gravity || world.effects.air() ? f(UnderGravity{}) : f(StraightLine{});
}

/// Fills the restitution and friction tables from the materials: impacts look them up by index.
/// Pairs that cannot meet (two obstacles) or have no coefficient (validateScene refuses scenes
/// where such a pair can meet) hold NaN.
void computePairCoefficients(World& world, const MaterialTable& materials) {
  const std::size_t count = world.material_names.size();
  world.restitution.assign(count, std::vector<double>(count, NAN));
  world.friction.assign(count, std::vector<double>(count, NAN));
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t j = 0; j < count; ++j) {
      const std::string& first = world.material_names[i];
      const std::string& second = world.material_names[j];
      if (const auto value = materials.restitution(first, second)) world.restitution[i][j] = *value;
      if (const auto value = materials.friction(first, second)) world.friction[i][j] = *value;
    }
  }
}

/// The body's track starts again from `state`: known, at the state's time, position and
/// velocities, and no longer in a constrained motion (in flight through air, with drag or
/// Magnus).
Track& restartTrack(World& world, const BodyStateSample& state) {
  Track& track = world.tracks[state.body];
  track.known = true;
  track.time = state.time;
  track.position = state.position;
  track.velocity = state.velocity;
  track.angular_velocity = state.angular_velocity;
  track.orientation = state.orientation;
  track.constrained = nullptr;
  monitor::startFlight(world, state.body);  // drag or magnus: its flight through air
  return track;
}

/// A body given a state moves freely from it until the groups of lasting contact are formed
/// again: a movable body under gravity; a body of a stepped cluster goes on in its sub-step's
/// straight line from the state, and its cluster is solved again from there (marked stale).
/// Returns whether the body is a stepped cluster's.
bool releaseFromState(World& world, std::size_t body) {
  Track& track = world.tracks[body];
  const bool stepped = track.stepped >= 0;
  track.acceleration =
      world.inverse_mass[body] > 0 && !stepped ? world.gravity : Eigen::Vector3d::Zero();
  track.angular_acceleration.setZero();
  if (stepped) world.stepping.clusters[static_cast<std::size_t>(track.stepped)].stale = true;
  return stepped;
}

/// Takes the received states as the bodies' tracks, oldest first: a state not newer than its
/// body's last one is stale (counted, dropped); a state older than the track's motion (found
/// after the state's instant) is set aside (counted); every other replaces the track. One that
/// follows an impact the monitor applied to the body since the body's previous state (or found
/// in this step at its very start, `in_step`: the step the states end) and lacks more than half
/// of the impact's velocity change is reported as contradicting it, but at the impact's own
/// instant, where it is the motion just before the impact and the monitor keeps the one after.
void applyStates(World& world, const std::vector<BodyStateSample>& states, StepReport& report,
                 bool in_step) {
  const auto earlier = [](const BodyStateSample& x, const BodyStateSample& y) {
    return x.time < y.time || (x.time == y.time && x.body < y.body);
  };
  // Sources usually send their bodies in one order, and the states of one array share a stamp:
  // the copy and sort are paid only when the states are not in order already.
  const std::vector<BodyStateSample>* ordered = &states;
  std::vector<BodyStateSample> sorted;
  if (!std::is_sorted(states.begin(), states.end(), earlier)) {
    sorted = states;
    std::stable_sort(sorted.begin(), sorted.end(), earlier);
    ordered = &sorted;
  }
  for (const BodyStateSample& state : *ordered) {
    Track& track = world.tracks[state.body];
    if (state.time <= track.last_state_time) {
      ++report.stale_states;
      continue;
    }
    const double previous_state_time = track.last_state_time;
    track.last_state_time = state.time;
    if (track.known && state.time < track.time) {
      ++report.states_set_aside;
      continue;
    }
    // An impact since the previous state (or at its instant, which kept the monitor's motion
    // after it), or one at that very instant found only now (a body a stepped cluster let go of
    // at the step's start, closing on the floor).
    const bool impact_since_previous_state =
        (track.last_impact_time >= previous_state_time && track.last_impact_time <= state.time) ||
        (in_step && track.impact_step == world.steps);
    if (track.known && impact_since_previous_state &&
        track.impact_change != Eigen::Vector3d::Zero()) {
      const auto predicted = withMotionModel(world, [&](auto motion) {
        return monitor::velocityAt<decltype(motion)>(world, state.body, state.time);
      });
      const double change = track.impact_change.norm();
      const double missing = -(state.velocity - predicted).dot(track.impact_change) / change;
      if (missing > 0.5 * change) {
        // At the impact's very instant the motion before it is as true as the one after: the
        // monitor's after is kept (kSameInstant).
        if (state.time - track.last_impact_time <= monitor::kSameInstant) continue;
        report.contradicted.push_back({state.body, track.last_impact_time, state.time, missing});
      }
    }
    restartTrack(world, state);
    if (world.effects.gravity) {
      releaseFromState(world, state.body);
      world.groups_current = false;
    }
  }
}

/// The flights through air that stalled up to `time` (each integrated that far: the same steps
/// as when it is asked later), and those left since the last report, into the report.
template <class Motion>
void reportStalledFlights(World& world, double time, StepReport& report) {
  if (world.air.empty()) return;
  for (std::size_t body = 0; body < world.tracks.size(); ++body) {
    const Track& track = world.tracks[body];
    if (!track.known || !track.constrained || !track.constrained->free()) continue;
    monitor::positionAt<Motion>(world, body, time);
    monitor::noteStall(world, body);
  }
  report.stalled.insert(report.stalled.end(), world.stalled.begin(), world.stalled.end());
  world.stalled.clear();
}

void forgetStaleBodies(World& world, double time) {
  for (Track& track : world.tracks) {
    if (track.known && time - track.last_state_time > world.settings.body_timeout) {
      track.known = false;
    }
  }
}

/// Every tracked movable body stops where it is at `time` for the rest of the step: the last
/// fallback when a step's work runs out twice (nothing moves, so nothing goes into anything).
template <class Motion>
void holdEverything(World& world, double time) {
  monitor::clearStepped(world, time);
  for (std::size_t body = 0; body < world.bodies.size(); ++body) {
    Track& track = world.tracks[body];
    if (!track.known || world.inverse_mass[body] == 0.0) continue;
    track.position = monitor::positionAt<Motion>(world, body, time);
    track.time = time;
    track.velocity.setZero();
    track.angular_velocity.setZero();
    track.acceleration.setZero();
    track.angular_acceleration.setZero();
    track.constrained = nullptr;
  }
  monitor::clearGroups(world);
}

/// A group's event solves it again only past the instant it was solved (eventResolution). Within
/// it, its motion goes on as it is. (A curved group's integrated motion ends at its event: where
/// friction's modes stop holding within the resolution, formGroups solves the group without
/// friction, whose forces the solve and the integrator compute alike.)
bool solvesAgain(const monitor::ContactGroup& group, double when, double span) {
  return when > group.time + monitor::eventResolution(when, span);
}

/// Where a continuous step has got to: the instant, the schedule's contacts touching at it, the
/// bodies whose motion changed there, a group event's bodies (their groups form again), whether
/// the stepped clusters have an event at the instant, the next state imposed, and the budget of
/// instants (a second one after the first fallback).
struct StepProgress {
  double instant = 0.0;
  std::vector<std::size_t> touching;
  std::vector<Pair> touching_pairs;  // the touching contacts' pairs outside stepped clusters
  std::vector<std::size_t> changed;
  std::vector<std::size_t> event_bodies;
  /// A curved group integrated further at the instant (its frontier): its bodies, whose pairs
  /// are scheduled again; `extension` when that is all the instant is (not an instant of the
  /// step's budget).
  std::vector<std::size_t> extended;
  bool extension = false;
  bool stepped_due = false;
  std::size_t next_imposed = 0;
  int budget = 0;
  bool fell_back = false;
};

/// The pairs struck in the step so far, sorted, each once.
std::vector<Pair> struckPairs(const World& world, const StepReport& report) {
  std::vector<Pair> struck;
  for (const ImpactRecord& impact : report.impacts) {
    struck.emplace_back(impact.body_a,
                        impact.other_is_obstacle ? impact.other + world.bodyCount() : impact.other);
  }
  std::sort(struck.begin(), struck.end());
  struck.erase(std::unique(struck.begin(), struck.end()), struck.end());
  return struck;
}

/// The step's instants ran out: the first time, every pair struck in the step is resolved at once
/// as one inelastic cluster and the step goes on with a second budget; the second time, every
/// body is held where it is (false: the step ends here).
template <class Motion>
bool fallBack(World& world, StepProgress& at, StepReport& report) {
  report.truncated = true;
  ++report.fallbacks;
  if (at.fell_back) {
    holdEverything<Motion>(world, at.instant);
    return false;
  }
  at.fell_back = true;
  at.budget += world.settings.max_instants_per_step;
  monitor::resolveInelastically<Motion>(world, at.instant, struckPairs(world, report), report,
                                        at.changed);
  return true;
}

/// The touching contacts at the instant resolved, but for a pair with a body of a stepped
/// cluster: the cluster's to keep apart.
template <class Motion>
void resolveTouching(World& world, const ContactSchedule<Motion>& schedule, StepProgress& at,
                     StepReport& report) {
  at.touching_pairs.clear();
  for (const std::size_t k : at.touching) {
    if (!world.steppedPair(schedule.pair(k))) at.touching_pairs.push_back(schedule.pair(k));
  }
  if (!at.touching_pairs.empty() && world.settings.detect_impacts) {
    monitor::resolveInstant<Motion>(world, at.instant, at.touching_pairs, report, at.changed);
  }
}

/// The states imposed at the instant (the impacts a playback was told of) taken as the tracks.
void imposeStates(World& world, const std::vector<BodyStateSample>& imposed, StepProgress& at) {
  for (; at.next_imposed < imposed.size() && imposed[at.next_imposed].time <= at.instant;
       ++at.next_imposed) {
    const BodyStateSample& state = imposed[at.next_imposed];
    // The motion just after an impact, which turns no body at its instant: the orientation the
    // track carries is kept.
    const Eigen::Quaterniond orientation = world.tracks[state.body].orientation;
    Track& track = restartTrack(world, state);
    track.orientation = orientation;
    const bool stepped = releaseFromState(world, state.body);
    at.stepped_due = at.stepped_due || stepped;
    track.last_impact_time = state.time;
    track.impact_change.setZero();  // the state is the motion after it: nothing to contradict
    // It is a state too: one given later at its own instant is newer than it.
    track.last_state_time = std::max(track.last_state_time, state.time);
    at.changed.push_back(state.body);
  }
}

/// The stepped clusters advanced at `when`. A body a cluster let go of may be closing on what it
/// touches (its last sub-step brought it there): that is an impact of the exact model, at `when`.
template <class Motion>
void stepClusters(World& world, double when, const monitor::PairIndex& index,
                  std::vector<std::size_t>& changed, StepReport& report) {
  std::vector<std::size_t> released;
  monitor::advanceStepped(world, when, changed, released, report);
  if (!released.empty() && world.settings.detect_impacts) {
    monitor::resolveInstant<Motion>(
        world, when, monitor::touchingPairsOf(world, when, released, index), report, changed);
  }
}

/// The bodies whose groups of lasting contact form again at the instant: those whose motion
/// changed and a group event's. At the step's start (`first`): every known body's, the groups
/// cleared, unless the groups hold already for these tracks; then also the curved groups' bodies
/// (integrated to the last step's end: on to this one's).
std::vector<std::size_t> regroupedBodies(World& world, bool first, const StepProgress& at) {
  std::vector<std::size_t> seeds = at.changed;
  seeds.insert(seeds.end(), at.event_bodies.begin(), at.event_bodies.end());
  if (first && !world.groups_current) {
    monitor::clearGroups(world);
    seeds.clear();
    for (std::size_t body = 0; body < world.bodies.size(); ++body) {
      if (world.tracks[body].known) seeds.push_back(body);
    }
  } else if (first) {
    for (const monitor::ContactGroup& group : world.groups) {
      if (group.alive && group.curved) {
        seeds.insert(seeds.end(), group.bodies.begin(), group.bodies.end());
      }
    }
  }
  return seeds;
}

/// Gravity, at the instant: the stepped clusters (the grid's sub-steps, a sub-step that ended
/// early, or a cluster whose members' states were replaced; at the start, what the last step left
/// due), the groups of lasting contact of the bodies whose motion changed, and the stepped
/// clusters those bodies may now reach within their sub-step. `changed` ends sorted, each once.
template <class Motion>
void settleLastingContact(World& world, const monitor::PairIndex& index, bool first,
                          StepProgress& at, StepReport& report) {
  if (at.stepped_due || first) stepClusters<Motion>(world, at.instant, index, at.changed, report);
  at.stepped_due = false;
  const std::vector<std::size_t> seeds = regroupedBodies(world, first, at);
  if (!seeds.empty()) monitor::formGroups(world, at.instant, seeds, index, at.changed);
  const std::vector<std::size_t> moved = at.changed;
  monitor::joinStepped(world, at.instant, moved, at.changed, report);
  std::sort(at.changed.begin(), at.changed.end());
  at.changed.erase(std::unique(at.changed.begin(), at.changed.end()), at.changed.end());
}

/// What the instant cost the exact model (World::work): each body whose motion changed there, and
/// the solves the curved groups' integration took since they were last charged. `charged`: the
/// bodies charged (some more than once).
void chargeInstant(World& world, const std::vector<std::size_t>& changed,
                   std::vector<std::size_t>& charged) {
  charged = changed;
  for (const std::size_t body : changed) ++world.work[body];
  world.work_total += changed.size();
  for (monitor::ContactGroup& group : world.groups) {
    if (!group.alive || !group.step) continue;
    monitor::chargeIntegration(world, group);
    charged.insert(charged.end(), group.bodies.begin(), group.bodies.end());
  }
}

/// An update's exact work in all, at most this many bodies' budgets (World::work_budget).
constexpr std::size_t kBudgetsPerUpdate = 16;

/// The bodies (of those `charged` at the instant) whose exact work in this step ran over the
/// budget, or, once the step's work in all has run over kBudgetsPerUpdate budgets, every body
/// that spent a sixteenth of one (all of them looked at once, when that happens; after, those
/// charged), none stepped yet, are stepped from the instant with the bodies near them
/// (stepOverBudget; counted in the report's fallbacks and named in its over_budget); what the
/// stepped clusters let go of is resolved as at the grid (stepClusters). `changed` ends sorted,
/// each once.
template <class Motion>
void stepOverBudget(World& world, const monitor::PairIndex& index, std::vector<std::size_t> charged,
                    double instant, std::vector<std::size_t>& changed, StepReport& report) {
  if (world.work_budget == 0 || !world.stepping.enabled()) return;
  const bool all_spent = world.work_total > kBudgetsPerUpdate * world.work_budget;
  if (all_spent && !world.work_all_spent) {
    world.work_all_spent = true;
    charged.clear();
    for (std::size_t body = 0; body < world.bodies.size(); ++body) charged.push_back(body);
  }
  const std::size_t allowed = all_spent ? world.work_budget / kBudgetsPerUpdate : world.work_budget;
  std::sort(charged.begin(), charged.end());
  charged.erase(std::unique(charged.begin(), charged.end()), charged.end());
  std::vector<std::size_t> over;
  for (const std::size_t body : charged) {
    const Track& track = world.tracks[body];
    if (world.work[body] > allowed && track.known && track.stepped < 0 &&
        world.inverse_mass[body] > 0) {
      over.push_back(body);
    }
  }
  if (over.empty()) return;
  report.fallbacks += over.size();
  report.over_budget.insert(report.over_budget.end(), over.begin(), over.end());
  std::vector<std::size_t> released;
  monitor::stepOverBudget(world, instant, over, changed, released, report);
  if (!released.empty() && world.settings.detect_impacts) {
    monitor::resolveInstant<Motion>(
        world, instant, monitor::touchingPairsOf(world, instant, released, index), report, changed);
  }
  std::sort(changed.begin(), changed.end());
  changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
}

/// The first contacts of the pairs of the bodies whose motion changed scheduled again (at the
/// start: of every pair).
template <class Motion>
void scheduleChanged(const World& world, ContactSchedule<Motion>& schedule, bool first,
                     const StepProgress& at) {
  if (first) {
    // Each body once, in the order first changed (without gravity `changed` holds a body once a
    // round it took part in: a lattice's thousands, each round); a body's pairs are added at its
    // first mention, so the later ones added nothing.
    std::vector<std::size_t> once;
    std::vector<char> seen(world.bodyCount(), 0);
    for (const std::size_t body : at.changed) {
      if (!seen[body]) once.push_back(body);
      seen[body] = 1;
    }
    schedule.scheduleAll(at.instant, once);
  } else {
    for (const std::size_t body : at.changed) schedule.reschedule(body, at.instant);
    for (const std::size_t body : at.extended) schedule.reschedule(body, at.instant);
  }
}

/// On to the next event within the step: the earliest of a first contact, a state imposed and
/// (gravity) a group's motion changing or a stepped cluster's sub-step (at one instant: the group
/// first, then the state, then the contact). False when there is none up to `time`.
template <class Motion>
bool nextEvent(World& world, ContactSchedule<Motion>& schedule,
               const std::vector<BodyStateSample>& imposed, double time, StepProgress& at) {
  const double next_contact = schedule.earliest();
  const double next_state =
      at.next_imposed < imposed.size() ? imposed[at.next_imposed].time : INFINITY;
  double next_group_event = INFINITY, next_stepped = INFINITY;
  std::size_t group = 0;
  if constexpr (Motion::kAccelerates) {
    std::tie(next_group_event, group) = monitor::nextGroupEvent(world);
    next_stepped = monitor::nextSteppedEvent(world, time);
  }
  const double next = std::min({next_contact, next_state, next_group_event, next_stepped});
  at.extension = false;
  if (!(next <= time)) return false;
  if (next_group_event == next || next_state == next || next_stepped == next) {
    at.instant = next;
    at.touching.clear();
    if (next_group_event == next && monitor::integrateFurther(world, group, next)) {
      // Integrated further: its bodies' pairs are scheduled again past the old frontier.
      at.extended = world.groups[group].bodies;
      at.extension = next_state != next && next_stepped != next;
    } else if (next_group_event == next) {
      monitor::ContactGroup& changing = world.groups[group];
      monitor::takeGroupEvents(changing, next);
      if (solvesAgain(changing, next, time - world.now)) at.event_bodies = changing.bodies;
    }
    at.stepped_due = next_stepped == next;
    return true;
  }
  return schedule.next(at.instant, at.touching);
}

/// Gravity, at the step's end: the groups of lasting contact formed for the tracks at `time`,
/// their contacts reported, and the bodies of the stepped clusters.
void reportLastingContact(World& world, double time, StepReport& report) {
  std::vector<std::size_t> formed;
  monitor::formAllGroups(world, time, formed);
  monitor::reportContacts(world, time, report.contacts);
  report.stepped_bodies = monitor::steppedBodies(world);
}

/// What the step's impact clusters' joint solves and stepped clusters' solves spent
/// (MonitorSettings::max_impact_work_per_step, max_stepped_work_per_step), and the bodies their
/// bounds cut short or held, each once.
void reportImpactWork(const World& world, StepReport& report) {
  report.impact_work = world.impact_work;
  report.stepped_work = world.stepped_work;
  for (std::vector<std::size_t>* bodies : {&report.over_impact_work, &report.over_stepped_work}) {
    std::sort(bodies->begin(), bodies->end());
    bodies->erase(std::unique(bodies->begin(), bodies->end()), bodies->end());
  }
}

/// Continuous detection: from the last states, the first contact of every candidate pair,
/// earliest first, and (gravity) the events of the groups of lasting contact; at each instant of
/// contact the touching contacts are resolved, the groups of the bodies whose motion changed
/// are formed again and their pairs scheduled again; then the states at `time` are taken.
///
/// When the step's instants run out (a ball wedged in a gap bouncing ever faster), every pair
/// struck in the step is resolved at once as one inelastic cluster, so none of them approaches,
/// and the step goes on with a second budget; if that runs out too, every body is held where it
/// is until the step's end. Both count in report.fallbacks.
template <class Motion>
StepReport continuousStep(World& world, double time, const std::vector<BodyStateSample>& states,
                          const std::vector<BodyStateSample>& imposed = {}) {
  StepReport report;
  world.step_end = time;
  world.stepping.beginStep(world.now, time);
  world.work.assign(world.bodies.size(), 0);
  world.work_total = 0;
  world.work_all_spent = false;
  world.impact_work = 0;
  world.stepped_work = 0;
  monitor::candidatePairs<Motion>(world, world.now, time, world.scratch.pairs);
  ContactSchedule<Motion> schedule(world, time);
  const monitor::PairIndex index{world.scratch.pairs, world.scratch.pairs_of};
  StepProgress at;
  at.instant = world.now;
  at.budget = world.settings.max_instants_per_step;
  schedule.touchingAtStart(at.instant, at.touching);
  std::vector<std::size_t> charged;
  bool first = true;
  for (int instants = 0;; instants += at.extension ? 0 : 1, first = false) {
    at.changed.clear();
    if (instants >= at.budget && !fallBack<Motion>(world, at, report)) break;
    resolveTouching<Motion>(world, schedule, at, report);
    imposeStates(world, imposed, at);
    if constexpr (Motion::kAccelerates) {
      settleLastingContact<Motion>(world, index, first, at, report);
      chargeInstant(world, at.changed, charged);
      stepOverBudget<Motion>(world, index, charged, at.instant, at.changed, report);
    }
    at.event_bodies.clear();
    scheduleChanged<Motion>(world, schedule, first, at);
    at.extended.clear();
    if (!nextEvent<Motion>(world, schedule, imposed, time, at)) break;
  }
  reportStalledFlights<Motion>(world, time, report);
  applyStates(world, states, report, true);
  world.now = time;
  if constexpr (Motion::kAccelerates) {
    world.step_end = time;
    reportLastingContact(world, time, report);
    report.exact_work = world.work_total;
  }
  reportImpactWork(world, report);
  return report;
}

/// Lasting contact between the samples of discrete detection: the groups' own events in
/// (now, time] (a slip that stops, a curved step's mode that changes), each group formed again at
/// its instant as continuous detection does between impacts; curved groups integrated on to
/// `time`. Lasting contact is the model of motion under either detection: without this, a
/// sliding contact's friction would act past the instant its slip stops, to the next sample.
template <class Motion>
void advanceLastingContact(World& world, double time, StepReport& report) {
  world.step_end = time;
  world.stepping.beginStep(world.now, time);
  world.work.assign(world.bodies.size(), 0);
  world.work_total = 0;
  world.work_all_spent = false;
  // Without groups for these tracks, they are formed after the states at `time`; the stepped
  // clusters move on regardless.
  const bool lasting = world.groups_current;
  std::vector<Pair>& pairs = world.scratch.pairs;
  monitor::candidatePairs<Motion>(world, world.now, time, pairs);
  std::vector<std::vector<std::size_t>>& pairs_of = world.scratch.pairs_of;
  pairs_of.assign(world.bodies.size(), {});
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    pairs_of[pairs[k].first].push_back(k);
    if (!world.isObstacle(pairs[k].second)) pairs_of[pairs[k].second].push_back(k);
  }
  const monitor::PairIndex index{pairs, pairs_of};
  std::vector<std::size_t> seeds, changed;
  if (lasting) {
    for (const monitor::ContactGroup& group : world.groups) {
      if (group.alive && group.curved)
        seeds.insert(seeds.end(), group.bodies.begin(), group.bodies.end());
    }
  }
  if (!seeds.empty()) monitor::formGroups(world, world.now, seeds, index, changed);
  // The stepped clusters' events and the groups' (at one instant, the cluster first), each
  // followed by the groups of the bodies whose motion changed and the clusters they now reach.
  // What an instant cost, charged (World::work), and the bodies over the budget stepped.
  std::vector<std::size_t> charged;
  const auto budget = [&](double when) {
    chargeInstant(world, changed, charged);
    stepOverBudget<Motion>(world, index, charged, when, changed, report);
  };
  const auto settle = [&](double when) {
    if (lasting && !changed.empty()) {
      const std::vector<std::size_t> changed_seeds = changed;
      monitor::formGroups(world, when, changed_seeds, index, changed);
    }
    const std::vector<std::size_t> moved = changed;
    monitor::joinStepped(world, when, moved, changed, report);
    budget(when);
  };
  changed.clear();
  stepClusters<Motion>(world, world.now, index, changed, report);
  settle(world.now);
  for (int events = 0; events < world.settings.max_instants_per_step; ++events) {
    auto [when, group] =
        lasting ? monitor::nextGroupEvent(world) : std::pair<double, std::size_t>{INFINITY, 0};
    const double stepped = monitor::nextSteppedEvent(world, time);
    if (!(std::min(when, stepped) <= time)) break;
    changed.clear();
    if (stepped <= when) {
      stepClusters<Motion>(world, stepped, index, changed, report);
      settle(stepped);
      continue;
    }
    if (monitor::integrateFurther(world, group, when)) {
      // Integrated further, not an event of the budget (bounded: each reaches on by one step
      // at least, and a motion takes at most ConstrainedStep's most steps).
      --events;
      continue;
    }
    monitor::ContactGroup& changing = world.groups[group];
    monitor::takeGroupEvents(changing, when);
    if (!solvesAgain(changing, when, time - world.now)) continue;
    seeds = changing.bodies;
    monitor::formGroups(world, when, seeds, index, changed);
    const std::vector<std::size_t> moved = changed;
    monitor::joinStepped(world, when, moved, changed, report);
    budget(when);
  }
}

/// The candidate pairs touching at the sample (but for a stepped cluster's, which it keeps
/// apart): new contacts and lasting ones in `touching`, those that overlapped at the sample before
/// already (no new impact) in `overlapped_before`.
template <class Motion>
void touchingAtSample(const World& world, double time, const std::vector<Pair>& pairs,
                      std::vector<Pair>& touching, std::vector<Pair>& overlapped_before) {
  for (const Pair& pair : pairs) {
    const Geometry g = monitor::geometry<Motion>(world, pair, time);
    if (world.steppedPair(pair)) continue;  // its stepped cluster keeps it apart
    if (!g.valid || g.gap > g.tolerance) continue;
    if (world.overlapping.count(pair) == 0 || world.lasting(pair)) {
      touching.push_back(pair);
    } else {
      overlapped_before.push_back(pair);
    }
  }
}

/// A pair still overlapping from an earlier impact is no new impact, but it takes part in one on
/// its bodies: a ball rising out of the floor it bounced off, struck from above, runs into the
/// floor (alone it would be driven through it, the floor pair never found again). The pairs of
/// `overlapped_before` reached from the pairs that strike now, through touching pairs, as
/// continuous detection's clusters, move to `touching` (sorted then).
template <class Motion>
void joinOverlappedBefore(const World& world, double time, std::vector<Pair>& overlapped_before,
                          std::vector<Pair>& touching) {
  std::vector<char> struck(world.bodies.size(), 0);
  std::vector<std::size_t> frontier;
  const auto reach = [&](std::size_t participant) {
    if (world.isObstacle(participant) || struck[participant]) return;
    struck[participant] = 1;
    frontier.push_back(participant);
  };
  for (const Pair& pair : touching) {
    const Geometry g = monitor::geometry<Motion>(world, pair, time);
    if (monitor::approaching<Motion>(world, pair, g, time)) {
      reach(pair.first);
      reach(pair.second);
    }
  }
  for (bool grown = !frontier.empty(); grown;) {
    grown = false;
    for (auto pair = overlapped_before.begin(); pair != overlapped_before.end();) {
      const bool first = struck[pair->first] != 0;
      const bool second = !world.isObstacle(pair->second) && struck[pair->second] != 0;
      if (!first && !second) {
        ++pair;
        continue;
      }
      reach(pair->first);
      reach(pair->second);
      touching.push_back(*pair);
      pair = overlapped_before.erase(pair);
      grown = true;
    }
    // Touching pairs of the bodies reached carry the blow on (a rack, a stack).
    for (const Pair& pair : touching) {
      if (struck[pair.first] || (!world.isObstacle(pair.second) && struck[pair.second])) {
        const std::size_t before = frontier.size();
        reach(pair.first);
        reach(pair.second);
        grown = grown || frontier.size() != before;
      }
    }
  }
  std::sort(touching.begin(), touching.end());
}

/// The pairs overlapping at the sample (but for a stepped cluster's), remembered for the next:
/// an impact is found when contact begins.
template <class Motion>
void rememberOverlapping(World& world, double time, const std::vector<Pair>& pairs) {
  world.overlapping.clear();
  for (const Pair& pair : pairs) {
    if (world.steppedPair(pair)) continue;
    const Geometry g = monitor::geometry<Motion>(world, pair, time);
    if (g.valid && g.gap < -g.tolerance) world.overlapping.insert(pair);
  }
}

/// Discrete detection: the groups' events up to `time` (advanceLastingContact), the states at
/// `time` taken, then the pairs that overlap then (and did not at the previous step, unless they
/// are lasting contacts) and approach are resolved. A lasting contact held overlapping (where its
/// impact was found) is a contact, not a new detection: an impulse on a resting body runs into
/// its supports, as under continuous detection.
template <class Motion>
StepReport discreteStep(World& world, double time, const std::vector<BodyStateSample>& states) {
  StepReport report;
  world.sample_period = time - world.now;
  world.impact_work = 0;
  world.stepped_work = 0;
  if constexpr (Motion::kAccelerates) advanceLastingContact<Motion>(world, time, report);
  applyStates(world, states, report, true);
  world.now = time;
  std::vector<Pair>& pairs = world.scratch.pairs;
  monitor::candidatePairs<Motion>(world, time, time, pairs);
  std::vector<Pair> touching;
  std::vector<Pair> overlapped_before;  // touching still, overlapping at the sample before
  touchingAtSample<Motion>(world, time, pairs, touching, overlapped_before);
  if (!overlapped_before.empty()) {
    joinOverlappedBefore<Motion>(world, time, overlapped_before, touching);
  }
  std::vector<std::size_t> changed;
  monitor::resolveInstant<Motion>(world, time, touching, report, changed);
  if constexpr (Motion::kAccelerates) {
    const std::vector<std::size_t> moved = changed;
    monitor::joinStepped(world, time, moved, changed, report);
  }
  rememberOverlapping<Motion>(world, time, pairs);
  reportStalledFlights<Motion>(world, time, report);
  if constexpr (Motion::kAccelerates) {
    reportLastingContact(world, time, report);
    report.exact_work = world.work_total;
  }
  reportImpactWork(world, report);
  return report;
}

/// The first states: taken as the tracks and the time line started; in discrete detection the
/// pairs that overlap already are remembered (an impact is found when contact begins).
template <class Motion>
void start(World& world, double time) {
  world.started = true;
  world.now = time;
  if (world.detection != Detection::kDiscrete) return;
  std::vector<Pair>& pairs = world.scratch.pairs;
  monitor::allCandidatePairs(world, pairs);
  for (const Pair& pair : pairs) {
    const Geometry g = monitor::geometry<Motion>(world, pair, time);
    if (g.valid && g.gap < -g.tolerance) world.overlapping.insert(pair);
  }
}

}  // namespace

ImpactMonitor::ImpactMonitor(const Scene& scene, const MonitorSettings& settings)
    : world_(std::make_unique<World>()) {
  World& world = *world_;
  world.scene = std::make_shared<const Scene>(scene);
  world.settings = settings;
  world.detection = scene.detection;
  world.restitution_threshold = scene.restitution_threshold;
  world.bodies = scene.bodies;
  world.obstacles = scene.obstacles;
  const auto by_id = [](const auto& x, const auto& y) { return x.id < y.id; };
  std::sort(world.bodies.begin(), world.bodies.end(), by_id);
  std::sort(world.obstacles.begin(), world.obstacles.end(), by_id);
  world.effects = runnableEffects(scene.effects);
  if (world.effects.gravity) world.gravity = scene.gravity;
  world.integration_tolerance = scene.contact_integration_tolerance;
  world.flight_tolerance = scene.flight_integration_tolerance;
  if (world.effects.gravity) {
    world.stepping.min_bodies = static_cast<std::size_t>(scene.stepped_cluster_min_bodies);
    world.stepping.time_step = scene.stepped_cluster_time_step;
    world.work_budget = static_cast<std::size_t>(std::max(scene.exact_work_budget, 0));
  }
  world.friction_model = frictionModelFor(world.effects);

  std::vector<std::string>& material_names = world.material_names;
  const auto material_index = [&material_names](const std::string& name) {
    const auto found = std::find(material_names.begin(), material_names.end(), name);
    if (found != material_names.end()) {
      return static_cast<std::size_t>(found - material_names.begin());
    }
    material_names.push_back(name);
    return material_names.size() - 1;
  };
  for (std::size_t i = 0; i < world.bodies.size(); ++i) {
    const BodySpec& body = world.bodies[i];
    world.body_index[body.id] = i;
    world.radius.push_back(body.radius);
    world.inverse_mass.push_back(inverseMass(body.mass));
    world.spin_factor.push_back(
        world.effects.spin ? spinFactor(world.inverse_mass.back(), body.radius, body.inertia)
                           : 0.0);
    world.material.push_back(material_index(body.material));
    if (world.effects.air()) {
      world.air.push_back(
          bodyAirFactors(body, scene.air_density, world.effects.drag, world.effects.magnus));
    }
  }
  for (const ObstacleSpec& obstacle : world.obstacles) {
    world.radius.push_back(contactRadius(shapeOf(obstacle)));
    world.material.push_back(material_index(obstacle.material));
  }
  computePairCoefficients(world, scene.materials);

  world.tracks.resize(world.bodies.size());
  world.obstacle_tracks.resize(world.obstacles.size());
  for (std::size_t i = 0; i < world.obstacles.size(); ++i) {
    const ObstacleSpec& obstacle = world.obstacles[i];
    if (!obstacle.frame.empty()) continue;  // placed by setObstaclePose from tf
    world.obstacle_tracks[i] = monitor::ObstacleTrack{true, placeFixed(obstacle)};
  }
  world.partners.assign(world.bodies.size(), {});
  shaped_ = std::make_unique<monitor::ShapedRoom>(monitor::shapedRoomOf(world));
}

ImpactMonitor::ImpactMonitor(const ImpactMonitor& other)
    : world_(std::make_unique<World>(*other.world_)),
      shaped_(std::make_unique<monitor::ShapedRoom>(*other.shaped_)) {}
ImpactMonitor& ImpactMonitor::operator=(const ImpactMonitor& other) {
  if (this != &other) {
    world_ = std::make_unique<World>(*other.world_);
    shaped_ = std::make_unique<monitor::ShapedRoom>(*other.shaped_);
  }
  return *this;
}
ImpactMonitor::ImpactMonitor(ImpactMonitor&&) noexcept = default;
ImpactMonitor& ImpactMonitor::operator=(ImpactMonitor&&) noexcept = default;
ImpactMonitor::~ImpactMonitor() = default;

std::size_t ImpactMonitor::bodyCount() const { return world_->bodies.size(); }
std::size_t ImpactMonitor::obstacleCount() const { return world_->obstacles.size(); }
const BodySpec& ImpactMonitor::body(std::size_t index) const { return world_->bodies[index]; }
const ObstacleSpec& ImpactMonitor::obstacle(std::size_t index) const {
  return world_->obstacles[index];
}
const Scene& ImpactMonitor::scene() const { return *world_->scene; }
bool ImpactMonitor::started() const { return world_->started; }
double ImpactMonitor::now() const { return world_->now; }

void ImpactMonitor::tune(Detection detection, double restitution_threshold,
                         const MaterialTable& materials) {
  World& world = *world_;
  if (detection != world.detection) world.overlapping.clear();
  world.groups_current = false;  // friction coefficients may have changed
  world.detection = detection;
  world.restitution_threshold = restitution_threshold;
  computePairCoefficients(world, materials);
  auto tuned = std::make_shared<Scene>(*world.scene);
  tuned->detection = detection;
  tuned->restitution_threshold = restitution_threshold;
  tuned->materials = materials;
  world.scene = std::move(tuned);
  ++shaped_->revision;  // a flying shaped body goes on with the new coefficients
}

std::optional<PlacedShape> ImpactMonitor::obstaclePose(std::size_t obstacle) const {
  if (!world_->obstacle_tracks[obstacle].known) return std::nullopt;
  return world_->obstacle_tracks[obstacle].placed;
}

std::optional<std::size_t> ImpactMonitor::bodyIndex(const std::string& id) const {
  const auto found = world_->body_index.find(id);
  if (found == world_->body_index.end()) return std::nullopt;
  return found->second;
}

void ImpactMonitor::setObstaclePose(std::size_t obstacle, const RigidPose& frame) {
  world_->obstacle_tracks[obstacle] =
      monitor::ObstacleTrack{true, place(world_->obstacles[obstacle], frame)};
  world_->groups_current = false;
  world_->scratch.obstacles.invalidate();
  ++shaped_->revision;
}

void ImpactMonitor::placeObstacle(std::size_t obstacle, const PlacedShape& placed) {
  world_->obstacle_tracks[obstacle] = monitor::ObstacleTrack{true, placed};
  world_->groups_current = false;
  world_->scratch.obstacles.invalidate();
  ++shaped_->revision;
}

void ImpactMonitor::reset() {
  World& world = *world_;
  for (Track& track : world.tracks) track = Track{};
  for (std::size_t i = 0; i < world.obstacles.size(); ++i) {
    if (!world.obstacles[i].frame.empty()) world.obstacle_tracks[i] = monitor::ObstacleTrack{};
  }
  world.overlapping.clear();
  monitor::clearStepped(world, world.now);
  monitor::clearGroups(world);
  world.contact_since.clear();
  world.stalled.clear();
  world.started = false;
  world.now = 0.0;
  world.scratch.obstacles.invalidate();
  for (auto& track : shaped_->tracks) track.reset();
  shaped_->unmodelled_now.clear();
}

std::size_t ImpactMonitor::trackedBodies() const {
  const auto balls = std::count_if(world_->tracks.begin(), world_->tracks.end(),
                                   [](const Track& t) { return t.known; });
  const auto shaped = std::count_if(shaped_->tracks.begin(), shaped_->tracks.end(),
                                    [](const auto& t) { return t.has_value(); });
  return static_cast<std::size_t>(balls + shaped);
}

bool ImpactMonitor::shaped(std::size_t body) const { return shaped_->shaped(body); }

std::optional<std::size_t> ImpactMonitor::restingOn(std::size_t body) const {
  if (shaped_->shaped(body)) {
    const auto& track = shaped_->tracks[body];
    if (!track || track->mode() != monitor::ShapedTrack::Mode::kLasting) return std::nullopt;
    return track->against();
  }
  const World& world = *world_;
  if (!world.tracks[body].known) return std::nullopt;
  if (world.stepped(body)) {
    const auto& cluster =
        world.stepping.clusters[static_cast<std::size_t>(world.tracks[body].stepped)];
    for (const monitor::SteppedClusterContact& contact : cluster.contacts) {
      if (contact.pair.first == body && world.isObstacle(contact.pair.second)) {
        return contact.pair.second - world.bodyCount();
      }
    }
    return std::nullopt;
  }
  if (world.partners.empty()) return std::nullopt;
  for (const std::size_t other : world.partners[body]) {
    if (world.isObstacle(other)) return other - world.bodyCount();
  }
  return std::nullopt;
}

std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> ImpactMonitor::predictedState(
    std::size_t body, double time) const {
  if (shaped_->shaped(body)) {
    if (!shaped_->tracks[body]) return std::nullopt;
    const BodyStateSample state = shaped_->tracks[body]->stateAt(time);
    return std::make_pair(state.position, state.velocity);
  }
  const World& world = *world_;
  if (!world.tracks[body].known) return std::nullopt;
  return withMotionModel(world, [&](auto motion) {
    using Motion = decltype(motion);
    return std::make_pair(monitor::positionAt<Motion>(world, body, time),
                          monitor::velocityAt<Motion>(world, body, time));
  });
}

double ImpactMonitor::motionSince(std::size_t body) const {
  if (shaped_->shaped(body) && shaped_->tracks[body]) return shaped_->tracks[body]->since();
  return world_->tracks[body].time;
}

Eigen::Vector3d ImpactMonitor::predictedAngularVelocity(std::size_t body, double time) const {
  if (shaped_->shaped(body)) {
    if (!shaped_->tracks[body]) return Eigen::Vector3d::Zero();
    return shaped_->tracks[body]->stateAt(time).angular_velocity;
  }
  const World& world = *world_;
  if (!world.tracks[body].known) return Eigen::Vector3d::Zero();
  return withMotionModel(world, [&](auto motion) {
    return monitor::angularVelocityAt<decltype(motion)>(world, body, time);
  });
}

Eigen::Quaterniond ImpactMonitor::lastOrientation(std::size_t body) const {
  if (shaped_->shaped(body)) {
    const auto& track = shaped_->tracks[body];
    return track ? track->last_orientation : Eigen::Quaterniond::Identity();
  }
  const monitor::Track& track = world_->tracks[body];
  return track.known ? track.orientation : Eigen::Quaterniond::Identity();
}

Eigen::Quaterniond ImpactMonitor::predictedOrientation(std::size_t body, double time) const {
  if (shaped_->shaped(body)) {
    const auto& track = shaped_->tracks[body];
    return track ? track->stateAt(time).orientation : Eigen::Quaterniond::Identity();
  }
  return lastOrientation(body);
}

namespace {

/// The states (or imposed states) of balls only: a shaped body's are the shaped tracks'.
std::vector<BodyStateSample> ballStates(const monitor::ShapedRoom& room,
                                        const std::vector<BodyStateSample>& states) {
  std::vector<BodyStateSample> balls;
  for (const BodyStateSample& state : states) {
    if (!room.shaped(state.body)) balls.push_back(state);
  }
  return balls;
}

}  // namespace

StepReport ImpactMonitor::advance(double time, const std::vector<BodyStateSample>& imposed) {
  World& world = *world_;
  if (!world.started || time <= world.now) return StepReport{};
  forgetStaleBodies(world, time);
  ++world.steps;
  if (!shaped_->any()) {
    return withMotionModel(world, [&](auto motion) {
      return continuousStep<decltype(motion)>(world, time, {}, imposed);
    });
  }
  const double from = world.now;
  StepReport report = withMotionModel(world, [&](auto motion) {
    return continuousStep<decltype(motion)>(world, time, {}, ballStates(*shaped_, imposed));
  });
  monitor::advanceShaped(world, *shaped_, from, time, imposed, ballsAt(time), report);
  return report;
}

monitor::BallPositions ImpactMonitor::ballsAt(double time) const {
  return [this, time](std::size_t body) -> std::optional<Eigen::Vector3d> {
    const auto state = predictedState(body, time);
    if (!state) return std::nullopt;
    return state->first;
  };
}

StepReport ImpactMonitor::step(double time, const std::vector<BodyStateSample>& states) {
  if (!shaped_->any()) return stepBalls(time, states);
  World& world = *world_;
  const double from = world.now;
  StepReport report = stepBalls(time, ballStates(*shaped_, states));
  const double to = std::max(time, world.now);
  monitor::stepShaped(world, *shaped_, from, to, states, ballsAt(to), report);
  return report;
}

StepReport ImpactMonitor::stepBalls(double time, const std::vector<BodyStateSample>& states) {
  World& world = *world_;
  if (!world.started || time <= world.now) {
    StepReport report;
    applyStates(world, states, report, false);
    if (!world.started) {
      withMotionModel(world, [&](auto motion) {
        start<decltype(motion)>(world, time);
        return 0;
      });
    }
    if (world.effects.gravity) {
      // The bodies these states put in contact rest, slide or roll from now: a ball given at
      // rest on the floor is held there, not let fall into it until the next step.
      std::vector<std::size_t> formed;
      world.step_end = world.now;
      monitor::formAllGroups(world, world.now, formed);
      monitor::reportContacts(world, world.now, report.contacts);
    }
    return report;
  }
  forgetStaleBodies(world, time);
  ++world.steps;
  return withMotionModel(world, [&](auto motion) {
    using Motion = decltype(motion);
    return world.detection == Detection::kContinuous ? continuousStep<Motion>(world, time, states)
                                                     : discreteStep<Motion>(world, time, states);
  });
}

}  // namespace collision_response::core
