#include "solver/contact_group.h"

#include "solver/order_free.h"

namespace collision_response::core::contact_group {

void tangentBasis(const V3& normal, V3& first, V3& second) {
  Eigen::Index axis = 0;
  normal.cwiseAbs().minCoeff(&axis);
  V3 unit = V3::Zero();
  unit[axis] = 1;
  first = normal.cross(unit).normalized();
  second = normal.cross(first);
}

namespace {

/// Among the least-squares solutions of a x = b, given the one of minimum norm `x` from a's
/// complete orthogonal decomposition a P = Q [T 0; 0 0] Z (rank r): the one whose unknowns
/// marked in `least_first` have the least norm, and among those the least norm of all. The
/// solutions are x + K y, K = P Z^T's last n - r columns an orthonormal basis of a's kernel,
/// and x is orthogonal to it, so |x + K y|^2 = |x|^2 + |y|^2: the minimum-norm y of
/// (S K) y = -S x (S the marked rows) is both.
Vector leastFirst(const Eigen::CompleteOrthogonalDecomposition<Matrix>& decomposition,
                  const Vector& x, const std::vector<char>& least_first) {
  const Eigen::Index n = decomposition.cols(), rank = decomposition.rank();
  std::vector<Eigen::Index> marked;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (least_first[static_cast<std::size_t>(i)]) marked.push_back(i);
  }
  if (rank == n || marked.empty()) return x;
  const Matrix kernel =
      decomposition.colsPermutation() * decomposition.matrixZ().bottomRows(n - rank).transpose();
  const auto m = static_cast<Eigen::Index>(marked.size());
  Matrix selected(m, n - rank);
  Vector shift(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    selected.row(r) = kernel.row(marked[static_cast<std::size_t>(r)]);
    shift[r] = -x[marked[static_cast<std::size_t>(r)]];
  }
  return x + kernel * selected.completeOrthogonalDecomposition().solve(shift);
}

}  // namespace

Vector solveMinimumNorm(Eigen::Index size, const std::vector<Entry>& entries, const Vector& target,
                        const std::vector<char>& least_first) {
  const auto unknown = [](Eigen::Index i) { return static_cast<std::size_t>(i); };
  ConnectedSets connected(unknown(size));
  for (const Entry& entry : entries) {
    if (entry.value != 0) connected.link(unknown(entry.row), unknown(entry.column));
  }
  const std::vector<std::vector<std::size_t>> blocks = connected.sets();
  // Each unknown's block and its place in it.
  std::vector<std::size_t> block_of(unknown(size)), place(unknown(size));
  std::vector<Matrix> parts(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (std::size_t i = 0; i < blocks[b].size(); ++i) {
      block_of[blocks[b][i]] = b;
      place[blocks[b][i]] = i;
    }
    const auto n = static_cast<Eigen::Index>(blocks[b].size());
    parts[b] = Matrix::Zero(n, n);
  }
  for (const Entry& entry : entries) {
    if (entry.value == 0) continue;
    parts[block_of[unknown(entry.row)]](static_cast<Eigen::Index>(place[unknown(entry.row)]),
                                        static_cast<Eigen::Index>(place[unknown(entry.column)])) =
        entry.value;
  }
  Vector solution = Vector::Zero(size);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const std::vector<std::size_t>& block = blocks[b];
    const auto n = static_cast<Eigen::Index>(block.size());
    Vector right(n);
    for (Eigen::Index i = 0; i < n; ++i)
      right[i] = target[static_cast<Eigen::Index>(block[unknown(i)])];
    const Eigen::CompleteOrthogonalDecomposition<Matrix> decomposition(parts[b]);
    Vector x = decomposition.solve(right);
    if (!least_first.empty() && decomposition.rank() < n) {
      std::vector<char> marked(block.size());
      for (std::size_t i = 0; i < block.size(); ++i) marked[i] = least_first[block[i]];
      x = leastFirst(decomposition, x, marked);
    }
    for (Eigen::Index i = 0; i < n; ++i)
      solution[static_cast<Eigen::Index>(block[unknown(i)])] = x[i];
  }
  return solution;
}

std::vector<Entry> assembleConditions(const Group& group, const std::vector<Unknown>& unknowns,
                                      const std::vector<Condition>& conditions) {
  std::vector<std::vector<Eigen::Index>> conditions_of(group.contactCount());
  for (std::size_t i = 0; i < conditions.size(); ++i) {
    conditions_of[conditions[i].contact].push_back(static_cast<Eigen::Index>(i));
  }
  std::vector<Entry> entries;
  for (std::size_t u = 0; u < unknowns.size(); ++u) {
    const auto j = static_cast<Eigen::Index>(u);
    group.respondToOne(unknowns[u].contact, unknowns[u].pattern,
                       [&](std::size_t k, Real gap, const V3& slip) {
                         for (const Eigen::Index i : conditions_of[k]) {
                           const Condition& condition = conditions[static_cast<std::size_t>(i)];
                           entries.push_back(Entry{i, j, conditionValue(condition, gap, slip)});
                         }
                       });
  }
  return entries;
}

std::vector<V3> forcesOf(std::size_t count, const std::vector<Unknown>& unknowns,
                         const Vector& solution) {
  std::vector<V3> forces(count, V3::Zero());
  for (Eigen::Index j = 0; j < solution.size(); ++j) {
    const Unknown& unknown = unknowns[static_cast<std::size_t>(j)];
    forces[unknown.contact] += solution[j] * unknown.pattern;
  }
  return forces;
}

}  // namespace collision_response::core::contact_group
