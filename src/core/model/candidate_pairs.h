// Which pairs a step looks at: the broadphase's pairs of bodies whose swept boxes overlap, and
// the obstacles each body may reach.
#pragma once

#include <cstddef>
#include <vector>

#include "geometry/broadphase.h"
#include "model/monitor_world.h"

namespace collision_response::core::monitor {

/// Every pair worth testing: both tracked, not both immovable (no broadphase; for tests that
/// compare the two).
void allCandidatePairs(const World& world, std::vector<Pair>& pairs);

/// The candidate pairs over [from, to]: those whose boxes swept over [from, to] overlap (the
/// broadphase), in the canonical order: a body's pairs with bodies (sorted), then with
/// obstacles (whose indices follow every body's); or all of them (settings.broadphase false).
template <class Motion>
void candidatePairs(World& world, double from, double to, std::vector<Pair>& pairs);

/// After `body` changed at `from`: pairs its new motion over [from, to] may form that are not
/// candidates yet, appended to `pairs`; their indices. `pairs_of[body]`: its pairs so far.
template <class Motion>
std::vector<std::size_t> addReachablePairs(World& world, std::size_t body, double from, double to,
                                           std::vector<Pair>& pairs,
                                           const std::vector<std::vector<std::size_t>>& pairs_of);

/// Whether a body's box swept over [from, to] may reach an obstacle: a fixed one where it is, a
/// tf-attached one moving on from its placement (mayReachMoving).
bool mayReachObstacle(const World& world, const Box& box, std::size_t obstacle, double from,
                      double to);

/// A bound on where a body's box swept over [from, to] may reach `obstacle` (mayReachObstacle
/// is false for a box that does not overlap it), grown by a relative 1e-9 against rounding;
/// not finite where there is none (a plane).
Box obstacleReachBound(const World& world, std::size_t obstacle, double from, double to);

}  // namespace collision_response::core::monitor
