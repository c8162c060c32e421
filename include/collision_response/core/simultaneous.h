// Impacts that strike at one instant and share bodies (a cluster): one joint solve, so that the
// answer depends on the contacts, not on the order anybody lists them.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "collision_response/core/solver_body.h"

namespace collision_response::core {

/// A body of the cluster: inverse mass (0: immovable, an obstacle), velocity (updated) and, for
/// friction and spin, angular velocity and inverse inertia (solver_body.h).
using ClusterBody = SolverBody;

/// Sums each body's velocity changes from several contacts in an order that does not depend on
/// the order of the contacts: each component's positive terms are added smallest first, its
/// negative ones smallest in magnitude first, then the two sums, so that listing the contacts in
/// another order gives the same bits, a mirror image of a cluster the mirrored bits, and mirror
/// images cancel exactly where they should (+x and -x add to 0).
class OrderFreeSum {
 public:
  explicit OrderFreeSum(std::size_t bodies) : terms_(bodies) {}
  void add(std::size_t body, const Eigen::Vector3d& change) { terms_[body].push_back(change); }
  /// `start` plus the changes of `body`.
  Eigen::Vector3d total(std::size_t body, const Eigen::Vector3d& start) const;

 private:
  std::vector<std::vector<Eigen::Vector3d>> terms_;
};

/// A contact of the cluster between bodies `a` and `b` (indices into the cluster's bodies).
struct ClusterContact : ContactPoint {
  double restitution = 0.0;  ///< the coefficient this contact uses
};

/// What one contact of the cluster received.
struct ContactOutcome {
  double impulse = 0.0;         ///< N s, >= 0, on b along the normal, on a against it
  double approach_speed = 0.0;  ///< m/s, -(v_b - v_a).n before
  double energy_lost = 0.0;     ///< J, this contact's share: J (1 - e)(-d) / 2
};

/// What a joint solve of an impact cluster may spend, and spent, in contact iterations
/// (MonitorSettings::max_impact_work_per_step): a block of n contacts solved iteratively counts
/// n an iteration, one solved densely 1 + n^2 / 4 + n^3 / 400 a factorisation (what such a
/// factorisation takes in the time of an iteration's contact: doc/performance.md).
struct WorkBound {
  std::size_t limit = 0;  ///< at most this much; 0: no limit
  std::size_t spent = 0;  ///< added to by each solve
  bool cut = false;       ///< a solve stopped at the limit
  /// What is left of the limit (the largest size_t without one).
  std::size_t left() const;
  /// The cost of a dense factorisation of n contacts.
  static std::size_t denseStep(std::size_t n) { return 1 + n * n / 4 + n * n * n / 400; }
};

/// Resolves contacts that all strike at one instant, updating the bodies' velocities.
///
/// Model (Newton's restitution on every contact at once): find impulses J >= 0 such that every
/// contact that receives one leaves with d_k' = -e_k d_k, where d_k = (v_b - v_a).n_k. With
/// v_i' = v_i + w_i sum_k s_ik J_k n_k (s_ik = +1 for b, -1 for a), this is the linear system
/// A J = -(1 + e) d, A_kl = sum_i w_i s_ik s_il n_k.n_l. A contact whose solution would pull
/// (J_k < 0) is dropped and the rest solved again (an active set), so no contact adhesion. The
/// kinetic energy changes by sum_k J_k (d_k + d_k') / 2 = -sum_k J_k (1 - e_k)(-d_k) / 2 <= 0.
/// One contact alone is resolved by resolveImpact, exact to the last bit.
///
/// Two balls striking a third from both sides at once receive equal impulses; a chain struck at
/// one end (a cradle) is not solved here at once: the caller resolves, in rounds, only the
/// contacts that approach, so the impact travels down the chain ball by ball.
///
/// `work` (optional) bounds and counts the solve's work: where its next iteration would pass the
/// limit, the solve stops, `work->cut` is set, the bodies are left as they were and the answer
/// is empty (the caller resolves the cluster otherwise).
std::vector<ContactOutcome> resolveSimultaneous(std::vector<ClusterBody>& bodies,
                                                const std::vector<ClusterContact>& contacts,
                                                WorkBound* work = nullptr);

}  // namespace collision_response::core
