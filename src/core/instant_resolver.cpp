#include "instant_resolver.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <utility>

#include "collision_response/core/cluster_solver.h"
#include "collision_response/core/impact.h"
#include "motion_model.h"

namespace collision_response::core::monitor {
namespace {

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

/// The contacts (indices into `contacts`) whose pair approaches at `time`.
template <class Motion>
std::vector<std::size_t> findStriking(const World& world, double time,
                                      const std::vector<InstantContact>& contacts) {
  std::vector<std::size_t> striking;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    if (approaching<Motion>(world, contacts[k].pair, contacts[k].geometry.normal, time)) {
      striking.push_back(k);
    }
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
  std::vector<std::size_t> parent(involved.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&parent](std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const std::size_t k : striking) {
    const auto [a, other] = contacts[k].pair;
    if (world.inverseMassOf(a) > 0 && world.inverseMassOf(other) > 0) {
      parent[find(slot_of(a))] = find(slot_of(other));
    }
  }
  const auto cluster_of = [&](std::size_t k) {
    const auto [a, other] = contacts[k].pair;
    return world.inverseMassOf(a) > 0 ? find(slot_of(a)) : find(slot_of(other));
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
/// slower than the restitution threshold (then it rests: 0), or (gravity) a bounce off a plane
/// too slow to leave the touching band (then it rests instead: restSpeed).
template <class Motion>
double contactRestitution(const World& world, const InstantContact& contact,
                          double approach_speed) {
  const double restitution =
      approach_speed >= world.restitution_threshold ? world.restitutionOf(contact.pair) : 0.0;
  if constexpr (Motion::kAccelerates) {
    const double pressing = contact.geometry.normal.dot(world.gravity);  // normal into the plane
    if (world.isPlane(contact.pair.second) && pressing > 0 &&
        restitution * approach_speed <= restSpeed(pressing, contact.geometry.tolerance)) {
      return 0.0;
    }
  }
  return restitution;
}

template <class Motion>
PreparedCluster prepareCluster(const World& world, double time,
                               const std::vector<InstantContact>& contacts,
                               const std::vector<std::size_t>& cluster) {
  PreparedCluster prepared;
  std::vector<std::size_t>& members = prepared.members;
  const auto local = [&members](std::size_t participant) {
    const auto found = std::find(members.begin(), members.end(), participant);
    if (found != members.end()) return static_cast<std::size_t>(found - members.begin());
    members.push_back(participant);
    return members.size() - 1;
  };
  for (const std::size_t k : cluster) {
    const InstantContact& instant_contact = contacts[k];
    const Pair& pair = instant_contact.pair;
    ClusterContact contact;
    contact.a = local(pair.first);
    contact.b = local(pair.second);
    contact.normal = instant_contact.geometry.normal;
    const double approach_speed =
        (velocityAt<Motion>(world, pair.first, time) - velocityAt<Motion>(world, pair.second, time))
            .dot(contact.normal);
    contact.restitution = contactRestitution<Motion>(world, instant_contact, approach_speed);
    prepared.contacts.push_back(contact);
    if (world.friction_model) prepared.friction.push_back(world.frictionOf(pair));
  }
  for (const std::size_t participant : members) {
    ClusterBody body;
    body.inverse_mass = world.inverseMassOf(participant);
    body.velocity = velocityAt<Motion>(world, participant, time);
    body.angular_velocity = world.angularVelocityOf(participant);
    body.spin_factor = world.isObstacle(participant) ? 0.0 : world.spin_factor[participant];
    body.radius = world.radius[participant];
    prepared.bodies.push_back(body);
  }
  return prepared;
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
    track.time = time;
    track.velocity = prepared.bodies[m].velocity;
    track.angular_velocity = prepared.bodies[m].angular_velocity;
    track.last_impact_time = time;
    if constexpr (Motion::kAccelerates) world.updateResting(participant);
    changed.push_back(participant);
  }
}

template <class Motion>
void recordImpacts(const World& world, double time, const std::vector<InstantContact>& contacts,
                   const std::vector<std::size_t>& cluster, const PreparedCluster& prepared,
                   const std::vector<ClusterBody>& before, const ClusterOutcome& outcome,
                   StepReport& report) {
  for (std::size_t c = 0; c < cluster.size(); ++c) {
    const auto& [pair, g] = contacts[cluster[c]];
    const ClusterContact& contact = prepared.contacts[c];
    const std::vector<ClusterBody>& after = prepared.bodies;
    ImpactRecord record;
    record.time = time;
    record.body_a = pair.first;
    record.other_is_obstacle = world.isObstacle(pair.second);
    record.other = record.other_is_obstacle ? pair.second - world.bodyCount() : pair.second;
    record.normal = g.normal;
    record.contact_point = positionAt<Motion>(world, pair.first, time) +
                           (world.radius[pair.first] + 0.5 * g.gap) * g.normal;
    record.restitution = contact.restitution;
    record.impulse = outcome.normal[c].impulse;
    record.friction_impulse = outcome.friction[c].impulse;
    record.energy_lost = outcome.normal[c].energy_lost + outcome.friction[c].energy_lost;
    record.velocity_a_before = before[contact.a].velocity;
    record.velocity_b_before = before[contact.b].velocity;
    record.velocity_a_after = after[contact.a].velocity;
    record.velocity_b_after = after[contact.b].velocity;
    record.angular_velocity_a_before = before[contact.a].angular_velocity;
    record.angular_velocity_b_before = before[contact.b].angular_velocity;
    record.angular_velocity_a_after = after[contact.a].angular_velocity;
    record.angular_velocity_b_after = after[contact.b].angular_velocity;
    record.oblique = hasObliqueComponent(record.velocity_a_before, g.normal) ||
                     hasObliqueComponent(record.velocity_b_before, g.normal);
    report.impacts.push_back(record);
  }
}

}  // namespace

template <class Motion>
bool resolveInstant(World& world, double time, const std::vector<Pair>& touching,
                    StepReport& report, std::vector<std::size_t>& changed) {
  std::vector<InstantContact> contacts;
  for (const Pair& pair : touching) {
    const Geometry g = geometry<Motion>(world, pair, time);
    if (g.valid) contacts.push_back(InstantContact{pair, g});
  }
  for (int round = 0; round < world.settings.max_rounds_per_instant; ++round) {
    const std::vector<std::size_t> striking = findStriking<Motion>(world, time, contacts);
    if (striking.empty()) return true;
    for (const std::vector<std::size_t>& cluster : formClusters(world, contacts, striking)) {
      PreparedCluster prepared = prepareCluster<Motion>(world, time, contacts, cluster);
      const std::vector<ClusterBody> before = prepared.bodies;
      const ClusterOutcome outcome =
          solveCluster(prepared.bodies, prepared.contacts, prepared.friction, world.friction_model);
      storeVelocities<Motion>(world, time, prepared, changed);
      recordImpacts<Motion>(world, time, contacts, cluster, prepared, before, outcome, report);
    }
  }
  return false;
}

template bool resolveInstant<StraightLine>(World&, double, const std::vector<Pair>&, StepReport&,
                                           std::vector<std::size_t>&);
template bool resolveInstant<UnderGravity>(World&, double, const std::vector<Pair>&, StepReport&,
                                           std::vector<std::size_t>&);

}  // namespace collision_response::core::monitor
