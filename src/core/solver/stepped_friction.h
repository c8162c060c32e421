// Coulomb friction over a stepped cluster's sub-step: every pressed contact's tangential impulse
// at once, from the impulses of the sub-step before, by sweeps over the contacts in the
// sub-step's canonical order (the order of their points).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "collision_response/core/simultaneous.h"

namespace collision_response::core {

/// What the sweeps need of one contact besides the bodies.
struct SweptFrictionContact {
  double bound = 0.0;  ///< N s: mu times the contact's normal impulse; 0: no friction
  /// N s, on b: the impulse to start from (the sub-step before's, for its duration); only its
  /// part perpendicular to the normal, within the bound, is used.
  Eigen::Vector3d warm = Eigen::Vector3d::Zero();
};

/// What one contact received.
struct SweptFrictionOutcome {
  Eigen::Vector3d impulse = Eigen::Vector3d::Zero();  ///< N s, on b (on a the opposite), tangential
  bool sticking = false;                              ///< within its bound: the slip stopped
};

/// How the sweeps ended.
struct SweptFrictionReport {
  int sweeps = 0;
  /// The last sweep changed no contact's slip by more than the tolerance.
  bool converged = false;
  /// The warm start would have added kinetic energy: the sweeps started from no impulse.
  bool cold = false;
};

/// Maximal dissipation over the discs |T_k| <= mu_k J_k: the tangential impulses T (on each
/// contact's b) that minimise the kinetic energy they leave, E(T) = T.s + T.A T / 2 (s the slips,
/// A the tangential coupling of contacts sharing a movable body), whose minimum is Coulomb's law
/// (a slip stopped inside its disc, the bound against the slip left on its edge).
///
/// Projected Gauss-Seidel (the sequential impulses of Catto, "Iterative Dynamics with Temporal
/// Coherence", GDC 2005, over the friction discs): contact by contact, the impulse that minimises
/// E with the others held, T_k <- P_k(T_k - u_k / D_k), u_k its slip now and P_k the projection
/// onto its disc. For spheres the tangential coupling of a contact with itself is isotropic,
/// D_k = w_a (1 + 1/k_a) + w_b (1 + 1/k_b) (1/k the spin factor, 0 without kSpin), so each step is
/// that contact's exact minimum and E never increases. It starts from the warm impulses where
/// they remove energy (E <= 0), else from none: whatever the sweeps reach, |T_k| <= mu_k J_k and
/// E <= 0, friction adds no energy. It stops when a sweep changes no slip by more than
/// `tolerance` (m/s), or after `max_sweeps`. The contacts are swept in the order given: the
/// caller's canonical order (no name or listing order of the bodies enters the answer).
///
/// Updates the bodies' velocities (and with kSpin their angular velocities); `outcomes` gets one
/// entry per contact.
template <bool kSpin>
SweptFrictionReport applyFrictionBySweeps(std::vector<ClusterBody>& bodies,
                                          const std::vector<ClusterContact>& contacts,
                                          const std::vector<SweptFrictionContact>& frictions,
                                          double tolerance, int max_sweeps,
                                          std::vector<SweptFrictionOutcome>& outcomes);

/// The sweeps as a stepped sub-step calls them, chosen once for the scene's effects.
using SweptFrictionStep = SweptFrictionReport (*)(std::vector<ClusterBody>&,
                                                  const std::vector<ClusterContact>&,
                                                  const std::vector<SweptFrictionContact>&, double,
                                                  int, std::vector<SweptFrictionOutcome>&);

}  // namespace collision_response::core
