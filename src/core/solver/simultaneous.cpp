#include "collision_response/core/simultaneous.h"

#include <Eigen/Dense>
#include <algorithm>
#include <limits>

#include "collision_response/core/impact.h"
#include "solver/order_free.h"

namespace collision_response::core {
namespace {

double relativeNormalVelocity(const std::vector<ClusterBody>& bodies,
                              const ClusterContact& contact) {
  return (bodies[contact.b].velocity - bodies[contact.a].velocity).dot(contact.normal);
}

std::vector<ContactOutcome> resolveOne(std::vector<ClusterBody>& bodies,
                                       const ClusterContact& contact) {
  ClusterBody& a = bodies[contact.a];
  ClusterBody& b = bodies[contact.b];
  const ImpactResponse<double> response = resolveImpact(
      a.inverse_mass, a.velocity, b.inverse_mass, b.velocity, contact.normal, contact.restitution);
  a.velocity = response.velocity_a;
  b.velocity = response.velocity_b;
  return {ContactOutcome{response.normal_impulse, response.approach_speed, response.energy_lost}};
}

// Blocks of more than kDenseBlockContacts contacts are solved by conjugate gradients (doc/model.md,
// "Work per message"): a dense solve costs the cube of the contacts (a lattice of 1,000 touching
// balls closing on its centre, 2,700 contacts, took a minute).

using RealL = long double;
using MatrixL = Eigen::Matrix<RealL, Eigen::Dynamic, Eigen::Dynamic>;
using VectorL = Eigen::Matrix<RealL, Eigen::Dynamic, 1>;

/// A block's coupling: for each of its contacts, the (column, A_kl) of the contacts it shares a
/// movable body with (itself included), columns in the block's numbering.
using SparseRows = std::vector<std::vector<std::pair<std::size_t, double>>>;

/// The minimum-norm solution of A x = b (A symmetric positive semi-definite, b in its range) by
/// conjugate gradients from x = 0, which stays in A's range: to a residual of 1e-15 of |b| (long
/// double), or after 10 n iterations. Every sum is order-free, so the answer is the same for any
/// numbering of the contacts.
VectorL conjugateGradients(const SparseRows& rows, const std::vector<std::size_t>& active,
                           const VectorL& b, WorkBound* work) {
  const std::size_t n = active.size();
  std::vector<long> slot(rows.size(), -1);
  for (std::size_t i = 0; i < n; ++i) slot[active[i]] = static_cast<long>(i);
  std::vector<RealL> terms;
  const auto dot = [&terms](const VectorL& x, const VectorL& y) {
    terms.clear();
    for (Eigen::Index i = 0; i < x.size(); ++i) terms.push_back(x[i] * y[i]);
    return orderFreeSum(terms);
  };
  const auto apply = [&](const VectorL& x) {
    VectorL y(static_cast<Eigen::Index>(n));
    for (std::size_t i = 0; i < n; ++i) {
      terms.clear();
      for (const auto& [column, value] : rows[active[i]]) {
        const long j = slot[column];
        if (j >= 0) terms.push_back(RealL(value) * x[j]);
      }
      y[static_cast<Eigen::Index>(i)] = orderFreeSum(terms);
    }
    return y;
  };
  VectorL x = VectorL::Zero(static_cast<Eigen::Index>(n));
  VectorL r = b;
  VectorL p = r;
  RealL rs = dot(r, r);
  const RealL goal = RealL(1e-15) * RealL(1e-15) * rs;
  for (std::size_t iteration = 0; iteration < 10 * n && rs > goal; ++iteration) {
    if (work != nullptr) {
      if (work->left() < n) {
        work->cut = true;
        break;
      }
      work->spent += n;
    }
    const VectorL ap = apply(p);
    const RealL curvature = dot(p, ap);
    if (!(curvature > 0)) break;
    const RealL alpha = rs / curvature;
    x += alpha * p;
    r -= alpha * ap;
    const RealL next = dot(r, r);
    p = r + (next / rs) * p;
    rs = next;
  }
  return x;
}

/// A block's impulses by the active set: solve for the contacts still active, drop the one that
/// would pull hardest, until none pulls. `rows` and `target` ((1 + e) (-d)) in the block's
/// numbering.
///
/// `work` (optional): where it runs out (work->cut), the answer is to be discarded.
std::vector<double> solveBlock(const SparseRows& rows, const std::vector<RealL>& target,
                               WorkBound* work) {
  const std::size_t count = rows.size();
  std::vector<bool> active(count, true);
  std::vector<double> impulses(count, 0.0);
  for (std::size_t iteration = 0; iteration < count; ++iteration) {
    std::vector<std::size_t> kept;
    for (std::size_t k = 0; k < count; ++k) {
      if (active[k]) kept.push_back(k);
    }
    const auto size = static_cast<Eigen::Index>(kept.size());
    VectorL right(size);
    for (Eigen::Index i = 0; i < size; ++i) right[i] = target[kept[static_cast<std::size_t>(i)]];
    Eigen::VectorXd solution;
    if (count <= kDenseBlockContacts) {
      if (work != nullptr) {
        const std::size_t cost = WorkBound::denseStep(kept.size());
        if (work->left() < cost) {
          work->cut = true;
          break;
        }
        work->spent += cost;
      }
      // Solved in long double (11 more bits) and rounded once: the impulses are the doubles
      // nearest the exact solution, so contacts that are mirror images of each other receive the
      // same impulse to the bit, whatever order the solver visits them in.
      std::vector<long> slot(count, -1);
      for (Eigen::Index i = 0; i < size; ++i) slot[kept[static_cast<std::size_t>(i)]] = i;
      MatrixL system = MatrixL::Zero(size, size);
      for (Eigen::Index i = 0; i < size; ++i) {
        for (const auto& [column, value] : rows[kept[static_cast<std::size_t>(i)]]) {
          if (slot[column] >= 0) system(i, slot[column]) = value;
        }
      }
      // Minimum-norm least squares: also right when two contacts are redundant (A singular).
      solution = system.completeOrthogonalDecomposition().solve(right).cast<double>();
    } else {
      solution = conjugateGradients(rows, kept, right, work).cast<double>();
      if (work != nullptr && work->cut) break;
    }
    std::fill(impulses.begin(), impulses.end(), 0.0);
    Eigen::Index most_negative = -1;
    for (Eigen::Index i = 0; i < size; ++i) {
      impulses[kept[static_cast<std::size_t>(i)]] = solution[i];
      if (solution[i] < 0 && (most_negative < 0 || solution[i] < solution[most_negative])) {
        most_negative = i;
      }
    }
    if (most_negative < 0) break;
    active[kept[static_cast<std::size_t>(most_negative)]] = false;
    impulses[kept[static_cast<std::size_t>(most_negative)]] = 0.0;
    if (kept.size() == 1) {
      std::fill(impulses.begin(), impulses.end(), 0.0);
      break;
    }
  }
  for (double& impulse : impulses) impulse = std::max(impulse, 0.0);
  return impulses;
}

}  // namespace

std::size_t WorkBound::left() const {
  return limit == 0 ? std::numeric_limits<std::size_t>::max() : limit - std::min(limit, spent);
}

std::vector<ContactOutcome> resolveSimultaneous(std::vector<ClusterBody>& bodies,
                                                const std::vector<ClusterContact>& contacts,
                                                WorkBound* work) {
  if (contacts.size() == 1) return resolveOne(bodies, contacts.front());

  const std::size_t count = contacts.size();
  Eigen::VectorXd approach(count);  // -d_k
  for (std::size_t k = 0; k < count; ++k) {
    approach[k] = -relativeNormalVelocity(bodies, contacts[k]);
  }
  // A_kl = sum over the bodies the two contacts share of w_i s_ik s_il n_k.n_l: nonzero only
  // where they share a movable body.
  std::vector<std::vector<std::size_t>> incident(bodies.size());
  for (std::size_t k = 0; k < count; ++k) {
    if (bodies[contacts[k].a].inverse_mass > 0) incident[contacts[k].a].push_back(k);
    if (bodies[contacts[k].b].inverse_mass > 0) incident[contacts[k].b].push_back(k);
  }
  const auto coupling = [&](std::size_t k, std::size_t l) {
    const double alignment = contacts[k].normal.dot(contacts[l].normal);
    double value = 0.0;
    const auto add = [&](std::size_t body_k, double sign_k, std::size_t body_l, double sign_l) {
      if (body_k == body_l) value += bodies[body_k].inverse_mass * sign_k * sign_l * alignment;
    };
    add(contacts[k].a, -1, contacts[l].a, -1);
    add(contacts[k].a, -1, contacts[l].b, +1);
    add(contacts[k].b, +1, contacts[l].a, -1);
    add(contacts[k].b, +1, contacts[l].b, +1);
    return value;
  };
  std::vector<std::vector<std::size_t>> neighbours(count);
  for (std::size_t k = 0; k < count; ++k) {
    for (const std::size_t body : {contacts[k].a, contacts[k].b}) {
      if (bodies[body].inverse_mass > 0) {
        neighbours[k].insert(neighbours[k].end(), incident[body].begin(), incident[body].end());
      }
    }
    std::sort(neighbours[k].begin(), neighbours[k].end());
    neighbours[k].erase(std::unique(neighbours[k].begin(), neighbours[k].end()),
                        neighbours[k].end());
  }
  // Blocks: contacts connected through shared movable bodies. Each is solved on its own (the
  // system is block-diagonal: exact).
  ConnectedSets connected(count);
  for (std::size_t k = 0; k < count; ++k) {
    for (const std::size_t l : neighbours[k]) connected.link(k, l);
  }
  Eigen::VectorXd impulses = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(count));
  std::vector<std::size_t> place(count);
  for (const std::vector<std::size_t>& block : connected.sets()) {
    for (std::size_t i = 0; i < block.size(); ++i) place[block[i]] = i;
    SparseRows rows(block.size());
    std::vector<RealL> target(block.size());
    for (std::size_t i = 0; i < block.size(); ++i) {
      const std::size_t k = block[i];
      target[i] = (1.0L + contacts[k].restitution) * approach[static_cast<Eigen::Index>(k)];
      for (const std::size_t l : neighbours[k]) rows[i].emplace_back(place[l], coupling(k, l));
    }
    const std::vector<double> solved = solveBlock(rows, target, work);
    if (work != nullptr && work->cut) return {};  // the bodies untouched
    for (std::size_t i = 0; i < block.size(); ++i) {
      impulses[static_cast<Eigen::Index>(block[i])] = solved[i];
    }
  }

  std::vector<ContactOutcome> outcomes(count);
  OrderFreeSum changes(bodies.size());
  for (std::size_t k = 0; k < count; ++k) {
    const ClusterContact& contact = contacts[k];
    const double impulse = impulses[static_cast<Eigen::Index>(k)];
    changes.add(contact.a, -(bodies[contact.a].inverse_mass * impulse * contact.normal));
    changes.add(contact.b, bodies[contact.b].inverse_mass * impulse * contact.normal);
    outcomes[k].impulse = impulse;
    outcomes[k].approach_speed = approach[static_cast<Eigen::Index>(k)];
    outcomes[k].energy_lost =
        0.5 * impulse * (1.0 - contact.restitution) * approach[static_cast<Eigen::Index>(k)];
  }
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    bodies[i].velocity = changes.total(i, bodies[i].velocity);
  }
  return outcomes;
}

Eigen::Vector3d OrderFreeSum::total(std::size_t body, const Eigen::Vector3d& start) const {
  Eigen::Vector3d sum = start;
  std::vector<double> terms;
  for (int c = 0; c < 3; ++c) {
    terms.clear();
    for (const Eigen::Vector3d& change : terms_[body]) terms.push_back(change[c]);
    sum[c] += orderFreeSum(terms);
  }
  return sum;
}

}  // namespace collision_response::core
