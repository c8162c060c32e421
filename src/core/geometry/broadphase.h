// The broadphase: which pairs of bodies could meet during a step, in about linear time.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

namespace collision_response::core {

/// An axis-aligned box.
struct Box {
  Eigen::Vector3d low = Eigen::Vector3d::Zero();
  Eigen::Vector3d high = Eigen::Vector3d::Zero();
  /// The cube of half-width `half` about `centre`: a sphere's box (its radius), a shape's
  /// bounding sphere's (its reach), a ball's grown by how far it may move.
  static Box about(const Eigen::Vector3d& centre, double half) {
    return Box{centre.array() - half, centre.array() + half};
  }
  bool overlaps(const Box& other) const {
    return (low.array() <= other.high.array()).all() && (other.low.array() <= high.array()).all();
  }
};

/// A uniform grid, hashed by cell: each box is entered in every cell it covers; boxes that
/// share a cell and overlap are candidate pairs.
///
/// Why a grid: the bodies of a scene (balls, parts, robots' links) are of similar sizes and
/// their boxes here are swept over one step, so with cells about the size of a typical box
/// each box covers a few cells and each cell holds a few boxes: building and querying cost
/// about O(n), whatever the scene's extent and however the bodies line up. A sweep-and-prune
/// sorts every step and degrades to O(n^2) when the bodies line up along its axis (a row of
/// balls, a rack seen along its axis); a dynamic tree pays to rebalance when every box moves
/// every step, which is the normal case here. The cell size is the median box extent; a box
/// covering more than kMaxCells cells (one huge body) is kept aside and tested against all.
class SpatialHash {
 public:
  static constexpr std::size_t kMaxCells = 64;

  /// Enters `boxes` (indexed by body; `active[i]` false: left out).
  void build(const std::vector<Box>& boxes, const std::vector<char>& active);

  /// Every pair (i < j) of active boxes that overlap, sorted, each once.
  void overlappingPairs(std::vector<std::pair<std::size_t, std::size_t>>& pairs);

  /// The active boxes that overlap `box`, sorted, each once.
  void query(const Box& box, std::vector<std::size_t>& found) const;

 private:
  struct Cell {
    std::int64_t x, y, z;
  };
  Cell cellOf(const Eigen::Vector3d& point) const;
  static std::uint64_t key(std::int64_t x, std::int64_t y, std::int64_t z);
  /// Calls visit(key) for every cell `box` covers; false when it covers more than kMaxCells.
  template <typename Visit>
  bool forEachCell(const Box& box, Visit visit) const;

  /// The bucket of a cell key (Fibonacci hashing into 2^bucket_bits_ buckets).
  std::size_t bucketOf(std::uint64_t key) const {
    return bucket_bits_ == 0
               ? 0
               : static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> (64 - bucket_bits_));
  }

  const std::vector<Box>* boxes_ = nullptr;
  const std::vector<char>* active_ = nullptr;
  double cell_size_ = 1.0;
  // The (cell key, box) entries grouped by bucket with a counting sort: building is O(entries),
  // where sorting them was the step's largest cost at 10,000 bodies. Keys that share a bucket
  // are told apart by comparing the keys.
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed_;    // as entered
  std::vector<std::pair<std::uint64_t, std::size_t>> entries_;  // grouped by bucket
  std::vector<std::size_t> bucket_start_;                       // entries_ of bucket b: [b], [b+1])
  unsigned bucket_bits_ = 0;
  std::vector<std::size_t> large_;                              // boxes kept aside
  std::vector<std::size_t> first_count_;                        // overlappingPairs' counting sort
  std::vector<std::pair<std::size_t, std::size_t>> unordered_;  // its input
};

}  // namespace collision_response::core
