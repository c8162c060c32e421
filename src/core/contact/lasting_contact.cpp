#include "contact/lasting_contact.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "contact/solve_participants.h"
#include "contact/stepped_clusters.h"
#include "model/candidate_pairs.h"
#include "model/motion_model.h"
#include "solver/contact_forces.h"
#include "solver/contact_projection.h"

namespace collision_response::core {

const char* toString(ContactState state) {
  switch (state) {
    case ContactState::kResting:
      return "resting";
    case ContactState::kSliding:
      return "sliding";
    case ContactState::kRolling:
      return "rolling";
  }
  return "resting";
}

namespace monitor {
namespace {

using Motion = UnderGravity;  // lasting contact needs a steady force: the gravity effect

/// m: how far a pressed contact of a curved group (`pair`, integrated by ConstrainedStep) may
/// have drifted from touching by its integration alone: the integrator's error per step, absolute
/// and relative to the contact's coordinates (doc/model.md, "Motion between events"); 0 for any
/// other pair. Its constraint holds at the acceleration only, so its gap wanders by that error,
/// and where the normal's rate of turning jumps (a ball passing from a box's face onto its edge:
/// curvature 0 to 1 / r) a step across the jump leaves up to 4e-10 m, ten times the touching
/// band of a 33.5 mm ball. Such a contact still touches: it ends where its force is 0.
double integrationDrift(const World& world, const Pair& pair, const Geometry& g) {
  if (world.contact_since.count(pair) == 0) return 0.0;
  const Track& track = world.tracks[pair.first];
  if (!track.constrained || track.constrained->free()) return 0.0;
  return world.integration_tolerance * (1.0 + g.point.lpNorm<Eigen::Infinity>());
}

/// A candidate of lasting contact: touching (or overlapping: then it is held where it is; or a
/// curved group's pressed contact drifted off by its integration, integrationDrift) and neither
/// approaching nor separating faster than a body falls within the touching band, or within the
/// overlap of an overlapping pair, widened under discrete detection by a sample period's arc
/// (World::riseBand): a separation too slow to leave the overlap, or to stay out of it until a
/// sample sees it out, would fall back into it, where no impact is found again.
bool lastingCandidate(const World& world, const Pair& pair, double time, const Geometry& g) {
  if (!g.valid || g.gap > g.tolerance + integrationDrift(world, pair, g)) return false;
  const NormalMotion motion = normalMotion<Motion>(world, pair, g, time);
  const double pressing = world.gravity.norm();
  return std::abs(motion.speed) <=
         restSpeed(pressing, world.riseBand(g, pressing)) + motion.rounding;
}

void dissolve(World& world, std::size_t group, std::vector<std::size_t>& members) {
  ContactGroup& dissolved = world.groups[group];
  chargeIntegration(world, dissolved);
  dissolved.alive = false;
  for (const std::size_t body : dissolved.bodies) {
    world.tracks[body].group = -1;
    world.partners[body].clear();
    members.push_back(body);
  }
  dissolved.bodies.clear();
  dissolved.contacts.clear();
}

std::size_t newGroup(World& world) {
  for (std::size_t g = 0; g < world.groups.size(); ++g) {
    if (!world.groups[g].alive) return g;
  }
  world.groups.emplace_back();
  return world.groups.size() - 1;
}

/// A slip slower than what integrating curved contact leaves behind (1000 times its tolerance,
/// at least 1e-9 m/s) is none: the contact sticks, and its slip is closed.
ContactForceSettings lastingContactSettings(const World& world) {
  ContactForceSettings settings;
  settings.slip_tolerance = std::max(1e-9, 1e3 * world.integration_tolerance);
  return settings;
}

/// The instant a sliding contact's slip stops, when its rate is constant and against it (the
/// motion of a group on planes); infinity when it does not stop.
double slipStops(const ContactForce& force, double time) {
  const double slip = force.slip.norm();
  if (!(slip > 0)) return INFINITY;
  const Eigen::Vector3d direction = force.slip / slip;
  const double rate = force.slip_acceleration.dot(direction);
  if (!(rate < 0)) return INFINITY;
  return time + slip / -rate;
}

/// The candidates of one connected set: each pair with its geometry at the set's instant.
using Candidates = std::vector<std::pair<Pair, Geometry>>;

std::vector<Pair> pairsOf(const Candidates& candidates) {
  std::vector<Pair> pairs;
  for (const auto& [pair, g] : candidates) pairs.push_back(pair);
  return pairs;
}

/// A group's solve at its instant: its participants (the group's bodies, then the fixed ones) as
/// the force solver's bodies, where they are, its candidates as the solver's contacts, and the
/// forces.
struct GroupSolve {
  SolveParticipants participants;
  std::vector<ForceBody> bodies;
  std::vector<Eigen::Vector3d> positions;
  std::vector<ForceContact> contacts;
  ContactForceSolution solution;
};

/// The solver's bodies: each participant as it moves at `time`, a movable one under gravity.
std::vector<ForceBody> forceBodiesOf(const World& world, double time,
                                     const SolveParticipants& participants) {
  std::vector<ForceBody> force_bodies;
  for (const std::size_t p : participants.all) {
    ForceBody body;
    body.inverse_mass = world.inverseMassOf(p);
    body.radius = world.radius[p];
    body.velocity = velocityAt<Motion>(world, p, time);
    body.angular_velocity = angularVelocityAt<Motion>(world, p, time);
    if (body.inverse_mass > 0) {
      body.spin_factor = world.spin_factor[p];
      body.acceleration = world.gravity;
    }
    force_bodies.push_back(body);
  }
  return force_bodies;
}

/// The solver's contacts, one per candidate (`frictionless`: without friction).
std::vector<ForceContact> forceContactsOf(const World& world, const Candidates& candidates,
                                          const SolveParticipants& participants,
                                          bool frictionless) {
  std::vector<ForceContact> contacts;
  for (const auto& [pair, g] : candidates) {
    ForceContact contact;
    contact.a = participants.slot(pair.first);
    contact.b = participants.slot(pair.second);
    setContactGeometry(g, contact);
    if (world.friction_model && !frictionless) contact.friction = world.frictionOf(pair);
    contacts.push_back(contact);
  }
  return contacts;
}

std::vector<Eigen::Vector3d> positionsOf(const World& world, double time,
                                         const SolveParticipants& participants) {
  std::vector<Eigen::Vector3d> positions;
  for (const std::size_t p : participants.all)
    positions.push_back(positionAt<Motion>(world, p, time));
  return positions;
}

/// The gap each candidate is closed by: within the band, a lasting contact whose integrated
/// motion drifted off it (integrationDrift), or (continuous detection) one whose integrated motion
/// drifted past it, its gap. An overlap the states gave, or one discrete detection found an impact
/// in, is held where it is (0).
std::vector<double> gapsToClose(const World& world, const Candidates& candidates) {
  std::vector<double> gaps;
  for (const auto& [pair, g] : candidates) {
    const bool drifted = world.detection == Detection::kContinuous && g.gap < 0 &&
                         world.contact_since.count(pair) > 0;
    // A candidate apart is within the band or drifted off it (integrationDrift).
    gaps.push_back(g.gap >= -g.tolerance || drifted ? g.gap : 0.0);
  }
  return gaps;
}

/// The group's bodies and contacts at `time`, in the force solver's terms.
GroupSolve setUpGroup(const World& world, double time, const std::vector<std::size_t>& bodies,
                      const Candidates& candidates, bool frictionless) {
  GroupSolve solve;
  solve.participants = solveParticipants(world, bodies, pairsOf(candidates));
  solve.bodies = forceBodiesOf(world, time, solve.participants);
  solve.contacts = forceContactsOf(world, candidates, solve.participants, frictionless);
  solve.positions = positionsOf(world, time, solve.participants);
  return solve;
}

/// Lasting contacts touch: their gaps closed, their normal relative velocities closed; then the
/// forces; then sticking ones do not slip.
void solveGroupForces(const World& world, const std::vector<double>& gaps, GroupSolve& solve) {
  std::vector<ForceContact>& contacts = solve.contacts;
  closeContactGaps(solve.positions, solve.bodies, contacts, gaps);
  closeContactVelocities(solve.bodies, contacts, std::vector<bool>(contacts.size(), false));
  solve.solution = solveContactForces(solve.bodies, contacts, lastingContactSettings(world));
  if (solve.solution.friction_dropped) {
    // Friction's modes did not settle: the group moves without it until it is formed again, its
    // integrated motion and its slips included (solveContactForces).
    for (ForceContact& contact : contacts) contact.friction = 0.0;
  }
  std::vector<bool> sticking(contacts.size(), false);
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    sticking[k] =
        contacts[k].friction > 0 && solve.solution.contacts[k].mode == ContactMode::kSticking;
  }
  if (std::find(sticking.begin(), sticking.end(), true) != sticking.end()) {
    closeContactVelocities(solve.bodies, contacts, sticking);
  }
}

/// Whether the pressed contact `k` curves the group's motion: two spheres whose line of centres
/// turns (they move or accelerate relative to each other), or a sliding contact whose slip turns.
bool curvesMotion(const World& world, const GroupSolve& solve, std::size_t k, bool bounded) {
  const double speed_tolerance = lastingContactSettings(world).slip_tolerance;
  const double acceleration_tolerance = 1e-12 * world.gravity.norm();
  const ContactForce& force = solve.solution.contacts[k];
  const ForceContact& c = solve.contacts[k];
  // A finite shape's face (bounded) ends where the ball reaches an edge: a ball that moves on
  // it is followed step by step too, from one feature to the next.
  if (c.curvature > 0 || bounded) {
    const Eigen::Vector3d relative_velocity =
        solve.bodies[c.b].velocity - solve.bodies[c.a].velocity;
    const Eigen::Vector3d relative_acceleration =
        solve.solution.acceleration[c.b] - solve.solution.acceleration[c.a];
    if (relative_velocity.norm() > speed_tolerance ||
        relative_acceleration.norm() > acceleration_tolerance) {
      return true;
    }
  }
  if (force.mode == ContactMode::kSliding && c.friction > 0 && force.slip.norm() > 0) {
    const Eigen::Vector3d along = force.slip.normalized();
    const Eigen::Vector3d rate = force.slip_acceleration;
    if ((rate - rate.dot(along) * along).norm() > 1e-12 * (rate.norm() + acceleration_tolerance)) {
      return true;
    }
  }
  return false;
}

/// The contacts that press (the others separate) and what they press.
struct Pressed {
  std::vector<std::size_t> contacts;  ///< indices into the candidates
  std::vector<char> bodies;           ///< per body of the group: pressed by one of them
  /// Then the motion is integrated; otherwise the forces are constant and it is a parabola.
  bool curved = false;
};

Pressed pressedContacts(const World& world, const std::vector<std::size_t>& bodies,
                        const Candidates& candidates, const GroupSolve& solve) {
  Pressed pressed;
  pressed.bodies.assign(bodies.size(), 0);
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    if (solve.solution.contacts[k].mode == ContactMode::kSeparating) continue;
    pressed.contacts.push_back(k);
    if (curvesMotion(world, solve, k, candidates[k].second.bounded)) pressed.curved = true;
    const Pair& pair = candidates[k].first;
    for (const std::size_t p : {pair.first, pair.second}) {
      if (world.inverseMassOf(p) > 0) pressed.bodies[solve.participants.slot(p)] = 1;
    }
  }
  return pressed;
}

/// A curved group's integrated motion, and each participant's slot in it.
struct IntegratedMotion {
  std::shared_ptr<const ConstrainedStep> step;
  std::vector<std::size_t> slot;  ///< per slot of the solve
};

/// The integrated step: the pressed bodies, then the fixed participants of pressed contacts.
IntegratedMotion integrateGroup(const World& world, double time, const Candidates& candidates,
                                const GroupSolve& solve, const Pressed& pressed) {
  const std::size_t count = solve.participants.movable.size();
  IntegratedMotion motion;
  motion.slot.assign(solve.participants.all.size(), 0);
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < count; ++i) {
    if (pressed.bodies[i]) order.push_back(i);
  }
  const std::size_t movable = order.size();
  for (std::size_t i = count; i < solve.participants.all.size(); ++i) order.push_back(i);
  std::vector<ForceBody> step_bodies;
  std::vector<Eigen::Vector3d> step_positions;
  double guess = 0;
  for (std::size_t j = 0; j < order.size(); ++j) {
    motion.slot[order[j]] = j;
    step_bodies.push_back(solve.bodies[order[j]]);
    step_positions.push_back(solve.positions[order[j]]);
    if (j < movable)
      guess = std::max(guess, world.tracks[solve.participants.all[order[j]]].integration_step);
  }
  std::vector<ConstrainedContact> step_contacts;
  for (const std::size_t k : pressed.contacts) {
    ConstrainedContact c;
    c.a = motion.slot[solve.contacts[k].a];
    c.b = motion.slot[solve.contacts[k].b];
    const Geometry& g = candidates[k].second;
    c.plane = g.flat() && !g.bounded;
    if (c.plane) c.plane_normal = -g.normal;
    if (g.bounded) {
      c.shape = std::make_shared<const PlacedShape>(world.placedShape(candidates[k].first.second));
    }
    c.friction = solve.contacts[k].friction;
    c.mode = solve.solution.contacts[k].mode;
    c.slide_direction = solve.solution.contacts[k].slide_direction;
    step_contacts.push_back(c);
  }
  motion.step = std::make_shared<const ConstrainedStep>(
      step_bodies, step_positions, movable, step_contacts, time, std::max(world.step_end, time),
      world.integration_tolerance, lastingContactSettings(world).slip_tolerance,
      guess > 0 ? guess : 1e-3);
  return motion;
}

/// A group's motion from its instant: its solve, its pressed contacts, and (curved) its
/// integrated motion.
struct GroupMotion {
  GroupSolve solve;
  Pressed pressed;
  IntegratedMotion integrated;
};

/// Sets up, solves and (curved) integrates the group (`frictionless`: without friction).
GroupMotion groupMotion(const World& world, double time, const std::vector<std::size_t>& bodies,
                        const Candidates& candidates, bool frictionless) {
  GroupMotion motion;
  motion.solve = setUpGroup(world, time, bodies, candidates, frictionless);
  solveGroupForces(world, gapsToClose(world, candidates), motion.solve);
  motion.pressed = pressedContacts(world, bodies, candidates, motion.solve);
  if (motion.pressed.curved) {
    motion.integrated = integrateGroup(world, time, candidates, motion.solve, motion.pressed);
  }
  return motion;
}

/// Whether the modes friction chose stop holding at once: the integrated motion ends at the
/// group's instant, to the time line's resolution (slips at the slip tolerance, whose directions
/// the solve and the integrator read apart).
bool frictionModesStopAtOnce(const World& world, double time, const GroupMotion& motion) {
  const ConstrainedStep* step = motion.integrated.step.get();
  return step && step->modeChanged() &&
         !(step->end() > time + eventResolution(step->end(), world.step_end - world.now)) &&
         std::any_of(motion.solve.contacts.begin(), motion.solve.contacts.end(),
                     [](const ForceContact& c) { return c.friction > 0; });
}

/// The pressed contacts last (from `time`, or from when they began to), with the forces of the
/// solve; the separating ones end. The group's next event: a slip that stops, or the end of its
/// integrated motion where its modes change.
void storeGroupContacts(World& world, double time, const Candidates& candidates,
                        const GroupMotion& motion, ContactGroup& contact_group) {
  const GroupSolve& solve = motion.solve;
  contact_group.time = time;
  contact_group.next_event = INFINITY;
  // A slot of a dissolved group may be reused: none of its integrated motion stays.
  contact_group.step.reset();
  contact_group.charged = 0;
  contact_group.scheduled_to = INFINITY;
  contact_group.step_event_taken = false;
  for (const std::size_t k : motion.pressed.contacts) {
    const ContactForce& force = solve.solution.contacts[k];
    const Pair& pair = candidates[k].first;
    const ForceContact& c = solve.contacts[k];
    GroupContact contact;
    contact.pair = pair;
    contact.normal = candidates[k].second.normal;
    contact.point = candidates[k].second.point;
    contact.force = force;
    const auto since = world.contact_since.emplace(pair, time).first;
    contact.since = since->second;
    contact_group.contacts.push_back(contact);
    world.partners[pair.first].push_back(pair.second);
    if (!world.isObstacle(pair.second)) world.partners[pair.second].push_back(pair.first);
    if (force.mode == ContactMode::kSliding && c.friction > 0) {
      contact_group.next_event = std::min(contact_group.next_event, slipStops(force, time));
    }
  }
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    if (solve.solution.contacts[k].mode == ContactMode::kSeparating) {
      world.contact_since.erase(candidates[k].first);
    }
  }
  contact_group.alive = !contact_group.contacts.empty();
  if (motion.integrated.step) {
    contact_group.step = motion.integrated.step;
    contact_group.scheduled_to = motion.integrated.step->end();
    contact_group.curved = true;
  }
}

/// Every body of the group continues from `time` with the solve's motion: a pressed one in
/// `group` (and curved, integrated), any other free of it.
void storeGroupTracks(World& world, double time, const std::vector<std::size_t>& bodies,
                      std::size_t group, const GroupMotion& motion,
                      std::vector<std::size_t>& changed) {
  const GroupSolve& solve = motion.solve;
  const std::shared_ptr<const ConstrainedStep>& step = motion.integrated.step;
  ContactGroup& contact_group = world.groups[group];
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const std::size_t body = bodies[i];
    Track& track = world.tracks[body];
    track.position = solve.positions[i];
    track.angular_velocity = solve.bodies[i].angular_velocity;
    track.time = time;
    track.velocity = solve.bodies[i].velocity;
    track.acceleration = solve.solution.acceleration[i];
    track.angular_acceleration = world.spin_factor[body] != 0.0
                                     ? solve.solution.angular_acceleration[i]
                                     : Eigen::Vector3d::Zero();
    track.constrained = nullptr;
    if (motion.pressed.bodies[i]) {
      track.group = static_cast<int>(group);
      contact_group.bodies.push_back(body);
      if (step) {
        track.constrained = step;
        track.slot = motion.integrated.slot[i];
        track.integration_step = step->nextStep();
      }
    } else {
      track.group = -1;
      startFlight(world, body);
    }
    changed.push_back(body);
  }
}

void fallFreely(World& world, double time, const std::vector<std::size_t>& bodies,
                std::vector<std::size_t>& changed);

/// One connected set of candidates: solve, and give its bodies their motion. Set up, solved and
/// (curved) integrated by groupMotion; where friction's modes stop holding at once, the same
/// without friction; then its contacts and its bodies' tracks stored.
void solveGroup(World& world, double time, const std::vector<std::size_t>& bodies,
                const Candidates& candidates, std::vector<std::size_t>& changed) {
  GroupMotion motion = groupMotion(world, time, bodies, candidates, /*frictionless=*/false);
  if (frictionModesStopAtOnce(world, time, motion)) {
    // Solved again at this instant it would be so for ever, and as its integrated motion ends
    // here its bodies would be looked at by nothing until the step's end. It moves without
    // friction until formed again, as where friction's modes do not settle (solveContactForces).
    motion = groupMotion(world, time, bodies, candidates, /*frictionless=*/true);
  }
  const bool lasted = std::any_of(candidates.begin(), candidates.end(), [&](const auto& c) {
    return world.contact_since.count(c.first) > 0;
  });
  if (motion.pressed.contacts.empty() && !lasted && world.detection == Detection::kContinuous) {
    // Nothing presses, and nothing did: its bodies move on as they were, their gaps and normal
    // velocities unclosed (a ball that left an edge where its force was 0, touching still at the
    // next instant it is looked at, separates at the speed it has: closed, its flight would
    // change, as if the edge had pulled it). A contact that ends here is closed (its drift is the
    // integration's), then let go. Under discrete detection a slow separation is closed still
    // (lastingCandidate: it would fall back into an overlap no sample sees begin).
    fallFreely(world, time, bodies, changed);
    return;
  }
  const std::size_t group = newGroup(world);
  storeGroupContacts(world, time, candidates, motion, world.groups[group]);
  storeGroupTracks(world, time, bodies, group, motion, changed);
}

/// The bodies a search of lasting contact reaches, in the order reached: each one visited joins
/// with the group it was in (dissolved).
class GroupSearch {
 public:
  explicit GroupSearch(World& world) : world_(world), visited_(world.bodies.size(), 0) {}

  /// A tracked movable body joins, unless it moves with a stepped cluster (stepped_clusters.h).
  void visit(std::size_t body) {
    if (visited_[body] || !world_.tracks[body].known || world_.inverse_mass[body] == 0.0 ||
        world_.stepped(body)) {
      return;
    }
    visited_[body] = 1;
    members.push_back(body);
    const int group = world_.tracks[body].group;
    if (group >= 0) {
      dissolved_.clear();
      dissolve(world_, static_cast<std::size_t>(group), dissolved_);
      for (const std::size_t member : dissolved_) {
        if (!visited_[member]) {
          visited_[member] = 1;
          members.push_back(member);
        }
      }
    }
  }

  std::vector<std::size_t> members;

 private:
  World& world_;
  std::vector<char> visited_;
  std::vector<std::size_t> dissolved_;
};

/// The lasting candidates of the search's members at `time`, the other bodies of each joining
/// the search; the pairs that are none no longer last.
Candidates lastingCandidates(World& world, double time, const PairIndex& index,
                             GroupSearch& search) {
  Candidates candidates;
  std::vector<char> seen(index.pairs.size(), 0);
  for (std::size_t i = 0; i < search.members.size(); ++i) {
    const std::size_t body = search.members[i];
    for (const std::size_t k : index.of[body]) {
      if (seen[k]) continue;
      seen[k] = 1;
      const Pair& pair = index.pairs[k];
      if (world.steppedPair(pair)) continue;  // kept apart by the stepped cluster's sub-steps
      const Geometry g = geometry<Motion>(world, pair, time);
      if (!lastingCandidate(world, pair, time, g)) {
        world.contact_since.erase(pair);
        continue;
      }
      candidates.emplace_back(pair, g);
      const std::size_t other = pair.first == body ? pair.second : pair.first;
      if (!world.isObstacle(other)) search.visit(other);
    }
  }
  return candidates;
}

/// A connected set of movable bodies: its bodies (sorted) and its candidates (in the order of
/// their pairs).
struct ConnectedSet {
  std::vector<std::size_t> bodies;
  Candidates candidates;
};

/// The connected sets of `members` through the candidates between two movable bodies (union-find
/// over the members, in sorted order), by their smallest member; some are empty.
std::vector<ConnectedSet> connectedSets(const World& world, std::vector<std::size_t> members,
                                        Candidates candidates) {
  std::sort(members.begin(), members.end());
  std::vector<std::size_t> parent(members.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto slot = [&](std::size_t body) {
    return static_cast<std::size_t>(std::lower_bound(members.begin(), members.end(), body) -
                                    members.begin());
  };
  const auto find = [&parent](std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const auto& [pair, g] : candidates) {
    if (world.inverseMassOf(pair.first) > 0 && world.inverseMassOf(pair.second) > 0) {
      const std::size_t x = find(slot(pair.first)), y = find(slot(pair.second));
      parent[std::max(x, y)] = std::min(x, y);
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<ConnectedSet> sets(members.size());
  for (std::size_t i = 0; i < members.size(); ++i) sets[find(i)].bodies.push_back(members[i]);
  for (const auto& candidate : candidates) {
    const std::size_t body = world.inverseMassOf(candidate.first.first) > 0
                                 ? candidate.first.first
                                 : candidate.first.second;
    sets[find(slot(body))].candidates.push_back(candidate);
  }
  return sets;
}

/// Bodies without lasting contact move under gravity alone, from `time` (unless they already do).
void fallFreely(World& world, double time, const std::vector<std::size_t>& bodies,
                std::vector<std::size_t>& changed) {
  for (const std::size_t body : bodies) {
    Track& track = world.tracks[body];
    if (track.acceleration == world.gravity && track.angular_acceleration.isZero() &&
        (!track.constrained || track.constrained->free())) {
      continue;
    }
    track.position = positionAt<Motion>(world, body, time);
    track.velocity = velocityAt<Motion>(world, body, time);
    track.angular_velocity = angularVelocityAt<Motion>(world, body, time);
    track.time = time;
    track.acceleration = world.gravity;
    track.angular_acceleration.setZero();
    track.constrained = nullptr;
    startFlight(world, body);
    changed.push_back(body);
  }
}

/// A group's contact slides in its force's mode; otherwise it rolls where its surfaces move.
ContactState groupContactState(const World& world, double time, const GroupContact& contact) {
  if (contact.force.mode == ContactMode::kSliding) return ContactState::kSliding;
  return surfaceSpeed(world, contact.pair, time) > 1e-9 ? ContactState::kRolling
                                                        : ContactState::kResting;
}

}  // namespace

void chargeIntegration(World& world, ContactGroup& group) {
  if (!group.step || world.work.size() != world.bodies.size()) return;
  const std::size_t solves = group.step->solves();
  for (const std::size_t body : group.bodies) world.work[body] += solves - group.charged;
  world.work_total += group.bodies.size() * (solves - group.charged);
  group.charged = solves;
}

void clearGroups(World& world) {
  for (ContactGroup& group : world.groups) {
    if (group.alive) chargeIntegration(world, group);
  }
  world.groups.clear();
  for (Track& track : world.tracks) track.group = -1;
  world.partners.assign(world.bodies.size(), {});
  world.groups_current = false;
}

void formGroups(World& world, double time, const std::vector<std::size_t>& seeds,
                const PairIndex& index, std::vector<std::size_t>& changed) {
  if (world.partners.size() != world.bodies.size()) world.partners.assign(world.bodies.size(), {});
  GroupSearch search(world);
  for (const std::size_t seed : seeds) search.visit(seed);
  Candidates candidates = lastingCandidates(world, time, index, search);
  for (const ConnectedSet& set :
       connectedSets(world, std::move(search.members), std::move(candidates))) {
    if (set.bodies.empty()) continue;
    if (set.candidates.empty()) {
      fallFreely(world, time, set.bodies, changed);
    } else {
      solveGroup(world, time, set.bodies, set.candidates, changed);
    }
  }
}

void formAllGroups(World& world, double time, std::vector<std::size_t>& changed) {
  clearGroups(world);
  std::vector<Pair> pairs;
  candidatePairs<Motion>(world, time, time, pairs);
  std::vector<std::vector<std::size_t>> of(world.bodies.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    of[pairs[k].first].push_back(k);
    if (!world.isObstacle(pairs[k].second)) of[pairs[k].second].push_back(k);
  }
  std::vector<std::size_t> seeds;
  for (std::size_t body = 0; body < world.bodies.size(); ++body) {
    if (world.tracks[body].known) seeds.push_back(body);
  }
  formGroups(world, time, seeds, PairIndex{pairs, of}, changed);
  world.groups_current = true;
}

namespace {

/// Its integrated motion reaches past where its pairs were scheduled, or may be integrated on.
bool beyondFrontier(const ContactGroup& group) {
  return group.scheduled_to < group.step->end() || !group.step->complete();
}

}  // namespace

double integratedEvent(const ContactGroup& group) {
  if (!group.step || group.step_event_taken) return INFINITY;
  if (beyondFrontier(group)) return group.scheduled_to;
  return group.step->modeChanged() ? group.step->end() : INFINITY;
}

bool integrateFurther(World& world, std::size_t g, double when) {
  ContactGroup& group = world.groups[g];
  if (!group.step || group.step_event_taken || !beyondFrontier(group) ||
      !(group.scheduled_to <= when) || !(group.scheduled_to < group.next_event)) {
    return false;
  }
  // A query may have integrated it further already (ConstrainedStep's positions past its end).
  if (!(group.step->end() > group.scheduled_to)) group.step->extend();
  group.scheduled_to = group.step->end();
  return true;
}

void takeGroupEvents(ContactGroup& group, double when) {
  group.next_event = INFINITY;
  // Its mode change is taken with them; a frontier at the same instant is not (it is integrated
  // further at its own event, should the group go on as it is).
  if (group.step && !beyondFrontier(group) && integratedEvent(group) <= when) {
    group.step_event_taken = true;
  }
}

std::pair<double, std::size_t> nextGroupEvent(const World& world) {
  std::pair<double, std::size_t> next{INFINITY, 0};
  for (std::size_t g = 0; g < world.groups.size(); ++g) {
    const ContactGroup& group = world.groups[g];
    const double event = std::min(group.next_event, integratedEvent(group));
    if (group.alive && event < next.first) next = {event, g};
  }
  return next;
}

double surfaceSpeed(const World& world, const Pair& pair, double time) {
  const auto [a, other] = pair;
  const Eigen::Vector3d relative =
      velocityAt<Motion>(world, other, time) - velocityAt<Motion>(world, a, time);
  const Eigen::Vector3d turning =
      angularVelocityAt<Motion>(world, other, time) - angularVelocityAt<Motion>(world, a, time);
  return relative.norm() + world.radius[a] * turning.norm();
}

ContactRecord contactRecord(const World& world, double time, const Pair& pair,
                            const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                            double normal_force, const Eigen::Vector3d& friction_force,
                            ContactState state, double since) {
  const auto [a, other] = pair;
  ContactRecord record;
  record.time = time;
  record.body_a = a;
  record.other_is_obstacle = world.isObstacle(other);
  record.other = record.other_is_obstacle ? other - world.bodyCount() : other;
  record.contact_point = point;
  record.normal = normal;
  record.normal_force = normal_force;
  record.friction_force = friction_force;
  record.state = state;
  record.since = since;
  return record;
}

void reportContacts(const World& world, double time, std::vector<ContactRecord>& contacts) {
  for (const ContactGroup& group : world.groups) {
    if (!group.alive) continue;
    for (const GroupContact& contact : group.contacts) {
      contacts.push_back(contactRecord(world, time, contact.pair, contact.point, contact.normal,
                                       contact.force.normal, contact.force.tangential,
                                       groupContactState(world, time, contact), contact.since));
    }
  }
  reportSteppedContacts(world, time, contacts);
  std::sort(contacts.begin(), contacts.end(), [](const ContactRecord& x, const ContactRecord& y) {
    return std::tie(x.body_a, x.other_is_obstacle, x.other) <
           std::tie(y.body_a, y.other_is_obstacle, y.other);
  });
}

}  // namespace monitor
}  // namespace collision_response::core
