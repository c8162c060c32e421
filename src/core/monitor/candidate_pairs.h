// Which pairs a step looks at: the broadphase's pairs of bodies whose swept boxes overlap, and
// the obstacles each body may reach.
#pragma once

#include <cstddef>
#include <vector>

#include "geometry/broadphase.h"
#include "monitor/monitor_world.h"

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

/// The obstacles a box may reach, through a grid of their bounds (SpatialHash), so that a body
/// asks only the near ones of a robot's thousands of links: a filter only, each caller still
/// tests what it finds exactly, so the pairs are those of a test against every obstacle. An
/// obstacle without a finite bound (a plane) is found by every query.
class ObstacleIndex {
 public:
  ObstacleIndex() = default;
  ObstacleIndex(const ObstacleIndex&) = delete;  // the grid points into bounds_
  ObstacleIndex& operator=(const ObstacleIndex&) = delete;

  /// Enters each obstacle `o` with `entered[o]`: its bound `bounds[o]`, or, where that is not
  /// finite, as one every query finds.
  void build(std::vector<Box> bounds, const std::vector<char>& entered);

  /// The entered obstacles whose bound overlaps `box` (all of them for a box that is not
  /// finite), and those found by every query: sorted, each once.
  void query(const Box& box, std::vector<std::size_t>& found) const;

 private:
  std::vector<Box> bounds_;
  std::vector<char> gridded_;
  std::vector<std::size_t> entered_;  ///< every entered obstacle, sorted
  std::vector<std::size_t> always_;   ///< those without a finite bound, sorted
  SpatialHash grid_;
  bool any_gridded_ = false;
};

/// A bound on where a body's box swept over [from, to] may reach `obstacle` (mayReachObstacle
/// is false for a box that does not overlap it), grown by a relative 1e-9 against rounding;
/// not finite where there is none (a plane).
Box obstacleReachBound(const World& world, std::size_t obstacle, double from, double to);

}  // namespace collision_response::core::monitor
