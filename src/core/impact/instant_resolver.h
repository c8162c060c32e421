// What happens at one instant of impact: the touching contacts that approach are resolved, in
// rounds, cluster by cluster, until none approaches.
#pragma once

#include <cstddef>
#include <vector>

#include "collision_response/core/monitor.h"
#include "model/monitor_world.h"

namespace collision_response::core::monitor {

/// Resolves, in rounds, the pairs of `touching` that approach at `time` (the model of "Simultaneous
/// contacts" in doc/model.md): each round finds the striking contacts, groups them into clusters
/// (contacts that share a movable body), prepares each cluster (bodies, contacts, and the
/// restitution each contact uses: contactRestitution), solves it (solveCluster: the joint normal
/// solve, then friction), stores the new velocities in the tracks and records the impacts. The
/// bodies whose motion changed are appended to `changed`. When the rounds run out
/// (settings.max_rounds_per_instant: a ball squeezed between two walls), what remains is resolved
/// as one inelastic cluster (resolveInelastically), so no contact approaches after the instant;
/// that is counted in report.fallbacks.
template <class Motion>
void resolveInstant(World& world, double time, const std::vector<Pair>& touching,
                    StepReport& report, std::vector<std::size_t>& changed);

/// The pairs resolved at `time` as one inelastic cluster (e = 0, and friction with the effect):
/// impulses J >= 0 after which no pair approaches, J = 0 where a pair separates anyway (the
/// complementarity problem of solveContactForces at the level of velocities). Pairs need not
/// touch: their line of impact is the line of centres (a plane's normal). Records the impacts
/// with restitution 0; appends the bodies changed.
template <class Motion>
void resolveInelastically(World& world, double time, const std::vector<Pair>& pairs,
                          StepReport& report, std::vector<std::size_t>& changed);

}  // namespace collision_response::core::monitor
