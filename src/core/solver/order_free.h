// What the joint solves of a cluster share so that their answers depend on no order of the bodies
// or contacts: sums whose value does not depend on the order of their terms, the blocks of
// contacts connected through shared movable bodies, and the size above which a block is solved
// iteratively (doc/model.md, "Work per message, and threads").
#pragma once

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <utility>
#include <vector>

namespace collision_response::core {

/// Blocks of more contacts than this are solved iteratively, not by a dense decomposition (whose
/// cost grows with the cube of the contacts): the normal impulses by conjugate gradients, the
/// friction impulses by an accelerated projected gradient.
constexpr std::size_t kDenseBlockContacts = 128;

/// A sum whose value depends neither on the order of its terms nor on their signs' assignment
/// to a mirror image: the positive terms are added smallest first, the negative ones smallest in
/// magnitude first, and the two sums then added. Renaming bodies reorders the terms (the same
/// bits), a mirror image negates some of them (the negated bits: -a - b = -(a + b) exactly), and
/// +x and -x cancel to 0. `terms` is reordered.
template <class Real>
Real orderFreeSum(std::vector<Real>& terms) {
  const auto negative = std::partition(terms.begin(), terms.end(), [](Real t) { return t > 0; });
  std::sort(terms.begin(), negative);
  std::sort(negative, terms.end(), [](Real x, Real y) { return x > y; });
  Real positive_sum = 0, negative_sum = 0;
  for (auto t = terms.begin(); t != negative; ++t) positive_sum += *t;
  for (auto t = negative; t != terms.end(); ++t) negative_sum += *t;
  return positive_sum + negative_sum;
}

/// Disjoint sets of 0 .. count - 1, joined by links: each set's root is its smallest member,
/// whatever order the links come in, so the sets and their numbering depend on no order.
class ConnectedSets {
 public:
  explicit ConnectedSets(std::size_t count) : parent_(count) {
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }
  std::size_t root(std::size_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void link(std::size_t x, std::size_t y) {
    const std::size_t p = root(x), q = root(y);
    parent_[std::max(p, q)] = std::min(p, q);
  }
  /// The sets, each its members in increasing order, in the order of their smallest members.
  std::vector<std::vector<std::size_t>> sets() {
    std::vector<std::vector<std::size_t>> by_root(parent_.size());
    for (std::size_t x = 0; x < parent_.size(); ++x) by_root[root(x)].push_back(x);
    std::vector<std::vector<std::size_t>> out;
    for (std::vector<std::size_t>& set : by_root) {
      if (!set.empty()) out.push_back(std::move(set));
    }
    return out;
  }

 private:
  std::vector<std::size_t> parent_;
};

}  // namespace collision_response::core
