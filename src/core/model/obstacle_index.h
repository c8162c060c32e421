// The obstacle index: which obstacles a body's box may reach, through a grid of their bounds,
// so that a body asks only the near ones of a robot's thousands of links.
#pragma once

#include <cstddef>
#include <vector>

#include "geometry/broadphase.h"

namespace collision_response::core::monitor {

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
  /// finite, as one every query finds. `from`, `to`: the span the bounds hold for (covers).
  void build(std::vector<Box> bounds, const std::vector<char>& entered, double from = 0.0,
             double to = 0.0);

  /// Built, for a span that holds [from, to] (a bound that holds for a span holds for any span
  /// within it: obstacleReachBound).
  bool covers(std::size_t obstacles, double from, double to) const {
    return built_ && bounds_.size() == obstacles && from_ <= from && to <= to_;
  }

  /// Forgets what was entered: an obstacle placed anew, or a time line started again, may break
  /// the bounds it holds even for a span it covers.
  void invalidate() { built_ = false; }

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
  bool built_ = false;
  double from_ = 0.0, to_ = 0.0;
};

}  // namespace collision_response::core::monitor
