#include "solver/friction_impulses.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include "solver/contact_group.h"
#include "solver/order_free.h"

namespace collision_response::core {

using namespace contact_group;

namespace {

/// A block's friction problem, dense: the minimum of E(x) = x'A x / 2 + s'x over the discs
/// |x_k| <= b_k (`coupling` A, `slip` s, `bound` b; x_k = x[2 k], x[2 k + 1] in contact k's
/// tangent basis).
struct DiscProblem {
  const Matrix& coupling;
  const Vector& slip;
  const std::vector<Real>& bound;

  Eigen::Index size() const { return slip.size(); }
  Eigen::Index discs() const { return slip.size() / 2; }
  Real b(Eigen::Index k) const { return bound[static_cast<std::size_t>(k)]; }
  Real energy(const Vector& x) const { return 0.5L * x.dot(coupling * x) + slip.dot(x); }
  /// b_k^2 - |x_k|^2: > 0 inside disc k.
  Real room(const Vector& x, Eigen::Index k) const {
    return b(k) * b(k) - x.segment<2>(2 * k).squaredNorm();
  }
};

/// The scale of the energies: what stopping every slip alone would remove.
Real energyScale(const DiscProblem& problem) {
  Real scale = 0;
  for (Eigen::Index i = 0; i < problem.size(); ++i) {
    scale = std::max(scale, std::abs(problem.slip[i]) * problem.b(i / 2));
  }
  return scale;
}

/// The contacts at their disc's edge take the bound exactly, against the slip A x + s they
/// leave.
void pressEdgesToBound(const DiscProblem& problem, const std::vector<char>& edge, Vector& x) {
  const Vector residual = problem.coupling * x + problem.slip;  // the slips left
  for (Eigen::Index k = 0; k < problem.discs(); ++k) {
    if (!edge[static_cast<std::size_t>(k)]) continue;
    const Eigen::Matrix<Real, 2, 1> left = residual.segment<2>(2 * k);
    const Real b = problem.b(k);
    if (left.norm() > 0) {
      x.segment<2>(2 * k) = -b * left.normalized();
    } else if (x.segment<2>(2 * k).norm() > b) {
      x.segment<2>(2 * k) *= b / x.segment<2>(2 * k).norm();
    }
  }
}

/// The contacts inside their discs stop their slip exactly, the edge ones' impulses given: the
/// rows of A x + s = 0 of the inner unknowns, solved for them (least squares, minimum norm).
void stopInnerSlips(const DiscProblem& problem, const std::vector<char>& edge, Vector& x) {
  std::vector<Eigen::Index> inner;
  for (Eigen::Index i = 0; i < problem.size(); ++i) {
    if (!edge[static_cast<std::size_t>(i / 2)]) inner.push_back(i);
  }
  if (inner.empty()) return;
  const auto n = static_cast<Eigen::Index>(inner.size());
  Matrix system(n, n);
  Vector target(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    target[r] = -problem.slip[inner[r]];
    for (Eigen::Index j = 0; j < problem.size(); ++j) {
      if (edge[static_cast<std::size_t>(j / 2)]) {
        target[r] -= problem.coupling(inner[r], j) * x[j];
      }
    }
    for (Eigen::Index c = 0; c < n; ++c) system(r, c) = problem.coupling(inner[r], inner[c]);
  }
  const Vector solved = system.completeOrthogonalDecomposition().solve(target);
  for (Eigen::Index r = 0; r < n; ++r) x[inner[r]] = solved[r];
}

/// Whether Coulomb's conditions hold at x: an edge contact's impulse against the slip left
/// (not reversing it), an inner one within its bound with its slip stopped; and whether an edge
/// impulse has yet to settle along the slip left (to within rounding).
struct CoulombVerdict {
  bool holds = true;
  bool moved = false;
};

CoulombVerdict coulombVerdict(const DiscProblem& problem, const std::vector<char>& edge,
                              const Vector& x) {
  const Vector left = problem.coupling * x + problem.slip;
  CoulombVerdict verdict;
  for (Eigen::Index k = 0; k < problem.discs() && verdict.holds; ++k) {
    const Real b = problem.b(k);
    const Eigen::Matrix<Real, 2, 1> xk = x.segment<2>(2 * k), lk = left.segment<2>(2 * k);
    if (edge[static_cast<std::size_t>(k)]) {
      if (lk.norm() == 0) continue;
      verdict.holds = xk.dot(lk) <= 0;
      if ((xk / b + lk.normalized()).norm() > 1e-15L) verdict.moved = true;
    } else {
      verdict.holds = xk.norm() <= b && lk.norm() <= 1e-15L * (problem.slip.norm() + 1);
    }
  }
  return verdict;
}

/// Where a condition fails, the contact changes sides (all at once): an inner one beyond its
/// bound goes to the edge, an edge one whose impulse would reverse the slip goes inside.
void switchSides(const DiscProblem& problem, const Vector& x, std::vector<char>& edge) {
  const Vector left = problem.coupling * x + problem.slip;
  for (Eigen::Index k = 0; k < problem.discs(); ++k) {
    const Real b = problem.b(k);
    const Eigen::Matrix<Real, 2, 1> xk = x.segment<2>(2 * k), lk = left.segment<2>(2 * k);
    char& on_edge = edge[static_cast<std::size_t>(k)];
    if (!on_edge && xk.norm() > b) {
      on_edge = 1;
    } else if (on_edge && xk.dot(lk) > 0) {
      on_edge = 0;
    }
  }
}

/// The dense solve's steps (a factorisation of the block's matrix: the sticking solve, a round of
/// polishing, a Newton step) that a bound on the impact's work leaves it (WorkBound), and how
/// many it took.
struct DenseSteps {
  std::size_t left = std::numeric_limits<std::size_t>::max();
  std::size_t taken = 0;
  bool cut = false;  ///< a step was wanted with none left
  /// One more step: false (and cut) where none is left.
  bool take() {
    if (taken >= left) {
      cut = true;
      return false;
    }
    ++taken;
    return true;
  }
};

/// Coulomb's conditions for a given set of contacts at their disc's edge: those take the bound
/// exactly, against the slip they leave; the others stop their slip exactly (a linear solve);
/// repeated while the edge directions move. True (and `x` set) when they then hold; else `x` is
/// the last attempt and `edge` switched where a condition failed.
bool polishCoulomb(const DiscProblem& problem, Vector& x, std::vector<char>& edge,
                   DenseSteps& steps) {
  Vector polished = x;
  for (int round = 0; round < 8; ++round) {
    if (!steps.take()) return false;
    pressEdgesToBound(problem, edge, polished);
    stopInnerSlips(problem, edge, polished);
    const CoulombVerdict verdict = coulombVerdict(problem, edge, polished);
    if (verdict.holds && !verdict.moved) {
      x = polished;
      return true;
    }
    if (!verdict.holds) break;
  }
  switchSides(problem, polished, edge);
  x = polished;
  return false;
}

/// The barrier objective t E(y) - sum_k log(b_k^2 - |y_k|^2).
Real barrierObjective(const DiscProblem& problem, Real t, const Vector& y) {
  Real value = t * problem.energy(y);
  for (Eigen::Index k = 0; k < problem.discs(); ++k) value -= std::log(problem.room(y, k));
  return value;
}

/// One damped Newton step on the barrier objective at x for weight t: false where it no longer
/// decreases (the decrement below 1e-20, or no step length that stays inside every disc and
/// decreases it by a quarter of the decrement times the length: Armijo backtracking).
bool newtonStep(const DiscProblem& problem, Real t, Vector& x) {
  Vector gradient = t * (problem.coupling * x + problem.slip);
  Matrix hessian = t * problem.coupling;
  for (Eigen::Index k = 0; k < problem.discs(); ++k) {
    // -log g, g = b^2 - |x_k|^2: gradient 2 x_k / g, Hessian 2 I / g + 4 x_k x_k' / g^2.
    const Real g = problem.room(x, k);
    const Eigen::Matrix<Real, 2, 1> xk = x.segment<2>(2 * k);
    gradient.segment<2>(2 * k) += (2 / g) * xk;
    hessian.block<2, 2>(2 * k, 2 * k) +=
        (2 / g) * Eigen::Matrix<Real, 2, 2>::Identity() + (4 / (g * g)) * xk * xk.transpose();
  }
  const Vector step = -hessian.ldlt().solve(gradient);
  const Real decrement = -gradient.dot(step);
  if (!(decrement > 1e-20L)) return false;
  const Real here = barrierObjective(problem, t, x);
  Real length = 1;
  for (int halving = 0; halving < 60; ++halving, length *= 0.5L) {
    const Vector y = x + length * step;
    bool inside = true;
    for (Eigen::Index k = 0; k < problem.discs() && inside; ++k) inside = problem.room(y, k) > 0;
    if (inside && barrierObjective(problem, t, y) <= here - 0.25L * length * decrement) {
      x = y;
      return true;
    }
  }
  return false;
}

/// The primal barrier method (Boyd and Vandenberghe, "Convex Optimization", 2004, section
/// 11.3): from x = 0, Newton's method on t E(x) - sum log(b^2 - |x_k|^2) for t growing tenfold,
/// until the duality gap discs / t is below 1e-14 of the energies (nearer the discs' edges
/// b^2 - |x|^2 loses its digits). Where A is singular the barrier tends to the centre of the
/// optimal set, so the answer depends on no order.
///
/// Stopped short (no `steps` left), x is still inside every disc and E(x) <= 0: each Newton step
/// lowers t E - sum log(b^2 - |x|^2), whose log part is least at x = 0, so t E(x) stays below
/// what the log part gained, and a larger t keeps it so.
Vector barrierMinimum(const DiscProblem& problem, DenseSteps& steps) {
  const Real scale = energyScale(problem);
  Vector x = Vector::Zero(problem.size());
  Real t = 1 / std::max(scale, Real(1e-300));
  const Real gap_wanted = 1e-14L * std::max(scale, Real(1e-300));
  for (int outer = 0; outer < 40; ++outer) {
    for (int newton = 0; newton < 50; ++newton) {
      if (!steps.take()) return x;
      if (!newtonStep(problem, t, x)) break;
    }
    if (Real(problem.discs()) / t < gap_wanted) break;
    t *= 10;
  }
  return x;
}

/// The friction impulses x (each contact's, in its tangent basis: x[2 k], x[2 k + 1]) of a block
/// small enough for dense algebra: the minimum of E(x) = x'A x / 2 + s'x over the discs
/// |x_k| <= b_k (`coupling` A, `slip` s, `bound` b). First Coulomb's conditions solved exactly
/// from the sticking answer (fast, and usually right at once); where they do not settle, a
/// primal barrier method (barrierMinimum, in long double), then the same exact conditions from
/// its answer.
///
/// `steps`: what a bound on the impact's work leaves (DenseSteps). Stopped short before the
/// barrier method, no friction (x = 0); within it, its last iterate, inside every disc, where
/// its energy is at most E(0) = 0 (else x = 0); in the last polish, the barrier's answer;
/// `steps.cut` says so.
Vector frictionByBarrier(const Matrix& coupling, const Vector& slip, const std::vector<Real>& bound,
                         DenseSteps& steps) {
  const DiscProblem problem{coupling, slip, bound};
  const Eigen::Index disc = problem.discs();
  if (!steps.take()) return Vector::Zero(slip.size());
  Vector x = coupling.completeOrthogonalDecomposition().solve(-slip);  // sticking everywhere
  std::vector<char> edge(static_cast<std::size_t>(disc), 0);
  for (Eigen::Index k = 0; k < disc; ++k) {
    edge[static_cast<std::size_t>(k)] = x.segment<2>(2 * k).norm() > problem.b(k);
  }
  bool settled = false;
  for (int attempt = 0; attempt < 8 && !settled && !steps.cut; ++attempt) {
    settled = polishCoulomb(problem, x, edge, steps);
  }
  if (settled) return x;
  if (steps.cut) return Vector::Zero(slip.size());
  x = barrierMinimum(problem, steps);
  if (steps.cut) return problem.energy(x) <= 0 ? x : Vector::Zero(slip.size());
  for (Eigen::Index k = 0; k < disc; ++k) {
    edge[static_cast<std::size_t>(k)] = x.segment<2>(2 * k).norm() >= problem.b(k) * (1 - 1e-8L);
  }
  Vector polished = x;
  if (polishCoulomb(problem, polished, edge, steps)) x = polished;
  return x;
}

/// A block's tangential coupling row by row: for each unknown (a contact's first or second
/// tangent: 2 k and 2 k + 1 in the block's numbering), its nonzero (column, A_ij).
using CouplingRows = std::vector<std::vector<std::pair<Eigen::Index, Real>>>;

/// Relative to the largest slip, the projected-gradient residual at which the iterative friction
/// solve stops (doc/model.md, "Work per message, and threads").
constexpr Real kFrictionResidual = 1e-12L;
/// The iterative friction solve's iterations at most.
constexpr int kFrictionIterations = 10000;

/// The friction impulses of a block too large for dense algebra (more than kDenseBlockContacts
/// contacts): the minimum of E(x) = x'A x / 2 + s'x over the discs |x_k| <= b_k by an
/// accelerated projected gradient (Beck and Teboulle, "A fast iterative shrinkage-thresholding
/// algorithm for linear inverse problems", SIAM J. Imaging Sci. 2009), its momentum restarted
/// wherever it points against the step taken (O'Donoghue and Candes, "Adaptive restart for
/// accelerated gradient schemes", Found. Comput. Math. 2015). The step is 1/L with
/// L = max_i sum_j |A_ij|, at least A's largest eigenvalue (Gershgorin). A x is built row by row
/// from A's nonzeros: an iteration costs O(the block's nonzeros).
///
/// Every iterate is a projection onto the discs, so whatever the iteration reaches, |x_k| <= b_k
/// (to the rounding of one scaling). It stops where the projected-gradient residual
/// L |x - P(x - (A x + s) / L)| (per contact; 0 exactly where x is the minimum: Coulomb's law,
/// the slip stopped inside the disc, at the bound against the slip left on its edge) is at most
/// kFrictionResidual of the largest slip, returning true; else at a fixed point of the rounded
/// step or after `max_iterations` (kFrictionIterations, or fewer where the impact's work is
/// bounded: WorkBound), returning false; `iterations` says how many it took. The last iterate is
/// returned where its energy is at most E(0) = 0 (friction adds no energy), else the iterate of the
/// lowest energy (x = 0 at worst), returning false. Every sum (rows of A x, the energy, dot
/// products, the bound) is order-free and sign-symmetric (orderFreeSum), so renaming the bodies or
/// mirroring the cluster changes no bit. A block's friction problem by A's nonzeros (CouplingRows),
/// every sum order-free.
class SparseDiscProblem {
 public:
  SparseDiscProblem(const CouplingRows& rows, const Vector& slip, const std::vector<Real>& bound)
      : rows_(rows), slip_(slip), bound_(bound) {}

  Eigen::Index size() const { return slip_.size(); }
  Eigen::Index discs() const { return slip_.size() / 2; }

  /// A v, row by row.
  Vector apply(const Vector& v) {
    Vector out(size());
    for (Eigen::Index i = 0; i < size(); ++i) {
      terms_.clear();
      for (const auto& [j, value] : rows_[static_cast<std::size_t>(i)]) {
        terms_.push_back(value * v[j]);
      }
      out[i] = orderFreeSum(terms_);
    }
    return out;
  }
  /// E(v), A v given.
  Real energy(const Vector& v, const Vector& coupled) {
    terms_.clear();
    for (Eigen::Index i = 0; i < size(); ++i) {
      terms_.push_back(v[i] * (0.5L * coupled[i] + slip_[i]));
    }
    return orderFreeSum(terms_);
  }
  Real dot(const Vector& u, const Vector& v) {
    terms_.clear();
    for (Eigen::Index i = 0; i < size(); ++i) terms_.push_back(u[i] * v[i]);
    return orderFreeSum(terms_);
  }
  /// L = max_i sum_j |A_ij|: at least A's largest eigenvalue (Gershgorin).
  Real lipschitz() {
    Real bound = 0;
    for (Eigen::Index i = 0; i < size(); ++i) {
      terms_.clear();
      for (const auto& entry : rows_[static_cast<std::size_t>(i)]) {
        terms_.push_back(std::abs(entry.second));
      }
      bound = std::max(bound, orderFreeSum(terms_));
    }
    return bound;
  }
  Real largestSlip() const {
    Real largest = 0;
    for (Eigen::Index k = 0; k < discs(); ++k) {
      largest = std::max(largest, slip_.segment<2>(2 * k).norm());
    }
    return largest;
  }
  /// P(v - (A v + s) / L), A v given: a gradient step of length 1/L projected onto the discs.
  Vector projectedStep(const Vector& v, const Vector& coupled, Real lipschitz) const {
    Vector step = v - (coupled + slip_) / lipschitz;
    for (Eigen::Index k = 0; k < discs(); ++k) {
      const Real length = step.segment<2>(2 * k).norm(), b = bound_[static_cast<std::size_t>(k)];
      if (length > b) step.segment<2>(2 * k) *= b / length;
    }
    return step;
  }
  /// The projected-gradient residual L |v - P(v - (A v + s) / L)|, its largest per contact.
  Real residual(const Vector& v, const Vector& coupled, Real lipschitz) const {
    const Vector step = projectedStep(v, coupled, lipschitz);
    Real worst = 0;
    for (Eigen::Index k = 0; k < discs(); ++k) {
      worst = std::max(worst, lipschitz * (v.segment<2>(2 * k) - step.segment<2>(2 * k)).norm());
    }
    return worst;
  }

 private:
  const CouplingRows& rows_;
  const Vector& slip_;
  const std::vector<Real>& bound_;
  std::vector<Real> terms_;  // the sums' terms (orderFreeSum orders them in place)
};

/// The accelerated iteration's state: the last iterate x, where the next step starts (x plus
/// momentum) y, each with its A times it, and the momentum's weight.
struct AcceleratedIterate {
  Vector x, coupled_x, y, coupled_y;
  Real momentum = 1;
};

/// The iteration moves on to z (A z given): its momentum restarted where it points against the
/// step taken (O'Donoghue and Candes), else carried by Beck and Teboulle's weights
/// m' = (1 + sqrt(1 + 4 m^2)) / 2, y = z + (m - 1) / m' (z - x).
void advance(SparseDiscProblem& problem, Vector z, const Vector& coupled_z,
             AcceleratedIterate& it) {
  if (problem.dot(it.y - z, z - it.x) > 0) {
    it.y = z;
    it.coupled_y = coupled_z;
    it.momentum = 1;
  } else {
    const Real next = (1 + std::sqrt(1 + 4 * it.momentum * it.momentum)) / 2;
    const Real carried = (it.momentum - 1) / next;
    it.y = z + carried * (z - it.x);
    it.coupled_y = coupled_z + carried * (coupled_z - it.coupled_x);  // A y, by linearity
    it.momentum = next;
  }
  it.x = std::move(z);
  it.coupled_x = coupled_z;
}

bool frictionByProjectedGradient(const CouplingRows& rows, const Vector& slip,
                                 const std::vector<Real>& bound, int max_iterations,
                                 Vector& solution, int& iterations) {
  SparseDiscProblem problem(rows, slip, bound);
  const Eigen::Index size = problem.size();
  const Real lipschitz = problem.lipschitz();
  const Real largest_slip = problem.largestSlip();
  solution = Vector::Zero(size);
  if (!(lipschitz > 0)) return false;  // no contact moves a body: no impulse does anything
  const Real tolerance = kFrictionResidual * largest_slip;
  AcceleratedIterate it{Vector::Zero(size), Vector::Zero(size), Vector::Zero(size),
                        Vector::Zero(size)};
  Vector lowest = it.x;  // the iterate of the lowest energy so far
  Real lowest_energy = 0, energy_x = 0;
  bool settled = false;
  iterations = 0;
  for (int iteration = 0; iteration < max_iterations && !settled; ++iteration) {
    Vector z = problem.projectedStep(it.y, it.coupled_y, lipschitz);
    const Vector coupled_z = problem.apply(z);
    energy_x = problem.energy(z, coupled_z);
    if (energy_x <= lowest_energy) {
      lowest = z;
      lowest_energy = energy_x;
    }
    // Or a fixed point of the rounding.
    settled = problem.residual(z, coupled_z, lipschitz) <= tolerance || z == it.x;
    advance(problem, std::move(z), coupled_z, it);
    ++iterations;
  }
  if (energy_x <= 0) {
    solution = it.x;
    return problem.residual(it.x, it.coupled_x, lipschitz) <= tolerance;
  }
  solution = lowest;
  return false;
}

/// The contacts of an impact that can take friction: a bound mu J > 0 and a slip.
struct FrictionContacts {
  std::vector<std::size_t> active;  // their indices
  std::vector<Real> bound;          // per active contact: mu J
  std::vector<long> slot;           // per contact: its place in `active`, -1 if not there
};

FrictionContacts frictionContacts(const Group& group, const std::vector<ForceContact>& contacts,
                                  const std::vector<double>& normal_impulses) {
  FrictionContacts friction;
  friction.slot.assign(contacts.size(), -1);
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const Real b = Real(contacts[k].friction) * Real(normal_impulses[k]);
    if (b > 0 && group.slip(k).norm() > 0) {
      friction.slot[k] = static_cast<long>(friction.active.size());
      friction.active.push_back(k);
      friction.bound.push_back(b);
    }
  }
  return friction;
}

/// Contact k's tangent t (0: first, 1: second).
const V3& tangentOf(const Group& group, std::size_t k, Eigen::Index t) {
  return t == 0 ? group.first(k) : group.second(k);
}

/// The tangential coupling of the active contacts: per active contact l, what a unit impulse
/// along each of its tangents does to the slips of the active contacts m it shares a movable
/// body with, C(m, l) (row: m's tangents; column: l's), sorted by m; and the blocks of contacts
/// so connected. Built column by column from each unknown's response (Group::respondToOne), in
/// O(its nonzeros).
class TangentialCoupling {
 public:
  using Block = Eigen::Matrix<Real, 2, 2>;
  using Column = std::vector<std::pair<std::size_t, Block>>;

  TangentialCoupling(const Group& group, const FrictionContacts& friction)
      : columns_(friction.active.size()), connected_(friction.active.size()) {
    for (std::size_t l = 0; l < friction.active.size(); ++l) {
      for (Eigen::Index t = 0; t < 2; ++t) {
        std::size_t visited = 0;  // respondToOne visits in the same order for either force
        group.respondToOne(friction.active[l], tangentOf(group, friction.active[l], t),
                           [&](std::size_t k, Real, const V3& slip_change) {
                             if (friction.slot[k] < 0) return;
                             const auto m = static_cast<std::size_t>(friction.slot[k]);
                             if (t == 0) {
                               columns_[l].emplace_back(m, Block::Zero());
                               connected_.link(l, m);
                             }
                             Block& entry = columns_[l][visited++].second;
                             entry(0, t) = group.first(k).dot(slip_change);
                             entry(1, t) = group.second(k).dot(slip_change);
                           });
      }
      std::sort(columns_[l].begin(), columns_[l].end(),
                [](const auto& p, const auto& q) { return p.first < q.first; });
    }
  }

  /// The blocks: sets of active contacts connected through shared movable bodies.
  std::vector<std::vector<std::size_t>> blocks() { return connected_.sets(); }
  /// The active contacts m whose slips contact l's impulses change (m, C(m, l)), by m.
  const Column& column(std::size_t l) const { return columns_[l]; }

  /// The symmetric coupling A(m, l) = (C(m, l) + C(l, m)') / 2 (C is symmetric up to rounding),
  /// row r of m's tangents, column c of l's.
  Real operator()(std::size_t m, std::size_t l, Eigen::Index r, Eigen::Index c) const {
    const Column& column = columns_[l];
    const Column& row = columns_[m];
    const auto at = [](const Column& list, std::size_t key) {
      return std::lower_bound(list.begin(), list.end(), key,
                              [](const auto& p, std::size_t value) { return p.first < value; });
    };
    const auto forward = at(column, m);
    const auto backward = at(row, l);
    const Real there = forward != column.end() && forward->first == m ? forward->second(r, c) : 0;
    const Real back = backward != row.end() && backward->first == l ? backward->second(c, r) : 0;
    return 0.5L * (there + back);
  }

 private:
  std::vector<Column> columns_;
  ConnectedSets connected_;
};

/// Visits every coupling entry of a block, visit(row, column, A_ij), in the block's numbering
/// (contact p of the block: unknowns 2 p and 2 p + 1; `place`: each active contact's p).
template <class Visit>
void forEachCouplingEntry(const TangentialCoupling& coupling, const std::vector<std::size_t>& block,
                          const std::vector<Eigen::Index>& place, Visit visit) {
  for (std::size_t q = 0; q < block.size(); ++q) {
    const std::size_t l = block[q];
    const auto column = static_cast<Eigen::Index>(2 * q);
    for (const auto& entry : coupling.column(l)) {
      for (Eigen::Index r = 0; r < 2; ++r) {
        for (Eigen::Index c = 0; c < 2; ++c) {
          visit(2 * place[entry.first] + r, column + c, coupling(entry.first, l, r, c));
        }
      }
    }
  }
}

/// A block's friction problem in its numbering (contact p of the block: unknowns 2 p, 2 p + 1):
/// the slips s in the contacts' tangent bases and the bounds b.
struct BlockProblem {
  Vector slip;
  std::vector<Real> bound;
};

/// The block's problem; `place` takes each of its contacts' p.
BlockProblem setUpBlock(const Group& group, const FrictionContacts& friction,
                        const std::vector<std::size_t>& block, std::vector<Eigen::Index>& place) {
  const auto n = static_cast<Eigen::Index>(block.size());
  BlockProblem problem{Vector(2 * n), std::vector<Real>(block.size())};
  for (Eigen::Index p = 0; p < n; ++p) {
    const std::size_t l = block[static_cast<std::size_t>(p)];
    place[l] = p;
    problem.bound[static_cast<std::size_t>(p)] = friction.bound[l];
    for (Eigen::Index t = 0; t < 2; ++t) {
      problem.slip[2 * p + t] =
          tangentOf(group, friction.active[l], t).dot(group.slip(friction.active[l]));
    }
  }
  return problem;
}

/// The block's impulses x (in its numbering) onto each contact's tangents: its impulse on b.
void addBlockImpulses(const Group& group, const FrictionContacts& friction,
                      const std::vector<std::size_t>& block, const Vector& x,
                      std::vector<V3>& impulses) {
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const std::size_t k = friction.active[block[static_cast<std::size_t>(j / 2)]];
    impulses[k] += x[j] * tangentOf(group, k, j % 2);
  }
}

/// A block's friction impulses x (in its numbering), by dense algebra up to kDenseBlockContacts
/// contacts (frictionByBarrier), above by the accelerated projected gradient
/// (frictionByProjectedGradient; false where it stops short of its residual).
///
/// `work` (optional): what the block may spend and spent (solveFrictionImpulses; WorkBound's
/// units: an iteration of the projected gradient costs the block's contacts, a step of the dense
/// solve, frictionByBarrier's factorisation and its line search, WorkBound::denseStep). A block
/// reached with too little left for a step gets no friction (x = 0); one that runs out stops
/// where its solve got to.
bool frictionOfBlock(const TangentialCoupling& coupling, const std::vector<std::size_t>& block,
                     const std::vector<Eigen::Index>& place, const Vector& slip,
                     const std::vector<Real>& bound, WorkBound* work, Vector& x) {
  const std::size_t left = work == nullptr ? std::numeric_limits<std::size_t>::max() : work->left();
  if (block.size() <= kDenseBlockContacts) {
    const std::size_t step_cost = WorkBound::denseStep(block.size());
    DenseSteps steps;
    if (left != std::numeric_limits<std::size_t>::max()) steps.left = left / step_cost;
    Matrix dense = Matrix::Zero(slip.size(), slip.size());
    forEachCouplingEntry(coupling, block, place,
                         [&](Eigen::Index i, Eigen::Index j, Real value) { dense(i, j) = value; });
    x = frictionByBarrier(dense, slip, bound, steps);
    if (work != nullptr) {
      work->spent += steps.taken * step_cost;
      work->cut = work->cut || steps.cut;
    }
    return !steps.cut;
  }
  const int allowed = static_cast<int>(
      std::min<std::size_t>(left / block.size(), static_cast<std::size_t>(kFrictionIterations)));
  if (allowed == 0) {
    work->cut = true;
    x = Vector::Zero(slip.size());
    return false;
  }
  CouplingRows rows(static_cast<std::size_t>(slip.size()));
  forEachCouplingEntry(coupling, block, place, [&](Eigen::Index i, Eigen::Index j, Real value) {
    if (value != 0) rows[static_cast<std::size_t>(i)].emplace_back(j, value);
  });
  int iterations = 0;
  const bool converged = frictionByProjectedGradient(rows, slip, bound, allowed, x, iterations);
  if (work != nullptr) {
    work->spent += static_cast<std::size_t>(iterations) * block.size();
    if (!converged && allowed < kFrictionIterations && iterations == allowed) work->cut = true;
  }
  return converged;
}

/// The answer in doubles: each contact's impulse (in `tangential`), slip, slip change and mode
/// (sticking where the impulse stays within its bound), each body's change of velocity (in
/// `acceleration`) and of angular velocity (in `angular_acceleration`).
ContactForceSolution storeFrictionImpulses(const Group& group, const FrictionContacts& friction,
                                           const std::vector<V3>& impulses, std::size_t body_count,
                                           bool converged) {
  const Response change = group.respond(impulses, false);
  ContactForceSolution result;
  result.converged = converged;
  result.contacts.resize(impulses.size());
  for (std::size_t k = 0; k < impulses.size(); ++k) {
    ContactForce& out = result.contacts[k];
    out.tangential = impulses[k].cast<double>();
    out.slip = group.slip(k).cast<double>();
    out.slip_acceleration = change.slip_acceleration[k].cast<double>();
    if (friction.slot[k] < 0) {
      out.mode = ContactMode::kSeparating;
    } else {
      const Real b = friction.bound[static_cast<std::size_t>(friction.slot[k])];
      out.mode =
          impulses[k].norm() < b * (1 - 1e-9L) ? ContactMode::kSticking : ContactMode::kSliding;
    }
  }
  result.acceleration.resize(body_count);
  result.angular_acceleration.resize(body_count);
  for (std::size_t i = 0; i < body_count; ++i) {
    result.acceleration[i] = change.acceleration[i].cast<double>();
    result.angular_acceleration[i] = change.angular_acceleration[i].cast<double>();
  }
  return result;
}

}  // namespace

ContactForceSolution solveFrictionImpulses(const std::vector<ForceBody>& bodies,
                                           const std::vector<ForceContact>& contacts,
                                           const std::vector<double>& normal_impulses,
                                           WorkBound* work) {
  // Maximal dissipation: the tangential impulses x (on each contact's b, in its tangent basis)
  // minimise the kinetic energy they leave, E(x) = x'A x / 2 + s'x (A the tangential coupling,
  // s the slips; E is exactly the change of kinetic energy), over the discs |x_k| <= mu_k J_k.
  // Its minimum is Coulomb's law: where the disc's inside holds it the slip stops (A x + s = 0),
  // elsewhere the impulse is at the bound against the slip left. E(x) <= E(0) = 0: friction
  // never adds energy. A_kl = 0 unless contacts k and l share a movable body, so E is a sum over
  // the blocks of contacts connected through shared movable bodies, each minimised on its own
  // (exact): by dense algebra up to kDenseBlockContacts contacts (frictionByBarrier), above by
  // an accelerated projected gradient to a documented residual (frictionByProjectedGradient).
  // A is built column by column from each unknown's response (Group::respondToOne), in
  // O(its nonzeros).
  const Group group(bodies, contacts);
  const FrictionContacts friction = frictionContacts(group, contacts, normal_impulses);
  TangentialCoupling coupling(group, friction);
  std::vector<V3> impulses(contacts.size(), V3::Zero());
  bool converged = true;
  std::vector<Eigen::Index> place(friction.active.size(), -1);  // each one's place in its block
  for (const std::vector<std::size_t>& block : coupling.blocks()) {
    const BlockProblem problem = setUpBlock(group, friction, block, place);
    Vector x;
    converged =
        frictionOfBlock(coupling, block, place, problem.slip, problem.bound, work, x) && converged;
    addBlockImpulses(group, friction, block, x, impulses);
  }
  return storeFrictionImpulses(group, friction, impulses, bodies.size(), converged);
}
}  // namespace collision_response::core
