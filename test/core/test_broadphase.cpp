// The broadphase's grid with boxes no scene would have but a publisher can send: far, fast and
// not finite. Each is bounded work with the same answer as testing every pair.
#include <gtest/gtest.h>

#include <limits>
#include <utility>
#include <vector>

#include "geometry/broadphase.h"

namespace collision_response::core {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

Box around(const Eigen::Vector3d& centre, double half) {
  return Box{centre.array() - half, centre.array() + half};
}

/// Every overlapping pair, by testing them all.
std::vector<std::pair<std::size_t, std::size_t>> allPairs(const std::vector<Box>& boxes) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    for (std::size_t j = i + 1; j < boxes.size(); ++j) {
      if (boxes[i].overlaps(boxes[j])) pairs.emplace_back(i, j);
    }
  }
  return pairs;
}

// Issue 13, item 3: a state far away and fast swept a box whose cell count overflowed int64
// and wrapped past the guard: the grid walked and stored cells until memory ran out. Here the
// wrap is exact: with cells of 0.25 m (the median box), a box of 274177 x 67280421310721 x 1
// cells covers 274177 * 67280421310721 = 2^64 + 1 cells, which int64 wraps to 1. Counted axis by
// axis, the box is kept aside and tested against every other.
TEST(Broadphase, ABoxWhoseCellCountWrapsInt64IsKeptAside) {
  std::vector<Box> boxes = {
      around({0, 0, 0}, 0.125), around({0.2, 0, 0}, 0.125), around({3, 0, 0}, 0.125),
      Box{Eigen::Vector3d(0.125, 0.125, 0.125),
          Eigen::Vector3d(0.125 + 274176 * 0.25, 0.125 + 67280421310720.0 * 0.25, 0.2)}};
  const std::vector<char> active(boxes.size(), 1);
  SpatialHash hash;
  hash.build(boxes, active);  // before the fix: 2^64 cells entered, until memory ran out
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  hash.overlappingPairs(pairs);
  EXPECT_EQ(pairs, allPairs(boxes));
  std::vector<std::size_t> found;
  hash.query(boxes[3], found);
  EXPECT_EQ(found, (std::vector<std::size_t>{0, 1, 2, 3}));
}

// The issue's own numbers: p = (5, -1.76e13, 5) moving at v = (1.05e8, 7.04e13, 0), the next
// input 0.5 s later.
TEST(Broadphase, TheAttacksFarFastBoxIsBoundedWork) {
  const Eigen::Vector3d start(5, -1.76e13, 5);
  const Eigen::Vector3d end = start + 0.5 * Eigen::Vector3d(1.05e8, 7.04e13, 0);
  std::vector<Box> boxes = {
      around({0, 0, 0}, 0.1), around({0.15, 0, 0}, 0.1), around({3, 0, 0}, 0.1),
      Box{start.cwiseMin(end).array() - 0.1, start.cwiseMax(end).array() + 0.1}};
  const std::vector<char> active(boxes.size(), 1);
  SpatialHash hash;
  hash.build(boxes, active);
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  hash.overlappingPairs(pairs);
  EXPECT_EQ(pairs, allPairs(boxes));
}

// Boxes with infinite or NaN corners (a track that became non-finite) are not cells at all:
// kept aside, never converted to integers (undefined behaviour), and the pairs stay right.
TEST(Broadphase, NonFiniteBoxesAreKeptAside) {
  std::vector<Box> boxes = {around({0, 0, 0}, 0.1), around({0.15, 0, 0}, 0.1),
                            Box{Eigen::Vector3d(-kInf, 0, 0), Eigen::Vector3d(kInf, 0, 0)},
                            Box{Eigen::Vector3d(kNan, 0, 0), Eigen::Vector3d(kNan, 1, 1)},
                            around({5, 5, 5}, 0.1)};
  const std::vector<char> active(boxes.size(), 1);
  SpatialHash hash;
  hash.build(boxes, active);
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  hash.overlappingPairs(pairs);
  EXPECT_EQ(pairs, allPairs(boxes));
  std::vector<std::size_t> found;
  hash.query(boxes[3], found);
  EXPECT_TRUE(found.empty());  // NaN overlaps nothing
}

// A cell count that fits each axis but not the product: 64 x 64 x 64 cells.
TEST(Broadphase, ABoxOfManyCellsOnEveryAxisIsKeptAside) {
  std::vector<Box> boxes = {around({0, 0, 0}, 0.5), around({0.9, 0, 0}, 0.5),
                            around({10, 10, 10}, 0.5), around({0, 0, 0}, 31.9)};
  const std::vector<char> active(boxes.size(), 1);
  SpatialHash hash;
  hash.build(boxes, active);
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  hash.overlappingPairs(pairs);
  EXPECT_EQ(pairs, allPairs(boxes));
}

}  // namespace
}  // namespace collision_response::core
