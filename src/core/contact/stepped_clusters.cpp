#include "contact/stepped_clusters.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>

#include "contact/solve_participants.h"
#include "geometry/broadphase.h"
#include "model/candidate_pairs.h"
#include "model/motion_model.h"
#include "solver/order_free.h"
#include "solver/stepped_contact.h"

namespace collision_response::core::monitor {
namespace {

using Motion = UnderGravity;  // stepped clusters need a steady force: the gravity effect

/// The closure of a solve (new near pairs found with the solved velocities) is looked for at
/// most this many times; each time the contact set only grows, so it ends anyway, but a scene
/// that needs more is resolved with what it has (counted, never silent: the solve's own
/// tolerance check still ends the sub-step before a contact it does not hold closes).
constexpr int kMaxClosures = 16;

/// What a body of a solve starts from at its instant.
struct Start {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d kick = Eigen::Vector3d::Zero();  ///< the gravity of the sub-step, if not given
};

/// How far a body's surface may move over `span` from `time`, before its sub-step is solved: at
/// its speed plus the gravity a sub-step gives (a stepped body's motion), or along its own
/// motion at its speed and acceleration bound (any other's), whichever is farther.
double reachBefore(const World& world, std::size_t body, double time, double span) {
  const double speed = velocityAt<Motion>(world, body, time).norm();
  if (world.inverse_mass[body] == 0.0) return speed * span;
  const double acceleration =
      world.stepped(body) ? 0.0 : accelerationBound<Motion>(world, body, time, time + span);
  return (speed + world.gravity.norm() * span) * span + 0.5 * acceleration * span * span;
}

/// Every pair of tracked participants whose surfaces are within their reaches of each other at
/// `time` (body pairs through a grid of their boxes; each movable body with the obstacles a
/// grid of their bounds finds near it, nearObstacleBox), in the canonical order. `looked_at`: the
/// bodies placed and the pairs whose contact geometry was computed.
std::vector<Pair> nearPairs(const World& world, double time, double span,
                            const std::vector<double>& reach, std::size_t& looked_at) {
  const std::size_t n = world.bodies.size();
  std::vector<Box> boxes(n);
  std::vector<Eigen::Vector3d> centres(n, Eigen::Vector3d::Zero());
  std::vector<char> active(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!world.tracks[i].known) continue;
    active[i] = 1;
    const Eigen::Vector3d centre = positionAt<Motion>(world, i, time);
    centres[i] = centre;
    const double half = world.radius[i] * (1 + 2 * world.settings.contact_tolerance) + reach[i] +
                        64 * kEps * centre.lpNorm<Eigen::Infinity>();
    boxes[i] = Box::about(centre, half);
  }
  SpatialHash hash;
  hash.build(boxes, active);
  std::vector<std::pair<std::size_t, std::size_t>> overlapping;
  hash.overlappingPairs(overlapping);
  looked_at = n + overlapping.size();
  std::vector<Pair> pairs;
  for (const auto& [a, b] : overlapping) {
    if (world.inverse_mass[a] + world.inverse_mass[b] == 0.0) continue;
    const Geometry g = geometry<Motion>(world, Pair(a, b), time);
    if (g.valid && g.gap <= reach[a] + reach[b] + g.tolerance) pairs.emplace_back(a, b);
  }
  // The obstacles through a grid of their bounds: a robot's 2,000 links beside a cluster of
  // 1,728 balls cost 3.5 million contact geometries a call otherwise (issue 41).
  std::vector<Box> bounds(world.obstacles.size());
  std::vector<double> moving(world.obstacles.size(), 0.0);
  std::vector<char> entered(world.obstacles.size(), 0);
  for (std::size_t o = 0; o < world.obstacles.size(); ++o) {
    if (!world.obstacle_tracks[o].known) continue;
    entered[o] = 1;
    moving[o] = world.obstaclePose(n + o).velocity.norm() * span;
    bounds[o] = nearObstacleBox(world, o, time, moving[o]);
  }
  ObstacleIndex obstacles;
  obstacles.build(std::move(bounds), entered);
  std::vector<std::size_t> near;
  for (std::size_t a = 0; a < n; ++a) {
    if (!active[a] || world.inverse_mass[a] == 0.0) continue;
    obstacles.query(nearBodyBox(world, world.radius[a], centres[a], reach[a]), near);
    looked_at += near.size();
    for (const std::size_t o : near) {
      const Pair pair(a, n + o);
      const Geometry g = geometry<Motion>(world, pair, time);
      if (g.valid && g.gap <= reach[a] + moving[o] + g.tolerance) pairs.push_back(pair);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

/// A component's solve: its members (sorted) and their sub-step.
struct Component {
  std::vector<std::size_t> members;
  std::vector<Pair> pairs;  ///< its contacts, canonical order
  SteppedOutcome outcome;
  /// Held still because the step's stepped work ran out (MonitorSettings::
  /// max_stepped_work_per_step), not because no velocities keep its gaps.
  bool over_work = false;
};

/// Every movable body of the sub-step held still over it, the others moving as they do: the
/// stepped clusters' fallback (SteppedOutcome::held), here where the step's stepped work is spent.
SteppedOutcome heldSubstep(const std::vector<SteppedBody>& bodies, std::size_t contacts,
                           double duration) {
  SteppedOutcome outcome;
  outcome.duration = duration;
  outcome.contacts.resize(contacts);
  outcome.converged = false;
  outcome.held = true;
  for (const SteppedBody& body : bodies) {
    const bool movable = body.inverse_mass > 0;
    outcome.velocity.push_back(movable ? Eigen::Vector3d::Zero() : body.velocity);
    outcome.angular_velocity.push_back(movable ? Eigen::Vector3d::Zero() : body.angular_velocity);
  }
  return outcome;
}

/// The sub-step's bodies: each movable participant from its start, each fixed one as it moves.
std::vector<SteppedBody> steppedBodiesOf(const World& world, double time,
                                         const SolveParticipants& participants,
                                         const std::vector<Start>& starts) {
  std::vector<SteppedBody> bodies;
  for (const std::size_t p : participants.all) {
    SteppedBody body;
    body.inverse_mass = world.inverseMassOf(p);
    body.radius = world.radius[p];
    if (body.inverse_mass > 0) {
      const Start& start = starts[p];
      body.velocity = start.velocity;
      body.angular_velocity = start.angular_velocity;
      body.kick = start.kick;
      body.spin_factor = world.spin_factor[p];
    } else {
      body.velocity = velocityAt<Motion>(world, p, time);
      body.angular_velocity = angularVelocityAt<Motion>(world, p, time);
    }
    bodies.push_back(body);
  }
  return bodies;
}

/// What a closure's round solved at the grid, per pair: its keeping impulse and its friction
/// impulse (on b), for the next round to start from.
using RoundImpulses = std::map<Pair, std::pair<double, Eigen::Vector3d>>;

/// The sub-step's contacts, and each one's warm start: a force times the span.
struct SteppedContacts {
  std::vector<SteppedContact> contacts;
  std::vector<double> warm;
  std::vector<Pair> pairs;  ///< those of `contacts`
};

/// The component's pairs that have a line to keep apart along, as the sub-step's contacts
/// (`warm_start`: with the arrivals and forces the last sub-step left, or, for a pair the
/// closure's round before solved, that round's impulses).
SteppedContacts steppedContactsOf(const World& world, double time, double span, bool warm_start,
                                  const SolveParticipants& participants,
                                  const std::vector<Pair>& pairs, const RoundImpulses& before) {
  SteppedContacts stepped;
  for (const Pair& pair : pairs) {
    const Geometry g = geometry<Motion>(world, pair, time);
    if (!g.valid) continue;  // coincident centres and no approach: no line to keep apart along
    SteppedContact contact;
    contact.a = participants.slot(pair.first);
    contact.b = participants.slot(pair.second);
    contact.normal = g.normal;
    contact.point = g.point;
    contact.lever_a = g.lever_a;
    contact.lever_b = g.lever_b;
    contact.gap = g.gap;
    contact.band = g.tolerance;
    contact.restitution = world.restitutionOf(pair);
    if (world.friction_model) contact.friction = world.frictionOf(pair);
    if (warm_start) {
      const auto arrived = world.stepping.arrival_speed.find(pair);
      if (arrived != world.stepping.arrival_speed.end()) contact.arrival_speed = arrived->second;
    }
    stepped.contacts.push_back(contact);
    // At the grid, the last sub-step's forces; within a sub-step (whose gravity its members have
    // already), only what changed is solved for.
    const auto force = world.stepping.keeping_force.find(pair);
    const bool known = warm_start && force != world.stepping.keeping_force.end();
    stepped.warm.push_back(known ? force->second * span : 0.0);
    const auto friction = world.stepping.friction_force.find(pair);
    if (warm_start && friction != world.stepping.friction_force.end()) {
      stepped.contacts.back().friction_warm = friction->second * span;
    }
    const auto solved = before.find(pair);
    if (warm_start && solved != before.end()) {
      stepped.warm.back() = solved->second.first;
      stepped.contacts.back().friction_warm = solved->second.second;
    }
    stepped.pairs.push_back(pair);
  }
  return stepped;
}

/// The solve of one component from `starts` over `span`, its work counted in World::stepped_work
/// and cut to what the step has left of MonitorSettings::max_stepped_work_per_step: with less
/// than one iteration over its contacts left, its movable bodies are held still.
void solveComponent(World& world, double time, double span, const std::vector<Start>& starts,
                    bool warm_start, const RoundImpulses& before, Component& component) {
  const SolveParticipants participants =
      solveParticipants(world, component.members, component.pairs);
  const std::vector<SteppedBody> bodies = steppedBodiesOf(world, time, participants, starts);
  SteppedContacts stepped =
      steppedContactsOf(world, time, span, warm_start, participants, component.pairs, before);
  component.pairs = std::move(stepped.pairs);
  SteppedSettings settings;
  settings.duration = span;
  settings.restitution_threshold = world.restitution_threshold;
  if (world.friction_model) settings.friction = world.friction_model.swept;
  // An iteration of a solve, or a sweep, goes over every contact of the component.
  const std::size_t per_iteration = std::max<std::size_t>(1, stepped.contacts.size());
  const std::size_t bound = world.settings.max_stepped_work_per_step;
  if (bound > 0) {
    const std::size_t left = (bound - std::min(bound, world.stepped_work)) / per_iteration;
    if (left == 0) {
      component.outcome = heldSubstep(bodies, stepped.contacts.size(), span);
      component.over_work = true;
      return;
    }
    settings.max_total_iterations =
        static_cast<int>(std::min<std::size_t>(left, std::numeric_limits<int>::max()));
  }
  component.outcome = solveSteppedSubstep(bodies, stepped.contacts, settings, stepped.warm);
  const int spent = component.outcome.iterations + component.outcome.friction_sweeps;
  world.stepped_work += static_cast<std::size_t>(spent) * per_iteration;
  // Held where its work ran out: the bound's, not a wedge's.
  component.over_work = component.outcome.held && spent >= settings.max_total_iterations;
}

/// Takes a lasting group apart: its bodies leave it (to be formed again by the caller).
void leaveLastingGroup(World& world, std::size_t body, std::vector<std::size_t>& changed) {
  const int group = world.tracks[body].group;
  if (group < 0) return;
  ContactGroup& dissolved = world.groups[static_cast<std::size_t>(group)];
  chargeIntegration(world, dissolved);
  dissolved.alive = false;
  for (const std::size_t member : dissolved.bodies) {
    world.tracks[member].group = -1;
    if (member < world.partners.size()) world.partners[member].clear();
    changed.push_back(member);
  }
  dissolved.bodies.clear();
  dissolved.contacts.clear();
}

/// Numbers the clusters' bodies again (Track::stepped) after clusters were added or removed.
void indexClusters(World& world) {
  for (std::size_t c = 0; c < world.stepping.clusters.size(); ++c) {
    for (const std::size_t body : world.stepping.clusters[c].bodies) {
      world.tracks[body].stepped = static_cast<int>(c);
    }
  }
}

/// Whether `p` is a body the solves move.
bool movable(const World& world, std::size_t p) {
  return !world.isObstacle(p) && world.inverse_mass[p] > 0;
}

/// How far each tracked body may move over `horizon` from `time` (reachBefore); 0 for the others.
std::vector<double> reachesOver(const World& world, double time, double horizon) {
  std::vector<double> reach(world.bodies.size(), 0.0);
  for (std::size_t i = 0; i < world.bodies.size(); ++i) {
    if (world.tracks[i].known) reach[i] = reachBefore(world, i, time, horizon);
  }
  return reach;
}

/// At the grid: the tracked bodies of the connected sets of near pairs with at least min_bodies,
/// or with at least two and a body over its work budget (Track::over_budget); such a body near
/// no other is unmarked, back with the exact model.
std::vector<char> gridMembers(World& world, const std::vector<Pair>& near) {
  const std::size_t n = world.bodies.size();
  ConnectedSets sets(n);
  for (const Pair& pair : near) {
    if (movable(world, pair.first) && movable(world, pair.second)) {
      sets.link(pair.first, pair.second);
    }
  }
  std::vector<char> member(n, 0);
  for (const std::vector<std::size_t>& set : sets.sets()) {
    if (!movable(world, set.front())) continue;
    const bool marked = std::any_of(
        set.begin(), set.end(), [&](std::size_t body) { return world.tracks[body].over_budget; });
    if (set.size() == 1) world.tracks[set.front()].over_budget = false;
    if (set.size() < world.stepping.min_bodies && !(marked && set.size() >= 2)) continue;
    for (const std::size_t body : set) member[body] = world.tracks[body].known ? 1 : 0;
  }
  return member;
}

/// What a region's solve takes from `time` to `end`, growing as near pairs bring outsiders in:
/// its members, where each starts, and the pairs that are contacts of the solve.
struct Region {
  double time = 0.0;
  double end = 0.0;
  bool grid = false;
  std::vector<char> member;
  std::vector<Start> starts;
  std::vector<char> started;
  std::set<Pair> contact_pairs;
};

/// A body that is in a cluster not being solved again joins with its whole cluster.
void addClusterOf(const World& world, std::size_t body, Region& region) {
  const int cluster = world.tracks[body].stepped;
  if (cluster < 0 || region.grid) return;
  for (const std::size_t other :
       world.stepping.clusters[static_cast<std::size_t>(cluster)].bodies) {
    region.member[other] = 1;
  }
}

/// Where each member not started yet starts.
void startMembers(const World& world, Region& region) {
  const double span = region.end - region.time;
  for (std::size_t body = 0; body < world.bodies.size(); ++body) {
    if (!region.member[body] || region.started[body]) continue;
    region.started[body] = 1;
    Start& start = region.starts[body];
    start.position = positionAt<Motion>(world, body, region.time);
    start.velocity = velocityAt<Motion>(world, body, region.time);
    start.angular_velocity = angularVelocityAt<Motion>(world, body, region.time);
    // Gravity once per sub-step: a body of a cluster solved again within its sub-step has it.
    const bool given = world.stepped(body) && world.tracks[body].kicked_until >= region.end;
    start.kick = given ? Eigen::Vector3d::Zero() : Eigen::Vector3d(world.gravity * span);
  }
}

/// The near pairs with a member: their outsiders join (an immovable body stays a fixed
/// participant), and the pairs are contacts of the solve. True when anything was added.
bool takeNear(const World& world, const std::vector<Pair>& pairs, Region& region) {
  bool grown = false;
  for (const Pair& pair : pairs) {
    const bool in_first = region.member[pair.first] != 0;
    const bool in_second = !world.isObstacle(pair.second) && region.member[pair.second] != 0;
    if (!in_first && !in_second) continue;
    for (const std::size_t p : {pair.first, pair.second}) {
      if (movable(world, p) && !region.member[p]) {
        region.member[p] = 1;
        addClusterOf(world, p, region);
        grown = true;
      }
    }
    grown = region.contact_pairs.insert(pair).second || grown;
  }
  startMembers(world, region);
  return grown;
}

/// The region of `member` (with the clusters of its bodies) and of the near pairs it touches.
Region setUpRegion(const World& world, double time, double end, bool grid, std::vector<char> member,
                   const std::vector<Pair>& near) {
  const std::size_t n = world.bodies.size();
  Region region;
  region.time = time;
  region.end = end;
  region.grid = grid;
  region.member = std::move(member);
  for (std::size_t i = 0; i < n; ++i) {
    if (region.member[i]) addClusterOf(world, i, region);
  }
  region.starts.assign(n, Start{});
  region.started.assign(n, 0);
  takeNear(world, near, region);
  return region;
}

/// The connected components of the region's contact pairs among its members, each with its
/// pairs.
std::vector<Component> componentsOf(const World& world, const Region& region) {
  const std::size_t n = world.bodies.size();
  ConnectedSets sets(n);
  for (const Pair& pair : region.contact_pairs) {
    if (movable(world, pair.first) && movable(world, pair.second)) {
      sets.link(pair.first, pair.second);
    }
  }
  std::vector<Component> components;
  std::vector<long> component_of(n, -1);
  for (const std::vector<std::size_t>& set : sets.sets()) {
    if (!region.member[set.front()]) continue;
    component_of[set.front()] = static_cast<long>(components.size());
    components.emplace_back();
    components.back().members = set;
    for (const std::size_t body : set) component_of[body] = component_of[set.front()];
  }
  for (const Pair& pair : region.contact_pairs) {
    const std::size_t body = movable(world, pair.first) ? pair.first : pair.second;
    components[static_cast<std::size_t>(component_of[body])].pairs.push_back(pair);
  }
  return components;
}

/// The solved velocities may carry a member farther than its reach before.
void widenReaches(const std::vector<Component>& components, std::vector<double>& reach) {
  for (const Component& component : components) {
    for (std::size_t i = 0; i < component.members.size(); ++i) {
      reach[component.members[i]] =
          std::max(reach[component.members[i]],
                   component.outcome.velocity[i].norm() * component.outcome.duration);
    }
  }
}

/// The clusters that were: those whose bodies are solved now are replaced (all, at the grid);
/// their bodies outside the region go back to the exact model, and their contacts outside it end.
void replaceClusters(World& world, const Region& region, std::vector<std::size_t>& changed,
                     std::vector<std::size_t>& released) {
  const std::vector<char>& member = region.member;
  std::vector<SteppedCluster> kept;
  for (SteppedCluster& cluster : world.stepping.clusters) {
    bool replaced = region.grid;
    for (const std::size_t body : cluster.bodies) replaced = replaced || member[body];
    if (!replaced) {
      kept.push_back(std::move(cluster));
      continue;
    }
    for (const std::size_t body : cluster.bodies) {
      if (member[body]) continue;
      // Out of every cluster: back to the exact model, from where it is, under gravity.
      Track& track = world.tracks[body];
      track.position = positionAt<Motion>(world, body, region.time);
      track.velocity = velocityAt<Motion>(world, body, region.time);
      track.time = region.time;
      track.acceleration = world.gravity;
      track.angular_acceleration.setZero();
      track.stepped = -1;
      startFlight(world, body);
      changed.push_back(body);
      released.push_back(body);
    }
    for (const SteppedClusterContact& contact : cluster.contacts) {
      if (!member[contact.pair.first] &&
          (world.isObstacle(contact.pair.second) || !member[contact.pair.second])) {
        world.contact_since.erase(contact.pair);
      }
    }
  }
  world.stepping.clusters = std::move(kept);
}

/// The component's members move with its sub-step from the region's instant, out of any lasting
/// group.
void storeClusterTracks(World& world, const Region& region, const Component& component,
                        std::vector<std::size_t>& changed) {
  for (std::size_t i = 0; i < component.members.size(); ++i) {
    const std::size_t body = component.members[i];
    leaveLastingGroup(world, body, changed);
    Track& track = world.tracks[body];
    track.position = region.starts[body].position;
    track.velocity = component.outcome.velocity[i];
    track.angular_velocity = component.outcome.angular_velocity[i];
    track.acceleration.setZero();
    track.angular_acceleration.setZero();
    track.time = region.time;
    track.constrained = nullptr;
    track.kicked_until = region.end;
    track.stepped = 0;  // numbered by indexClusters
    changed.push_back(body);
  }
}

/// What the component's contacts leave the next sub-step (arrivals, keeping forces), and those
/// that carried a keeping impulse as the cluster's contacts; the others no longer last.
void storeClusterContacts(World& world, double time, const Component& component,
                          SteppedCluster& cluster) {
  Stepping& stepping = world.stepping;
  const SteppedOutcome& outcome = component.outcome;
  for (std::size_t k = 0; k < component.pairs.size(); ++k) {
    const Pair& pair = component.pairs[k];
    const SteppedContactOutcome& received = outcome.contacts[k];
    if (received.arrival_speed > 0) {
      stepping.arrival_speed[pair] = received.arrival_speed;
    } else {
      stepping.arrival_speed.erase(pair);
    }
    if (received.keeping_impulse > 0 || received.bounce_impulse > 0) {
      stepping.keeping_force[pair] = received.keeping_impulse / outcome.duration;
    } else {
      stepping.keeping_force.erase(pair);
    }
    if (received.friction_impulse > 0) {
      stepping.friction_force[pair] =
          (received.friction_impulse / outcome.duration) * received.friction_direction;
    } else {
      stepping.friction_force.erase(pair);
    }
    if (!(received.keeping_impulse > 0)) {
      world.contact_since.erase(pair);
      continue;
    }
    const Geometry g = geometry<Motion>(world, pair, time);
    SteppedClusterContact contact;
    contact.pair = pair;
    contact.normal = g.normal;
    contact.point = g.point;
    contact.keeping_impulse = received.keeping_impulse;
    contact.friction_impulse = received.friction_impulse;
    contact.friction_direction = received.friction_direction;
    contact.sticking = received.sticking;
    world.contact_since.emplace(pair, time);
    cluster.contacts.push_back(contact);
  }
}

/// A solved component becomes a cluster over its sub-step (one held counted as a fallback).
void storeCluster(World& world, const Region& region, const Component& component,
                  std::vector<std::size_t>& changed, StepReport& report) {
  SteppedCluster cluster;
  cluster.bodies = component.members;
  cluster.start = region.time;
  cluster.end = region.time + component.outcome.duration;
  if (component.over_work) {
    for (const std::size_t body : component.members) {
      if (movable(world, body)) report.over_stepped_work.push_back(body);
    }
  } else if (component.outcome.held) {
    ++world.stepping.held;
    ++report.fallbacks;
  }
  storeClusterTracks(world, region, component, changed);
  storeClusterContacts(world, region.time, component, cluster);
  world.stepping.clusters.push_back(std::move(cluster));
}

/// Whether the step's stepped work is spent (MonitorSettings::max_stepped_work_per_step).
bool steppedWorkSpent(const World& world) {
  const std::size_t bound = world.settings.max_stepped_work_per_step;
  return bound > 0 && world.stepped_work >= bound;
}

/// The pairs near each other over `span` from `time` (nearPairs), the search counted in the step's
/// stepped work: one unit for each body it placed and each pair whose contact geometry it
/// computed.
std::vector<Pair> countedNearPairs(World& world, double time, double span,
                                   const std::vector<double>& reach) {
  std::size_t looked_at = 0;
  std::vector<Pair> near = nearPairs(world, time, span, reach, looked_at);
  world.stepped_work += looked_at;
  return near;
}

/// The step's stepped work spent: the clusters with a body of `member` (at the grid: every
/// cluster), and the members in none, are held still from `time` to `end` as they are, without
/// looking for near pairs: the stepped clusters' fallback, their bodies named in
/// report.over_stepped_work. Their contacts carry no impulse over it (none is published; the next
/// sub-step's search finds them again). A body in no cluster at the grid stays with the exact
/// model.
void holdRegion(World& world, double time, double end, std::vector<char> member, bool grid,
                std::vector<std::size_t>& changed, std::vector<std::size_t>& released,
                StepReport& report) {
  const std::size_t n = world.bodies.size();
  if (grid) {
    member.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) member[i] = world.stepped(i) ? 1 : 0;
  }
  Region region = setUpRegion(world, time, end, grid, std::move(member), {});
  startMembers(world, region);
  std::vector<Component> components;
  std::vector<char> placed(n, 0);
  for (const SteppedCluster& cluster : world.stepping.clusters) {
    bool in_region = false;
    for (const std::size_t body : cluster.bodies) in_region = in_region || region.member[body];
    if (!in_region) continue;
    Component component;
    component.members = cluster.bodies;
    for (const SteppedClusterContact& contact : cluster.contacts) {
      component.pairs.push_back(contact.pair);
    }
    components.push_back(std::move(component));
    for (const std::size_t body : cluster.bodies) placed[body] = 1;
  }
  for (std::size_t body = 0; body < n; ++body) {
    if (region.member[body] && !placed[body] && movable(world, body)) {
      components.push_back(Component{{body}, {}, {}, false});
    }
  }
  for (Component& component : components) {
    std::vector<SteppedBody> bodies(component.members.size());
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      bodies[i].inverse_mass = world.inverseMassOf(component.members[i]);  // movable: held
    }
    component.outcome = heldSubstep(bodies, component.pairs.size(), end - time);
    component.over_work = true;
  }
  replaceClusters(world, region, changed, released);
  for (const Component& component : components) {
    storeCluster(world, region, component, changed, report);
  }
  indexClusters(world);
}

/// Solves the bodies of `member` (and every body their sub-steps bring near them) from `time`
/// to `end`, in connected components of near pairs, and makes them the clusters in place of
/// those they were in. `grid`: every tracked body is looked at and only components of at least
/// min_bodies are stepped (`member`: empty, found here); otherwise every component of the region
/// is.
void solveRegion(World& world, double time, double end, std::vector<char> member, bool grid,
                 std::vector<std::size_t>& changed, std::vector<std::size_t>& released,
                 StepReport& report) {
  if (steppedWorkSpent(world)) {
    holdRegion(world, time, end, std::move(member), grid, changed, released, report);
    return;
  }
  const double span = end - time;
  // Near is judged over a whole sub-step at least (stepped_cluster_time_step), whatever this one
  // is: a sub-step shortened to the rest of an update, or an update a little early, would
  // otherwise part a cluster for one sub-step and hand its bodies to the exact model.
  const double horizon = std::max(span, world.stepping.time_step);
  std::vector<double> reach = reachesOver(world, time, horizon);
  const std::vector<Pair> near = countedNearPairs(world, time, horizon, reach);
  Region region = setUpRegion(world, time, end, grid,
                              grid ? gridMembers(world, near) : std::move(member), near);
  // The closure: the components solved, then near pairs again with the solved velocities. At
  // the grid a round starts from the round before's impulses: its region, like the first, is
  // the same set of pairs whatever the bodies are called. (Within a sub-step the order of the
  // events that brought bodies in may be a name's, and a warm start would carry it.)
  std::vector<Component> components;
  RoundImpulses before;
  for (int closure = 0;; ++closure) {
    components = componentsOf(world, region);
    for (Component& component : components) {
      solveComponent(world, time, span, region.starts, grid, before, component);
    }
    before.clear();
    for (const Component& component : components) {
      for (std::size_t k = 0; k < component.pairs.size(); ++k) {
        const SteppedContactOutcome& received = component.outcome.contacts[k];
        before[component.pairs[k]] = {received.keeping_impulse,
                                      received.friction_impulse * received.friction_direction};
      }
    }
    if (closure + 1 >= kMaxClosures) break;
    widenReaches(components, reach);
    if (!takeNear(world, countedNearPairs(world, time, horizon, reach), region)) break;
  }
  replaceClusters(world, region, changed, released);
  for (const Component& component : components) {
    storeCluster(world, region, component, changed, report);
  }
  indexClusters(world);
}

/// A cluster's contact rests where its surfaces do not move; otherwise it rolls where it sticks.
ContactState clusterContactState(const World& world, double time,
                                 const SteppedClusterContact& contact) {
  if (surfaceSpeed(world, contact.pair, time) <= 1e-9) return ContactState::kResting;
  return contact.sticking ? ContactState::kRolling : ContactState::kSliding;
}

}  // namespace

// A box about obstacle `o`'s origin at its placement that a ball's box of half-width
// r (1 + contact_tolerance) + reach about its centre (nearBodyBox) must overlap for the
// ball's surface to be within reach + moving + the touching band of the obstacle's at `time`:
// the shape lies within its bounding radius R of its origin, which moves at most |v| |time -
// placement| (straight on, or on the screw of its twist: shapeAt), so the gap is at least the
// centres' distance less r, R and that; the band (contactGeometry's) is at most
// contact_tolerance (r + R) and a few roundings, the relative 1e-9 in each box. Not finite for a
// plane (every body asks it).
Box nearObstacleBox(const World& world, std::size_t o, double time, double moving) {
  const PlacedShape& placed = world.obstacle_tracks[o].placed;
  const double bounding = boundingRadiusOf(placed.shape);
  const Eigen::Vector3d& origin = placed.pose.transform.translation();
  const double travel = placed.pose.velocity.norm() * std::abs(time - placed.pose.time);
  double half = bounding * (1 + world.settings.contact_tolerance) + travel + moving;
  half += 1e-9 * (origin.lpNorm<Eigen::Infinity>() + bounding + travel + moving);
  return Box::about(origin, half);
}

// The ball's side of nearObstacleBox.
Box nearBodyBox(const World& world, double radius, const Eigen::Vector3d& centre, double reach) {
  double half = radius * (1 + world.settings.contact_tolerance) + reach;
  half += 1e-9 * (centre.lpNorm<Eigen::Infinity>() + radius + reach);
  return Box::about(centre, half);
}

double nextSteppedEvent(const World& world, double time) {
  const Stepping& stepping = world.stepping;
  if (!stepping.enabled()) return INFINITY;
  // The step's end starts the next step's first sub-step.
  double next = stepping.next < stepping.substeps ? stepping.instant(stepping.next) : INFINITY;
  for (const SteppedCluster& cluster : stepping.clusters) next = std::min(next, cluster.end);
  return next < time ? next : INFINITY;
}

void advanceStepped(World& world, double time, std::vector<std::size_t>& changed,
                    std::vector<std::size_t>& released, StepReport& report) {
  Stepping& stepping = world.stepping;
  if (!stepping.enabled()) return;
  if (stepping.next < stepping.substeps && stepping.instant(stepping.next) <= time) {
    ++stepping.next;
    std::size_t tracked = 0;
    for (std::size_t i = 0; i < world.bodies.size(); ++i) {
      tracked += world.tracks[i].known && world.inverse_mass[i] > 0 ? 1 : 0;
    }
    // Fewer bodies than a cluster needs and no cluster: nothing to look at (the exact model's
    // scenes pay nothing for the sub-steps).
    if (tracked < stepping.min_bodies && stepping.clusters.empty()) {
      for (Track& track : world.tracks) track.over_budget = false;
      return;
    }
    solveRegion(world, time, stepping.instant(stepping.next), {}, true, changed, released, report);
    return;
  }
  std::vector<char> member(world.bodies.size(), 0);
  bool any = false;
  for (SteppedCluster& cluster : stepping.clusters) {
    if (!(cluster.end <= time) && !cluster.stale) continue;
    cluster.stale = false;
    for (const std::size_t body : cluster.bodies) member[body] = 1;
    any = true;
  }
  const double end = stepping.instant(stepping.next);
  if (any && end > time) {
    solveRegion(world, time, end, member, false, changed, released, report);
  }
}

void stepOverBudget(World& world, double time, const std::vector<std::size_t>& over_budget,
                    std::vector<std::size_t>& changed, std::vector<std::size_t>& released,
                    StepReport& report) {
  Stepping& stepping = world.stepping;
  const double end = stepping.instant(stepping.next);
  std::vector<char> member(world.bodies.size(), 0);
  for (const std::size_t body : over_budget) {
    world.tracks[body].over_budget = true;
    member[body] = 1;
  }
  if (!(end > time)) return;  // the grid's instant is now: the marked bodies are stepped there
  solveRegion(world, time, end, member, false, changed, released, report);
}

void joinStepped(World& world, double time, const std::vector<std::size_t>& moved,
                 std::vector<std::size_t>& changed, StepReport& report) {
  Stepping& stepping = world.stepping;
  if (stepping.clusters.empty() || moved.empty()) return;
  const double end = stepping.instant(stepping.next);
  const double span = end - time;
  if (!(span > 0)) return;  // the sub-step ends now: the body is looked at with the next
  // Each cluster's box over the rest of its sub-step.
  std::vector<Box> cluster_boxes;
  for (const SteppedCluster& cluster : stepping.clusters) {
    Box box{Eigen::Vector3d::Constant(INFINITY), Eigen::Vector3d::Constant(-INFINITY)};
    for (const std::size_t body : cluster.bodies) {
      const Eigen::Vector3d here = positionAt<Motion>(world, body, time);
      const Eigen::Vector3d there = positionAt<Motion>(world, body, end);
      const Eigen::Vector3d low = here.cwiseMin(there).array() - world.radius[body];
      const Eigen::Vector3d high = here.cwiseMax(there).array() + world.radius[body];
      box.low = box.low.cwiseMin(low);
      box.high = box.high.cwiseMax(high);
    }
    cluster_boxes.push_back(box);
  }
  std::vector<char> member(world.bodies.size(), 0);
  bool any = false;
  for (const std::size_t body : moved) {
    if (!world.tracks[body].known || world.stepped(body) || world.inverse_mass[body] == 0.0) {
      continue;
    }
    const double reach = reachBefore(world, body, time, span);
    const Eigen::Vector3d centre = positionAt<Motion>(world, body, time);
    const double half = world.radius[body] * (1 + 2 * world.settings.contact_tolerance) + reach;
    const Box box = Box::about(centre, half);
    for (std::size_t c = 0; c < stepping.clusters.size(); ++c) {
      if (!cluster_boxes[c].overlaps(box)) continue;
      for (const std::size_t other : stepping.clusters[c].bodies) {
        const Geometry g =
            geometry<Motion>(world, Pair(std::min(body, other), std::max(body, other)), time);
        const double other_reach = velocityAt<Motion>(world, other, time).norm() * span;
        if (g.valid && g.gap <= reach + other_reach + g.tolerance) {
          member[body] = 1;
          for (const std::size_t m : stepping.clusters[c].bodies) member[m] = 1;
          any = true;
          break;
        }
      }
    }
  }
  std::vector<std::size_t> released;  // none: a re-solve within a sub-step releases no body
  if (any) solveRegion(world, time, end, member, false, changed, released, report);
}

void reportSteppedContacts(const World& world, double time, std::vector<ContactRecord>& contacts) {
  for (const SteppedCluster& cluster : world.stepping.clusters) {
    const double duration = cluster.end - cluster.start;
    if (!(duration > 0)) continue;
    for (const SteppedClusterContact& contact : cluster.contacts) {
      const auto since = world.contact_since.find(contact.pair);
      contacts.push_back(
          contactRecord(world, time, contact.pair, contact.point, contact.normal,
                        contact.keeping_impulse / duration,
                        contact.friction_impulse / duration * contact.friction_direction,
                        clusterContactState(world, time, contact),
                        since == world.contact_since.end() ? cluster.start : since->second));
    }
  }
}

std::vector<Pair> touchingPairsOf(const World& world, double time,
                                  const std::vector<std::size_t>& bodies, const PairIndex& index) {
  std::vector<Pair> touching;
  for (const std::size_t body : bodies) {
    if (body >= index.of.size()) continue;
    for (const std::size_t k : index.of[body]) {
      const Pair& pair = index.pairs[k];
      if (world.steppedPair(pair)) continue;
      const Geometry g = geometry<Motion>(world, pair, time);
      if (g.valid && std::abs(g.gap) <= g.tolerance) touching.push_back(pair);
    }
  }
  std::sort(touching.begin(), touching.end());
  touching.erase(std::unique(touching.begin(), touching.end()), touching.end());
  return touching;
}

void clearStepped(World& world, double time) {
  for (const SteppedCluster& cluster : world.stepping.clusters) {
    for (const std::size_t body : cluster.bodies) {
      Track& track = world.tracks[body];
      if (track.known) {
        track.position = positionAt<Motion>(world, body, time);
        track.velocity = velocityAt<Motion>(world, body, time);
        track.time = time;
        track.acceleration = world.gravity;
      }
      track.stepped = -1;
      if (track.known) startFlight(world, body);
    }
  }
  world.stepping.clusters.clear();
  world.stepping.keeping_force.clear();
  world.stepping.friction_force.clear();
  world.stepping.arrival_speed.clear();
}

std::size_t steppedBodies(const World& world) {
  std::size_t count = 0;
  for (const SteppedCluster& cluster : world.stepping.clusters) count += cluster.bodies.size();
  return count;
}

}  // namespace collision_response::core::monitor
