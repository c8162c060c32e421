// The participants of one solve of the contact room (a group of lasting contact, a component of
// a stepped cluster): the bodies it moves, then the fixed participants of its contacts, each at
// its slot, its index among the solver's bodies.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "model/monitor_world.h"

namespace collision_response::core::monitor {

/// A solve's participants in the solver's order: its movable bodies (sorted: slots 0..n-1), then
/// the fixed participants of its contacts (obstacles, immovable bodies), sorted.
struct SolveParticipants {
  std::vector<std::size_t> movable;  ///< sorted
  std::vector<std::size_t> fixed;    ///< sorted
  std::vector<std::size_t> all;      ///< movable, then fixed: participant of each slot

  /// The slot of `participant`, one of `all`.
  std::size_t slot(std::size_t participant) const {
    const auto found = std::lower_bound(movable.begin(), movable.end(), participant);
    if (found != movable.end() && *found == participant) {
      return static_cast<std::size_t>(found - movable.begin());
    }
    return movable.size() +
           static_cast<std::size_t>(std::lower_bound(fixed.begin(), fixed.end(), participant) -
                                    fixed.begin());
  }
};

/// The participants of a solve of `movable` (sorted) over the contacts of `pairs`.
inline SolveParticipants solveParticipants(const World& world,
                                           const std::vector<std::size_t>& movable,
                                           const std::vector<Pair>& pairs) {
  SolveParticipants participants;
  participants.movable = movable;
  for (const Pair& pair : pairs) {
    for (const std::size_t p : {pair.first, pair.second}) {
      if (world.inverseMassOf(p) == 0.0) participants.fixed.push_back(p);
    }
  }
  std::vector<std::size_t>& fixed = participants.fixed;
  std::sort(fixed.begin(), fixed.end());
  fixed.erase(std::unique(fixed.begin(), fixed.end()), fixed.end());
  participants.all = movable;
  participants.all.insert(participants.all.end(), fixed.begin(), fixed.end());
  return participants;
}

}  // namespace collision_response::core::monitor
