#include "impact/instant_resolver.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <unordered_map>
#include <utility>

#include "collision_response/core/impact.h"
#include "model/motion_model.h"
#include "solver/cluster_solver.h"
#include "solver/contact_forces.h"
#include "solver/order_free.h"

namespace collision_response::core::monitor {
namespace {

/// Relative to a contact's fastest approach in the rounds of one instant, the approach below which
/// it strikes again plastically (doc/model.md, "Simultaneous contacts").
constexpr double kRepeatStrikeResolution = 1e-12;

/// A touching contact at the instant: positions do not change during an instant, so its
/// geometry is computed once.
struct InstantContact {
  Pair pair;
  Geometry geometry;
};

/// A cluster ready for the solver: its participants (local index = position in `members`), its
/// bodies and contacts in the solver's terms, and each contact's friction coefficient.
struct PreparedCluster {
  std::vector<std::size_t> members;
  std::vector<ClusterBody> bodies;
  std::vector<ClusterContact> contacts;
  std::vector<double> friction;  ///< per contact, with the friction effect only
};

/// The contacts (indices into `contacts`) whose pair approaches at `time`. A lasting contact
/// (gravity) strikes only when it closes faster than a lasting contact may (restSpeed in its
/// touching band): what its resting forces leave by rounding is not an impact.
template <class Motion>
std::vector<std::size_t> findStriking(const World& world, double time,
                                      const std::vector<InstantContact>& contacts) {
  std::vector<std::size_t> striking;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const Pair& pair = contacts[k].pair;
    const Geometry& g = contacts[k].geometry;
    if (!approaching<Motion>(world, pair, g, time)) continue;
    if constexpr (Motion::kAccelerates) {
      if (world.lasting(pair)) {
        const double closing = (velocityAt<Motion>(world, pair.first, time) -
                                touchingVelocity<Motion>(world, pair, g, time))
                                   .dot(g.normal);
        if (closing <= restSpeed(world.gravity.norm(), g.tolerance)) continue;
      }
    }
    striking.push_back(k);
  }
  return striking;
}

/// Clusters: striking contacts that share a movable body are solved together (a union-find over
/// the participants of the striking contacts only, numbered in sorted order). In the order of
/// each cluster's first striking contact.
std::vector<std::vector<std::size_t>> formClusters(const World& world,
                                                   const std::vector<InstantContact>& contacts,
                                                   const std::vector<std::size_t>& striking) {
  std::vector<std::size_t> involved;
  for (const std::size_t k : striking) {
    involved.push_back(contacts[k].pair.first);
    involved.push_back(contacts[k].pair.second);
  }
  std::sort(involved.begin(), involved.end());
  involved.erase(std::unique(involved.begin(), involved.end()), involved.end());
  const auto slot_of = [&involved](std::size_t participant) {
    return static_cast<std::size_t>(
        std::lower_bound(involved.begin(), involved.end(), participant) - involved.begin());
  };
  ConnectedSets participants(involved.size());
  for (const std::size_t k : striking) {
    const auto [a, other] = contacts[k].pair;
    if (world.inverseMassOf(a) > 0 && world.inverseMassOf(other) > 0) {
      participants.link(slot_of(a), slot_of(other));
    }
  }
  const auto cluster_of = [&](std::size_t k) {
    const auto [a, other] = contacts[k].pair;
    return world.inverseMassOf(a) > 0 ? participants.root(slot_of(a))
                                      : participants.root(slot_of(other));
  };
  std::vector<std::vector<std::size_t>> clusters;
  std::map<std::size_t, std::size_t> cluster_slot;
  for (const std::size_t k : striking) {
    const auto [slot, inserted] = cluster_slot.emplace(cluster_of(k), clusters.size());
    if (inserted) clusters.emplace_back();
    clusters[slot->second].push_back(k);
  }
  return clusters;
}

/// The coefficient of restitution a striking contact uses: the pair's, unless its approach is
/// slower than the restitution threshold (then it rests: 0), or (gravity) its bounce would not
/// leave the touching band (the rest rule, restSpeed). Such a bounce starts an endless series of
/// ever smaller ones under the pressing acceleration g: the k-th after it leaves at e^k e u (u
/// the approach speed) and lands 2 e^k e u / g later, so they add up to 2 e u / (g (1 - e)). The
/// contact rests from that accumulation instant on (its `since`); in between every bounce stays
/// within the band, so the body moves as resting from now. A contact found overlapping (discrete
/// detection finds impacts by overlap at the samples) has the overlap as its band, widened so
/// that the bounce must stay out of it for a sample period (World::riseBand): one that would not
/// would fall back in deeper, a pair that overlapped at the sample before (so no new impact),
/// and no contact would hold the body; so it rests there, held where it is
/// (doc/model.md, "Detection").
template <class Motion>
double contactRestitution(World& world, double time, const InstantContact& contact,
                          double approach_speed) {
  const double restitution =
      approach_speed >= world.restitution_threshold ? world.restitutionOf(contact.pair) : 0.0;
  if constexpr (Motion::kAccelerates) {
    const auto [a, other] = contact.pair;
    const Eigen::Vector3d& normal = contact.geometry.normal;
    // What presses the pair together along the normal: gravity, or what the bodies' supports
    // leave of it, less the turning of the line of centres (|v_perp|^2 / d).
    double pressing =
        -normal.dot(accelerationOf<Motion>(world, other) - accelerationOf<Motion>(world, a));
    if (!contact.geometry.flat()) {
      const Eigen::Vector3d relative =
          touchingVelocity<Motion>(world, contact.pair, contact.geometry, time) -
          velocityAt<Motion>(world, a, time);
      const Eigen::Vector3d across = relative - relative.dot(normal) * normal;
      pressing -= contact.geometry.centripetal(across);
    }
    if (pressing > 0 && restitution * approach_speed <=
                            restSpeed(pressing, world.riseBand(contact.geometry, pressing))) {
      world.contact_since[contact.pair] =
          restitution < 1 ? time + 2 * restitution * approach_speed / (pressing * (1 - restitution))
                          : time;
      return 0.0;
    }
  }
  return restitution;
}

/// `joined`: 2 for a plastic contact of an earlier round that joins this one (e = 0).
template <class Motion>
PreparedCluster prepareCluster(World& world, double time,
                               const std::vector<InstantContact>& contacts,
                               const std::vector<std::size_t>& cluster,
                               const std::vector<char>& joined) {
  PreparedCluster prepared;
  std::vector<std::size_t>& members = prepared.members;
  std::vector<std::pair<std::size_t, Eigen::Vector3d>> finite_members;  // member, its velocity
  // Each participant's local index (a finite shape's per-contact members are not looked up): a
  // map, as a cluster of a lattice has thousands of members.
  std::unordered_map<std::size_t, std::size_t> local_of;
  const auto local = [&members, &local_of](std::size_t participant) {
    const auto [found, inserted] = local_of.emplace(participant, members.size());
    if (inserted) members.push_back(participant);
    return found->second;
  };
  for (const std::size_t k : cluster) {
    const InstantContact& instant_contact = contacts[k];
    const Pair& pair = instant_contact.pair;
    const Geometry& g = instant_contact.geometry;
    ClusterContact contact;
    contact.a = local(pair.first);
    if (g.bounded && world.isObstacle(pair.second)) {
      // A finite shape: one member of its own for each of its contacts, moving as its surface
      // does at the contact point (v + w x r), so that each contact sees the surface's own
      // velocity; an immovable body's contacts do not act on each other.
      members.push_back(pair.second);
      contact.b = members.size() - 1;
      finite_members.push_back({contact.b, g.surface_velocity});
    } else {
      contact.b = local(pair.second);
    }
    contact.normal = g.normal;
    contact.point = g.point;
    contact.lever_a = g.lever_a;
    contact.lever_b = g.lever_b;
    const double approach_speed = (velocityAt<Motion>(world, pair.first, time) -
                                   touchingVelocity<Motion>(world, pair, g, time))
                                      .dot(contact.normal);
    contact.restitution =
        joined[k] == 2 ? 0.0
                       : contactRestitution<Motion>(world, time, instant_contact, approach_speed);
    prepared.contacts.push_back(contact);
    if (world.friction_model) prepared.friction.push_back(world.frictionOf(pair));
  }
  for (const std::size_t participant : members) {
    ClusterBody body;
    body.inverse_mass = world.inverseMassOf(participant);
    body.velocity = velocityAt<Motion>(world, participant, time);
    body.angular_velocity = angularVelocityAt<Motion>(world, participant, time);
    body.spin_factor = world.isObstacle(participant) ? 0.0 : world.spin_factor[participant];
    body.radius = world.radius[participant];
    prepared.bodies.push_back(body);
  }
  // Its own angular velocity stays (as reported), acting on nothing: its radius is 0.
  for (const auto& [member, velocity] : finite_members) prepared.bodies[member].velocity = velocity;
  return prepared;
}

/// The cluster's contacts one after the other, in their canonical order, each that approaches
/// by the closed form of a single contact (solveContact: Newton's restitution, then its own
/// friction): the fallback of a joint solve past the step's impact work. Each such impact removes
/// energy (or none) and keeps momentum; what still approaches strikes again in the next round.
/// Not counted in World::impact_work: like a round's own bookkeeping, it costs O(the contacts).
ClusterOutcome solveContactByContact(const World& world, PreparedCluster& prepared) {
  ClusterOutcome outcome;
  outcome.normal.assign(prepared.contacts.size(), ContactOutcome{});
  outcome.friction.assign(prepared.contacts.size(), FrictionOutcome{});
  for (std::size_t c = 0; c < prepared.contacts.size(); ++c) {
    const ClusterContact& contact = prepared.contacts[c];
    ClusterBody& a = prepared.bodies[contact.a];
    ClusterBody& b = prepared.bodies[contact.b];
    if (!((b.velocity - a.velocity).dot(contact.normal) < 0)) continue;
    const ContactResolution resolution = solveContact(
        a, b, contact, world.friction_model ? prepared.friction[c] : 0.0, world.friction_model);
    outcome.normal[c] = resolution.normal;
    outcome.friction[c] = resolution.friction;
  }
  return outcome;
}

/// The cluster locked together (a perfectly plastic impact of the whole cluster), the fallback of
/// a joint solve past the step's impact work: every movable body takes one velocity, after which
/// no contact of the cluster approaches. Without an immovable participant, the cluster's centre
/// of mass velocity: momentum kept, and of all velocities that keep it, the least kinetic energy,
/// so none is gained. With immovable ones that all move alike (a fixed wall: at rest), theirs.
/// Angular velocities are kept (a sphere's turning does not move its surface along a normal).
/// Each contact's impulse and energy are those of its two bodies alone, J = -d / (w_a + w_b) and
/// J (-d) / 2 (d its normal relative velocity before, < 0 where it approaches): the lock's
/// forces between its contacts are indeterminate. False, nothing changed, where immovable
/// participants move differently (no velocity keeps every contact from approaching).
bool lockCluster(PreparedCluster& prepared, ClusterOutcome& outcome) {
  std::vector<ClusterBody>& bodies = prepared.bodies;
  const ClusterBody* immovable = nullptr;
  long double mass = 0;
  Eigen::Matrix<long double, 3, 1> momentum = Eigen::Matrix<long double, 3, 1>::Zero();
  for (const ClusterBody& body : bodies) {
    if (body.inverse_mass == 0.0) {
      if (immovable != nullptr && body.velocity != immovable->velocity) return false;
      immovable = &body;
    } else {
      mass += 1.0L / body.inverse_mass;
      momentum += body.velocity.cast<long double>() / static_cast<long double>(body.inverse_mass);
    }
  }
  const Eigen::Vector3d locked = immovable != nullptr
                                     ? immovable->velocity
                                     : Eigen::Vector3d((momentum / mass).cast<double>());
  outcome.normal.assign(prepared.contacts.size(), ContactOutcome{});
  outcome.friction.assign(prepared.contacts.size(), FrictionOutcome{});
  for (std::size_t c = 0; c < prepared.contacts.size(); ++c) {
    const ClusterContact& contact = prepared.contacts[c];
    const ClusterBody& a = bodies[contact.a];
    const ClusterBody& b = bodies[contact.b];
    const double approach = -(b.velocity - a.velocity).dot(contact.normal);
    ContactOutcome& normal = outcome.normal[c];
    normal.approach_speed = approach;
    if (approach > 0) {
      normal.impulse = approach / (a.inverse_mass + b.inverse_mass);
      normal.energy_lost = 0.5 * normal.impulse * approach;
    }
  }
  for (ClusterBody& body : bodies) {
    if (body.inverse_mass > 0.0) body.velocity = locked;
  }
  return true;
}

/// The cluster solved (solveCluster), its joint solves' work counted in World::impact_work
/// against MonitorSettings::max_impact_work_per_step, each stopped where it would pass what the
/// step has left. Where the normal solve is stopped, or the step's work is spent already,
/// `stopped` is set and the bodies are as they were (the caller locks the cluster with what
/// touches it: lockTouching); where the friction solve is stopped, its impulses are where it got
/// to (within mu J, no energy added) and the cluster's movable bodies are named in
/// report.over_impact_work. A single contact is its closed form, never bounded.
ClusterOutcome solveWithinBudget(World& world, PreparedCluster& prepared, StepReport& report,
                                 bool& stopped) {
  const std::size_t budget = world.settings.max_impact_work_per_step;
  const bool joint = prepared.contacts.size() > 1;
  WorkBound work;
  if (budget > 0) work.limit = budget - std::min(budget, world.impact_work);
  const bool spent = budget > 0 && joint && world.impact_work >= budget;
  ClusterOutcome outcome;
  if (!spent) {
    // Stopped (no normal impulses), solveCluster leaves the bodies as they were.
    outcome = solveCluster(prepared.bodies, prepared.contacts, prepared.friction,
                           world.friction_model, &work);
    world.impact_work += work.spent;
    // Cut, the step's impact work is spent: its later clusters are locked (monitor.h).
    if (work.cut) world.impact_work = std::max(world.impact_work, budget);
  }
  stopped = spent || outcome.normal.empty();
  if (stopped) return outcome;
  if (work.cut) {
    for (const std::size_t member : prepared.members) {
      if (!world.isObstacle(member) && world.inverseMassOf(member) > 0) {
        report.over_impact_work.push_back(member);
      }
    }
  }
  return outcome;
}

/// The cluster's movable bodies continue from `time` with their new velocities.
template <class Motion>
void storeVelocities(World& world, double time, const PreparedCluster& prepared,
                     std::vector<std::size_t>& changed) {
  for (std::size_t m = 0; m < prepared.members.size(); ++m) {
    const std::size_t participant = prepared.members[m];
    if (world.isObstacle(participant) || world.inverseMassOf(participant) == 0.0) continue;
    Track& track = world.tracks[participant];
    track.position = positionAt<Motion>(world, participant, time);  // before the velocity changes
    noteImpactChange(world, track, time,
                     prepared.bodies[m].velocity - velocityAt<Motion>(world, participant, time));
    track.time = time;
    track.velocity = prepared.bodies[m].velocity;
    track.angular_velocity = prepared.bodies[m].angular_velocity;
    track.last_impact_time = time;
    track.impact_step = world.steps;
    track.constrained = nullptr;
    startFlight(world, participant);
    changed.push_back(participant);
  }
}

/// A body's velocities at an impact, linear and angular.
struct BodyVelocities {
  Eigen::Vector3d linear;
  Eigen::Vector3d angular;
};

/// The record of an impact of `pair` (its geometry `g`) at `time`: who struck whom, along which
/// normal, where (a's surface plus half the gap), and the bodies' velocities before and after.
/// The restitution, the impulses and the energy lost are the caller's to fill in.
template <class Motion>
ImpactRecord impactRecord(const World& world, double time, const Pair& pair, const Geometry& g,
                          const BodyVelocities& a_before, const BodyVelocities& b_before,
                          const BodyVelocities& a_after, const BodyVelocities& b_after) {
  ImpactRecord record;
  record.time = time;
  record.body_a = pair.first;
  record.other_is_obstacle = world.isObstacle(pair.second);
  record.other = record.other_is_obstacle ? pair.second - world.bodyCount() : pair.second;
  record.normal = g.normal;
  record.contact_point = g.point;
  record.velocity_a_before = a_before.linear;
  record.velocity_b_before = b_before.linear;
  record.velocity_a_after = a_after.linear;
  record.velocity_b_after = b_after.linear;
  record.angular_velocity_a_before = a_before.angular;
  record.angular_velocity_b_before = b_before.angular;
  record.angular_velocity_a_after = a_after.angular;
  record.angular_velocity_b_after = b_after.angular;
  record.oblique = hasObliqueComponent(record.velocity_a_before, g.normal) ||
                   hasObliqueComponent(record.velocity_b_before, g.normal);
  return record;
}

BodyVelocities velocitiesOf(const ClusterBody& body) {
  return {body.velocity, body.angular_velocity};
}

template <class Motion>
void recordImpacts(const World& world, double time, const std::vector<InstantContact>& contacts,
                   const std::vector<std::size_t>& cluster, const PreparedCluster& prepared,
                   const std::vector<ClusterBody>& before, const ClusterOutcome& outcome,
                   const std::vector<char>& joined, StepReport& report) {
  for (std::size_t c = 0; c < cluster.size(); ++c) {
    // A plastic contact that joined the round and took no impulse had no impact.
    if (joined[cluster[c]] == 2 && !(outcome.normal[c].impulse > 0)) continue;
    const auto& [pair, g] = contacts[cluster[c]];
    const ClusterContact& contact = prepared.contacts[c];
    const std::vector<ClusterBody>& after = prepared.bodies;
    ImpactRecord record = impactRecord<Motion>(
        world, time, pair, g, velocitiesOf(before[contact.a]), velocitiesOf(before[contact.b]),
        velocitiesOf(after[contact.a]), velocitiesOf(after[contact.b]));
    record.restitution = contact.restitution;
    record.impulse = outcome.normal[c].impulse;
    record.friction_impulse = outcome.friction[c].impulse;
    record.energy_lost = outcome.normal[c].energy_lost + outcome.friction[c].energy_lost;
    report.impacts.push_back(record);
  }
}

/// The instant's contacts (indices into `contacts`) connected to those of `cluster` through
/// movable bodies, in order: the cluster and everything that touches it, transitively.
std::vector<std::size_t> touchingComponent(const World& world,
                                           const std::vector<InstantContact>& contacts,
                                           const std::vector<std::size_t>& cluster) {
  ConnectedSets bodies(world.bodyCount());  // joined by the contacts between movable bodies
  const auto movable = [&world](std::size_t participant) {
    return !world.isObstacle(participant) && world.inverseMassOf(participant) > 0;
  };
  const auto root_of = [&](const Pair& pair) {
    return movable(pair.first) ? bodies.root(pair.first) : bodies.root(pair.second);
  };
  for (const InstantContact& contact : contacts) {
    const auto [a, other] = contact.pair;
    if (movable(a) && movable(other)) bodies.link(a, other);
  }
  std::vector<char> reached(world.bodyCount(), 0);
  for (const std::size_t k : cluster) reached[root_of(contacts[k].pair)] = 1;
  std::vector<std::size_t> component;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const Pair& pair = contacts[k].pair;
    if ((movable(pair.first) || movable(pair.second)) && reached[root_of(pair)]) {
      component.push_back(k);
    }
  }
  return component;
}

/// The movable bodies among the contacts' participants, sorted.
std::vector<std::size_t> movableParticipants(const World& world,
                                             const std::vector<InstantContact>& contacts) {
  std::vector<std::size_t> movable;
  for (const InstantContact& contact : contacts) {
    for (const std::size_t participant : {contact.pair.first, contact.pair.second}) {
      if (!world.isObstacle(participant) && world.inverseMassOf(participant) > 0) {
        movable.push_back(participant);
      }
    }
  }
  std::sort(movable.begin(), movable.end());
  movable.erase(std::unique(movable.begin(), movable.end()), movable.end());
  return movable;
}

/// The linear and angular velocities of `bodies` at `time`, one after the other.
template <class Motion>
std::vector<double> velocitiesOf(const World& world, double time,
                                 const std::vector<std::size_t>& bodies) {
  std::vector<double> velocities;
  for (const std::size_t body : bodies) {
    const Eigen::Vector3d v = velocityAt<Motion>(world, body, time);
    const Eigen::Vector3d w = angularVelocityAt<Motion>(world, body, time);
    velocities.insert(velocities.end(), {v.x(), v.y(), v.z(), w.x(), w.y(), w.z()});
  }
  return velocities;
}

/// Whether the rounds of one instant still converge (doc/model.md, "Simultaneous contacts"). Rounds
/// that converge are left alone; these end them, and what remains is resolved as at the rounds'
/// budget's end (the inelastic fallback):
///  - a contact that strikes again slower than kRepeatStrikeResolution of its fastest approach
///    at this instant strikes plastically (strikes() is false): the rest of its series of ever
///    smaller bounces (a ball touching two walls: e^k of its speed, a round each) is below that
///    fraction of its speed;
///  - a round that ends where one of the last kRoundsRemembered did (velocities, plastic and
///    fastest approaches) repeats for ever (a joint solve that cannot stop a body 1e70 times
///    heavier than its neighbour: its impulse is below its velocity's last bit);
///  - a round in which every contact was plastic leaves none of them approaching, to rounding:
///    where only its own contacts strike again, the solve could not stop them (the velocities
///    drifting by an ulp a round, at 1e100), and kStaleRounds such rounds in a row end them;
///  - a body the solve cannot move (immovable, or moving with a velocity an impulse leaves
///    unchanged to the bit, a mass ratio past the doubles) keeps a contact it strikes again no
///    slower than before struck without end (a light ball squeezed between it and a fixed post;
///    a ball sliding in a wedge of the floor and a post whose normals are 1e-11 rad from
///    opposite), and so does a contact the joint solve gives no impulse although it strikes
///    (a heavy ball on a post beside a body 1e195 times lighter: its row is below the solve's
///    rounding): a contact struck so kUndecayedStrikes times in a row (none of them slower than
///    the one before) ends them. A series decaying slower than kUndecayedRate a strike would need
///    millions of rounds, past the budget anyway.
class RoundProgress {
 public:
  RoundProgress(std::size_t contacts, std::vector<std::size_t> movable)
      : movable_(std::move(movable)),
        fastest_(contacts, 0.0),
        last_approach_(contacts, 0.0),
        undecayed_(contacts, 0),
        driven_strikes_(contacts, 0) {}

  const std::vector<std::size_t>& movable() const { return movable_; }

  /// Before a round: true where the last round was all plastic and only its own contacts
  /// (`striking`, sorted) strike again, for the kStaleRounds-th time in a row.
  bool onlyStaleStrikesAgain(const std::vector<std::size_t>& striking) {
    const bool stale = previous_plastic_ && std::includes(previous_.begin(), previous_.end(),
                                                          striking.begin(), striking.end());
    stale_rounds_ = stale ? stale_rounds_ + 1 : 0;
    std::fill(undecayed_.begin(), undecayed_.end(), 0);  // strikes() marks this round's
    return stale_rounds_ >= kStaleRounds;
  }

  /// Contact k strikes at `approach` (m/s): false where it strikes plastically instead.
  bool strikes(std::size_t k, double approach) {
    const bool plastically = fastest_[k] > 0 && approach <= kRepeatStrikeResolution * fastest_[k];
    fastest_[k] = std::max(fastest_[k], approach);
    undecayed_[k] = last_approach_[k] > 0 && approach >= (1 - kUndecayedRate) * last_approach_[k];
    if (last_approach_[k] > 0 && !undecayed_[k]) driven_strikes_[k] = 0;  // it decays
    last_approach_[k] = approach;
    return !plastically;
  }

  /// The round's contacts, sorted (with the plastic ones that joined it).
  void beginRound(const std::vector<std::size_t>& contacts) {
    previous_ = contacts;
    previous_plastic_ = true;
  }

  /// One cluster of the round solved: `cluster` (indices of the instant's contacts) as the
  /// solver's `contacts`, its bodies `before` and `after`.
  void solved(const std::vector<std::size_t>& cluster, const std::vector<ClusterContact>& contacts,
              const std::vector<ClusterBody>& before, const std::vector<ClusterBody>& after,
              const ClusterOutcome& outcome) {
    for (std::size_t c = 0; c < cluster.size(); ++c) {
      if (contacts[c].restitution != 0.0) previous_plastic_ = false;
      const std::size_t k = cluster[c];
      if (!undecayed_[k]) continue;
      // Struck again no slower and given no impulse: the solve leaves it as it is (its row 1e195
      // times below its neighbours', past the doubles), as an unmoved body.
      bool driven = !(outcome.normal[c].impulse > 0);
      for (const std::size_t m : {contacts[c].a, contacts[c].b}) {
        driven = driven || after[m].inverse_mass == 0 ||
                 (!before[m].velocity.isZero(0.0) && after[m].velocity == before[m].velocity);
      }
      if (driven && ++driven_strikes_[k] >= kUndecayedStrikes) undriven_ = false;
    }
  }

  /// After a round, with the movable bodies' velocities (velocitiesOf movable()) and the
  /// contacts resolved plastically so far: true where the rounds would not converge.
  bool endsWithoutConverging(std::vector<double> state, const std::vector<char>& plastic) {
    if (!undriven_) return true;
    state.insert(state.end(), fastest_.begin(), fastest_.end());
    state.insert(state.end(), plastic.begin(), plastic.end());
    if (std::find(recent_.begin(), recent_.end(), state) != recent_.end()) return true;
    if (recent_.size() == kRoundsRemembered) recent_.erase(recent_.begin());
    recent_.push_back(std::move(state));
    return false;
  }

 private:
  static constexpr std::size_t kRoundsRemembered = 4;
  static constexpr int kStaleRounds = 8;
  static constexpr int kUndecayedStrikes = 64;
  static constexpr double kUndecayedRate = 1e-6;

  std::vector<std::size_t> movable_;
  std::vector<double> fastest_;        // per contact: its fastest approach so far (0: none)
  std::vector<double> last_approach_;  // per contact: at its previous strike
  std::vector<char> undecayed_;        // per contact: struck again no slower, this round
  std::vector<int> driven_strikes_;    // per contact: unmoved or unanswered such strikes in a row
  std::vector<std::vector<double>> recent_;
  std::vector<std::size_t> previous_;
  bool previous_plastic_ = false;
  bool undriven_ = true;  // no contact has reached kUndecayedStrikes
  int stale_rounds_ = 0;
};

/// A body of an inelastic impact: what its impulses act on, and its velocities just before.
using ImpactBody = SolverBody;

/// A pair of an inelastic impact (indices into its bodies), along its line of impact.
struct ImpactContact : ContactPoint {
  double friction = 0.0;  ///< Coulomb mu; 0 frictionless
};

/// The impulse on b at a contact (on a the opposite).
struct ContactImpulse {
  bool separating = true;                                ///< none: the pair separates anyway
  double normal = 0.0;                                   ///< N s, >= 0, along the normal
  Eigen::Vector3d tangential = Eigen::Vector3d::Zero();  ///< N s, friction
};

struct InelasticImpact {
  std::vector<ContactImpulse> impulses;  ///< per contact
  std::vector<BodyVelocities> after;     ///< per body
};

/// The inelastic impact of touching bodies: impulses J >= 0 after which no contact approaches,
/// J = 0 where one separates anyway, friction stopping the slip within mu J. It is the
/// complementarity problem of the contact forces of lasting contact one level down
/// (solveContactForces, its use with impulses): the bodies' velocities stand in its
/// accelerations, its forces are the impulses and its accelerations the velocities after.
InelasticImpact solveInelasticImpact(const std::vector<ImpactBody>& bodies,
                                     const std::vector<ImpactContact>& contacts) {
  std::vector<ForceBody> velocity_level;
  for (const ImpactBody& body : bodies) {
    ForceBody force_body{body};
    force_body.acceleration = body.velocity;
    force_body.angular_acceleration = body.angular_velocity;
    force_body.velocity = Eigen::Vector3d::Zero();
    force_body.angular_velocity = Eigen::Vector3d::Zero();
    velocity_level.push_back(force_body);
  }
  std::vector<ForceContact> force_contacts;
  for (const ImpactContact& contact : contacts) {
    ForceContact force_contact{contact};
    force_contact.friction = contact.friction;
    force_contacts.push_back(force_contact);
  }
  const ContactForceSolution solution = solveContactForces(velocity_level, force_contacts);
  InelasticImpact impact;
  for (const ContactForce& force : solution.contacts) {
    impact.impulses.push_back(
        ContactImpulse{force.mode == ContactMode::kSeparating, force.normal, force.tangential});
  }
  for (std::size_t i = 0; i < solution.acceleration.size(); ++i) {
    impact.after.push_back(
        BodyVelocities{solution.acceleration[i], solution.angular_acceleration[i]});
  }
  return impact;
}

/// The participants of `pairs`, sorted, each once.
std::vector<std::size_t> participantsOf(const std::vector<Pair>& pairs) {
  std::vector<std::size_t> participants;
  for (const Pair& pair : pairs) {
    participants.push_back(pair.first);
    participants.push_back(pair.second);
  }
  std::sort(participants.begin(), participants.end());
  participants.erase(std::unique(participants.begin(), participants.end()), participants.end());
  return participants;
}

/// The participants as bodies of the impact, with their velocities at `time`.
template <class Motion>
std::vector<ImpactBody> impactBodies(const World& world, double time,
                                     const std::vector<std::size_t>& participants) {
  std::vector<ImpactBody> bodies;
  for (const std::size_t p : participants) {
    ImpactBody body;
    body.inverse_mass = world.inverseMassOf(p);
    body.radius = world.radius[p];
    body.velocity = velocityAt<Motion>(world, p, time);
    body.angular_velocity = angularVelocityAt<Motion>(world, p, time);
    if (!world.isObstacle(p)) body.spin_factor = world.spin_factor[p];
    bodies.push_back(body);
  }
  return bodies;
}

/// The pairs of an inelastic impact that have a line of impact at `time`, with their geometry
/// and as contacts between the participants (sorted).
struct InelasticPairs {
  std::vector<Pair> pairs;
  std::vector<Geometry> geometries;
  std::vector<ImpactContact> contacts;
};

template <class Motion>
InelasticPairs inelasticPairs(const World& world, double time, const std::vector<Pair>& pairs,
                              const std::vector<std::size_t>& participants) {
  const auto slot = [&](std::size_t participant) {
    return static_cast<std::size_t>(
        std::lower_bound(participants.begin(), participants.end(), participant) -
        participants.begin());
  };
  InelasticPairs inelastic;
  for (const Pair& pair : pairs) {
    const Geometry g = geometry<Motion>(world, pair, time);
    if (!g.valid) continue;
    ImpactContact contact;
    contact.a = slot(pair.first);
    contact.b = slot(pair.second);
    contact.normal = g.normal;
    contact.point = g.point;
    contact.lever_a = g.lever_a;
    contact.lever_b = g.lever_b;
    if (world.friction_model) contact.friction = world.frictionOf(pair);
    inelastic.pairs.push_back(pair);
    inelastic.geometries.push_back(g);
    inelastic.contacts.push_back(contact);
  }
  return inelastic;
}

/// The velocity of b's contact point relative to a's (radii r_a, r_b along the normal n).
Eigen::Vector3d contactVelocity(double radius_a, double radius_b, const Eigen::Vector3d& normal,
                                const BodyVelocities& a, const BodyVelocities& b) {
  return Eigen::Vector3d(b.linear - a.linear -
                         (radius_a * a.angular + radius_b * b.angular).cross(normal));
}

/// The impacts of the pairs that took an impulse, with restitution 0.
template <class Motion>
void recordInelasticImpacts(const World& world, double time, const InelasticPairs& inelastic,
                            const std::vector<ImpactBody>& bodies, const InelasticImpact& impact,
                            StepReport& report) {
  for (std::size_t k = 0; k < inelastic.pairs.size(); ++k) {
    const ContactImpulse& impulse = impact.impulses[k];
    if (impulse.separating) continue;
    const Pair& pair = inelastic.pairs[k];
    const Geometry& g = inelastic.geometries[k];
    const ImpactContact& contact = inelastic.contacts[k];
    const BodyVelocities a_before = velocitiesOf(bodies[contact.a]);
    const BodyVelocities b_before = velocitiesOf(bodies[contact.b]);
    const BodyVelocities a_after{world.isObstacle(pair.first) || bodies[contact.a].inverse_mass == 0
                                     ? a_before.linear
                                     : impact.after[contact.a].linear,
                                 impact.after[contact.a].angular};
    const BodyVelocities b_after{
        bodies[contact.b].inverse_mass == 0 ? b_before.linear : impact.after[contact.b].linear,
        impact.after[contact.b].angular};
    ImpactRecord record =
        impactRecord<Motion>(world, time, pair, g, a_before, b_before, a_after, b_after);
    record.restitution = 0.0;
    record.impulse = impulse.normal;
    record.friction_impulse = impulse.tangential.norm();
    // The work of the impulse F on b (-F on a) over the change of the contact points' relative
    // velocity w: -F.(w_before + w_after) / 2.
    const double radius_a = world.radius[pair.first];
    const double radius_b = world.radius[pair.second];
    const Eigen::Vector3d force = impulse.normal * g.normal + impulse.tangential;
    record.energy_lost =
        -0.5 * force.dot(contactVelocity(radius_a, radius_b, g.normal, a_before, b_before) +
                         contactVelocity(radius_a, radius_b, g.normal, a_after, b_after));
    report.impacts.push_back(record);
  }
}

/// The movable participants continue from `time` with their velocities after the impact (the
/// angular one where they turn).
template <class Motion>
void storeInelasticVelocities(World& world, double time,
                              const std::vector<std::size_t>& participants,
                              const InelasticImpact& impact, std::vector<std::size_t>& changed) {
  for (std::size_t i = 0; i < participants.size(); ++i) {
    const std::size_t p = participants[i];
    if (world.isObstacle(p) || world.inverseMassOf(p) == 0.0) continue;
    Track& track = world.tracks[p];
    track.position = positionAt<Motion>(world, p, time);
    noteImpactChange(world, track, time,
                     impact.after[i].linear - velocityAt<Motion>(world, p, time));
    track.time = time;
    track.velocity = impact.after[i].linear;
    if (world.spin_factor[p] != 0.0) track.angular_velocity = impact.after[i].angular;
    track.last_impact_time = time;
    track.impact_step = world.steps;
    track.constrained = nullptr;
    startFlight(world, p);
    changed.push_back(p);
  }
}

/// Past the step's impact work (solveWithinBudget stopped), the cluster and every body that
/// touches it at the instant, transitively, are locked together (lockCluster; contact by contact
/// where immovable participants move differently: solveContactByContact): no contact among them
/// approaches after it, so the instant's rounds end there for them. Their impacts are recorded
/// (those that took an impulse), their bodies named in report.over_impact_work and marked in
/// `locked` (per body: the round's later clusters among them wait for the next round).
template <class Motion>
void lockTouching(World& world, double time, const std::vector<InstantContact>& contacts,
                  const std::vector<std::size_t>& cluster, StepReport& report,
                  std::vector<std::size_t>& changed, std::vector<char>& locked) {
  const std::vector<std::size_t> component = touchingComponent(world, contacts, cluster);
  std::vector<char> joined(contacts.size(), 2);  // recorded only where it takes an impulse
  PreparedCluster prepared = prepareCluster<Motion>(world, time, contacts, component, joined);
  const std::vector<ClusterBody> before = prepared.bodies;
  ClusterOutcome outcome;
  if (!lockCluster(prepared, outcome)) outcome = solveContactByContact(world, prepared);
  storeVelocities<Motion>(world, time, prepared, changed);
  recordImpacts<Motion>(world, time, contacts, component, prepared, before, outcome, joined,
                        report);
  for (const std::size_t member : prepared.members) {
    if (!world.isObstacle(member) && world.inverseMassOf(member) > 0) {
      report.over_impact_work.push_back(member);
      locked[member] = 1;
    }
  }
}

/// Whether a movable body of `cluster` was locked earlier in the round (lockTouching).
bool touchesLocked(const World& world, const std::vector<InstantContact>& contacts,
                   const std::vector<std::size_t>& cluster, const std::vector<char>& locked) {
  for (const std::size_t k : cluster) {
    for (const std::size_t participant : {contacts[k].pair.first, contacts[k].pair.second}) {
      if (!world.isObstacle(participant) && locked[participant]) return true;
    }
  }
  return false;
}

}  // namespace

template <class Motion>
void resolveInstant(World& world, double time, const std::vector<Pair>& touching,
                    StepReport& report, std::vector<std::size_t>& changed) {
  std::vector<InstantContact> contacts;
  for (const Pair& pair : touching) {
    const Geometry g = geometry<Motion>(world, pair, time);
    if (g.valid) contacts.push_back(InstantContact{pair, g});
  }
  // Contacts resolved plastically (e = 0) in an earlier round of this instant: they join every
  // later round that strikes while they do not separate, so the rounds' plastic limit is reached
  // at once instead of by ever smaller rounds.
  std::vector<char> plastic(contacts.size(), 0);
  RoundProgress progress(contacts.size(), movableParticipants(world, contacts));
  for (int round = 0; round < world.settings.max_rounds_per_instant; ++round) {
    std::vector<std::size_t> striking = findStriking<Motion>(world, time, contacts);
    if (striking.empty()) return;
    if (progress.onlyStaleStrikesAgain(striking)) break;
    std::vector<char> joined(contacts.size(), 0);
    for (const std::size_t k : striking) {
      const Pair& pair = contacts[k].pair;
      const double approach = (velocityAt<Motion>(world, pair.first, time) -
                               touchingVelocity<Motion>(world, pair, contacts[k].geometry, time))
                                  .dot(contacts[k].geometry.normal);
      joined[k] = progress.strikes(k, approach) ? 1 : 2;
    }
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      if (plastic[k] && !joined[k] &&
          !separating<Motion>(world, contacts[k].pair, contacts[k].geometry, time)) {
        striking.push_back(k);
        joined[k] = 2;
      }
    }
    std::sort(striking.begin(), striking.end());
    progress.beginRound(striking);
    // Bodies locked in this round (past the step's impact work): a later cluster among them is
    // part of a component already locked; what of it still approaches strikes in the next
    // round. Without this every such cluster locked its whole component again: a lattice of
    // 1,728 balls cut in its first round spent 0.1 s locking its 4,752 contacts 197 times.
    std::vector<char> locked;
    for (const std::vector<std::size_t>& cluster : formClusters(world, contacts, striking)) {
      if (!locked.empty() && touchesLocked(world, contacts, cluster, locked)) continue;
      PreparedCluster prepared = prepareCluster<Motion>(world, time, contacts, cluster, joined);
      const std::vector<ClusterBody> before = prepared.bodies;
      bool stopped = false;
      const ClusterOutcome outcome = solveWithinBudget(world, prepared, report, stopped);
      if (stopped) {
        if (locked.empty()) locked.assign(world.bodyCount(), 0);
        lockTouching<Motion>(world, time, contacts, cluster, report, changed, locked);
        continue;
      }
      progress.solved(cluster, prepared.contacts, before, prepared.bodies, outcome);
      storeVelocities<Motion>(world, time, prepared, changed);
      recordImpacts<Motion>(world, time, contacts, cluster, prepared, before, outcome, joined,
                            report);
      for (std::size_t c = 0; c < cluster.size(); ++c) {
        if (prepared.contacts[c].restitution == 0.0) plastic[cluster[c]] = 1;
      }
    }
    if (progress.endsWithoutConverging(velocitiesOf<Motion>(world, time, progress.movable()),
                                       plastic)) {
      break;
    }
  }
  if (findStriking<Motion>(world, time, contacts).empty()) return;
  report.truncated = true;
  ++report.fallbacks;
  std::vector<Pair> pairs;
  for (const InstantContact& contact : contacts) pairs.push_back(contact.pair);
  resolveInelastically<Motion>(world, time, pairs, report, changed);
}

template <class Motion>
void resolveInelastically(World& world, double time, const std::vector<Pair>& pairs,
                          StepReport& report, std::vector<std::size_t>& changed) {
  const std::vector<std::size_t> participants = participantsOf(pairs);
  const std::vector<ImpactBody> bodies = impactBodies<Motion>(world, time, participants);
  const InelasticPairs inelastic = inelasticPairs<Motion>(world, time, pairs, participants);
  const InelasticImpact impact = solveInelasticImpact(bodies, inelastic.contacts);
  recordInelasticImpacts<Motion>(world, time, inelastic, bodies, impact, report);
  storeInelasticVelocities<Motion>(world, time, participants, impact, changed);
}

template void resolveInstant<StraightLine>(World&, double, const std::vector<Pair>&, StepReport&,
                                           std::vector<std::size_t>&);
template void resolveInstant<UnderGravity>(World&, double, const std::vector<Pair>&, StepReport&,
                                           std::vector<std::size_t>&);
template void resolveInelastically<StraightLine>(World&, double, const std::vector<Pair>&,
                                                 StepReport&, std::vector<std::size_t>&);
template void resolveInelastically<UnderGravity>(World&, double, const std::vector<Pair>&,
                                                 StepReport&, std::vector<std::size_t>&);

}  // namespace collision_response::core::monitor
