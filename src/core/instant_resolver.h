// What happens at one instant of impact: the touching contacts that approach are resolved, in
// rounds, cluster by cluster, until none approaches.
#pragma once

#include <cstddef>
#include <vector>

#include "collision_response/core/monitor.h"
#include "monitor_world.h"

namespace collision_response::core::monitor {

/// Resolves, in rounds, the pairs of `touching` that approach at `time` (the model of "Simultaneous
/// contacts" in the README): each round finds the striking contacts, groups them into clusters
/// (contacts that share a movable body), prepares each cluster (bodies, contacts, and the
/// restitution each contact uses: contactRestitution), solves it (solveCluster: the joint normal
/// solve, then friction), stores the new velocities in the tracks and records the impacts. The
/// bodies whose motion changed are appended to `changed`. False when the rounds ran out
/// (settings.max_rounds_per_instant).
template <class Motion>
bool resolveInstant(World& world, double time, const std::vector<Pair>& touching,
                    StepReport& report, std::vector<std::size_t>& changed);

}  // namespace collision_response::core::monitor
