// One impact of two rigid bodies with rotation, exact, never gaining energy (issue 42, build
// step 3): one contact with Chatterjee and Ruina's law (frictionless: Newton's e along the normal
// with the effective mass), and several contacts of shaped bodies at one instant by Newton's
// joint rule with the lever arms (frictionless). Balls keep today's code, bit for bit.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/simultaneous.h"
#include "collision_response/core/solver_body.h"

namespace collision_response::core {

/// What one impact did.
struct RigidImpactOutcome {
  Eigen::Vector3d impulse = Eigen::Vector3d::Zero();  ///< N s, on b at the contact; -impulse on a
  double normal_impulse = 0.0;                        ///< N s, impulse.n, >= 0
  Eigen::Vector3d tangential_impulse = Eigen::Vector3d::Zero();  ///< N s, impulse - (impulse.n) n
  double approach_speed = 0.0;  ///< m/s, -u.n before (u: b's contact point relative to a's)
  /// The impulse lies inside the friction cone (kappa = 1 + e_t below): the contact did not
  /// slide. Balls: applyFriction's sticking, or no slip to stop.
  bool sticking = false;
  double energy_lost = 0.0;  ///< J, >= 0
};

/// Resolves one impact of `a` and `b` at `contact` (normal a -> b, lever arms r_a, r_b from each
/// centre of mass to the contact point), updating their velocities and angular velocities. No
/// impulse where the contact points do not approach (u.n >= 0).
///
/// Two balls (both kIsotropic) and e_t = 0: today's code, bit for bit: resolveImpact (impact.h)
/// along the normal, then, where mu > 0, Coulomb friction with the spin effect
/// (applyFriction<true>, friction.h) on the slip left after it, as a single contact of the
/// monitor's clusters is resolved (cluster_solver.cpp, solveContact). Every other pair:
/// resolveRigidImpactByLaw.
///
/// Bad input, named: restitution outside [0, 1], friction < 0 or not finite, tangential
/// restitution outside [-1, 1], a normal not finite or not of unit length (to 1e-9), a lever arm,
/// velocity or angular velocity not finite, an inverse mass < 0 or not finite, both sides
/// immovable, an inverse inertia tensor not finite or with a negative diagonal entry, a ball's
/// spin factor or radius < 0 or not finite. Whether a tensor is positive definite is
/// checkInertiaTensor's (mass_properties.h), where a user gives it. An answer beyond the range of
/// double is refused naming its first output (validation.h, kBeyondDoubles), the bodies left as
/// they were: K is formed in double, so a lever arm whose |r|^2 I^-1 passes ~1e308 is refused so.
Expected<RigidImpactOutcome> resolveRigidImpact(SolverBody& a, SolverBody& b,
                                                const ContactPoint& contact, double restitution,
                                                double friction,
                                                double tangential_restitution = 0.0);

/// Chatterjee and Ruina's algebraic law ("A new algebraic rigid-body collision law based on
/// impulse space considerations", J. Appl. Mech. 65:939-951, 1998),
/// for any two bodies, balls included (resolveRigidImpact uses it for every pair but two balls).
/// With K the contact's inverse effective mass (effective_mass.h) and u0 the contact points'
/// relative velocity before (u_n = u0.n < 0):
///
///   P_I  = (-u_n / n.K.n) n          the frictionless, perfectly plastic impulse;
///   P_II = K^-1 (-u0)                the sticking, perfectly plastic impulse; D = P_II - P_I;
///   P^   = (1 + e) P_I + (1 + e_t) D,
///
/// P = P^ where it lies inside the friction cone |P_t| <= mu P_n (sticking); otherwise
/// P = (1 + e) P_I + kappa D with kappa = mu (1 + e) |P_I| / (|D_t| - mu D.n), on the cone.
/// e_t is the tangential restitution, 0 here by default (the sticking impulse once: no tangential
/// rebound).
///
/// What it guarantees, exactly (not only for these tests):
/// - Newton's e along the normal whatever mu: n.K.D = n.(-u0) - n.K.P_I = 0, so
///   u'.n = u_n + (1 + e) P_I.K.n = -e u_n. With mu = 0 it is the frictionless impact, P =
///   (1 + e) m_eff (-u_n) n with m_eff = 1 / n.K.n, losing (1/2) m_eff (1 - e^2) u_n^2.
/// - It never gains energy for e in [0, 1], e_t in [-1, 1], mu >= 0: the energy changes by
///   P.u0 + P.K.P / 2 = -(1 - e^2) P_I.K.P_I / 2 - kappa (2 - kappa) D.K.D / 2 (P_I and D are
///   K-orthogonal), and 0 <= kappa <= 1 + e_t <= 2 (the cone is reached before P^). energy_lost
///   is this closed form, each term >= 0.
/// - Coulomb's cone |P_t| <= mu P_n, P_n >= 0; angular momentum about the contact point is
///   conserved for each body (its impulse acts there).
/// - Balls (K block-diagonal: r along n): P_I the normal impulse of resolveImpact, D the
///   sticking impulse of applyFriction, so P is today's answer (to rounding; the tests: a few
///   ulps).
/// A reading of the law that splits the sticking impulse (P_hat = (1 + e) P_II,n n + P_II,t)
/// instead of P_I and D gains energy where K couples the normal and the slip (a rod on its end):
/// test/exact/rigid_impact.py finds such cases and none for this one.
///
/// Computed in long double from K (double) and rounded once into the bodies. Not checked here
/// (resolveRigidImpact checks).
RigidImpactOutcome resolveRigidImpactByLaw(SolverBody& a, SolverBody& b,
                                           const ContactPoint& contact, double restitution,
                                           double friction, double tangential_restitution);

/// Resolves contacts of shaped bodies that all strike at one instant (a box landing flat touches
/// the floor at four corners), frictionless, updating the bodies' velocities and angular
/// velocities; outcomes in the order of `contacts`. With friction: resolveRigidSimultaneous
/// taking the contacts' coefficients, below.
///
/// The rule: Newton's joint rule of resolveSimultaneous (simultaneous.h) with the lever arms:
/// impulses J_k >= 0 such that every contact that receives one leaves with d_k' = -e_k d_k, d_k
/// the contact points' relative normal velocity, A J = (1 + e) (-d) with the Delassus matrix
/// A_kl = sum over the bodies i that contacts k and l share of s_ik s_il n_k.K_i(r_ik, r_il).n_l
/// = s_ik s_il (w_i n_k.n_l + (r_ik x n_k).I_i^-1 (r_il x n_l)) (s = +1 on b, -1 on a); a
/// contact that would pull is dropped and the rest solved again. Independent of the order of the
/// contacts: they are put in one canonical order first (by point, then normal, lever arms,
/// bodies and e), A is solved in long double by a complete orthogonal decomposition (A is
/// singular for four coplanar corners: the least-norm impulses, which give the only velocities
/// the rule allows), the impulses rounded to doubles and each body's changes summed order-free.
/// The energy changes by -sum_k J_k (1 - e_k)(-d_k) / 2 <= 0. A box of e = 1 landing flat
/// leaves at -v without spin; with any e in [0, 1] it loses (1/2) m (1 - e^2) v^2.
///
/// All bodies balls (kIsotropic): resolveSimultaneous itself, bit for bit.
///
/// Bad input, named (contacts[k].field, bodies[i].field): as resolveRigidImpact, and a contact's
/// body index out of range or both sides one body.
Expected<std::vector<ContactOutcome>> resolveRigidSimultaneous(
    std::vector<SolverBody>& bodies, const std::vector<ClusterContact>& contacts);

/// One contact's share of a frictional joint impact.
struct FrictionalOutcome {
  /// The impulse's part along the normal; its energy_lost (1 - e^2) J_k (-d_k) / 2, J_k the
  /// plastic frictionless impulse.
  ContactOutcome normal;
  double friction_impulse = 0.0;      ///< N s, the part across the normal, <= mu times the normal
  double friction_energy_lost = 0.0;  ///< J, >= 0 in sum: the law's kappa (2 - kappa) D.A.D / 2
  /// The law did not apply and the frictionless joint rule was taken (friction left out).
  bool frictionless_rule = false;
};

/// Contacts that all strike at one instant, each with Coulomb's coefficient `friction[k]` >= 0
/// (doc/model.md, "One impact of a shaped body"): Chatterjee and Ruina's law over all of them at
/// once, normal and tangential impulses together. With A the contacts' full Delassus matrix (3x3
/// blocks s_i s_j (w - [r_i]x I^-1 [r_j]x) summed over the bodies two contacts share) and u the
/// contact points' relative velocities:
///
///   P_I  the plastic frictionless joint impulses (the joint rule above with e = 0), J_k n_k;
///   P_II the least-norm sticking impulses of the contacts P_I presses: A P_II = -u there;
///   D = P_II - P_I;  P = (1 + e) P_I + kappa D,
///
/// kappa the largest in [0, 1] that keeps every contact's impulse in its cone
/// (kappa |D_t,k| <= mu_k ((1 + e) J_k + kappa D_k.n_k)). What it guarantees, as the law for one
/// contact: A D has no part along the normals the plastic impulses press (P_I.A.D = 0), so each of
/// them leaves at -e times its approach whatever mu, and the energy changes by
/// -(1 - e^2) P_I.A.P_I / 2 - kappa (2 - kappa) D.A.D / 2 <= 0; each impulse is in its cone. One
/// contact: Chatterjee and Ruina's law itself (to 1e-12). The sticking impulses hold the moment
/// of the friction about the body by shifting normal impulse forward, so a box landing flat while
/// it slides at u (half length a ahead of its centre, c above its face) leaves without turning at
/// u (1 - kappa), kappa = mu (1 + e) v_n / (u (1 + mu c / a)) where its rear corners' cones bind.
/// One kappa for all: the first cone reached sets how much of the sticking impulse is taken
/// everywhere (a documented choice: it keeps the energy's closed form). In the canonical order of
/// the contacts (the same bits in any order). The frictionless joint rule is taken (each
/// outcome's frictionless_rule) where the law does not apply: the contacts' e differ, no impulse
/// stops every slip (a moving obstacle's points no twist of the body follows), or a contact the
/// plastic impulses leave apart would approach after P. All coefficients 0: the frictionless
/// rule itself. Bad input as resolveRigidSimultaneous, and `friction` of another length or a
/// coefficient not finite or < 0.
Expected<std::vector<FrictionalOutcome>> resolveRigidSimultaneous(
    std::vector<SolverBody>& bodies, const std::vector<ClusterContact>& contacts,
    const std::vector<double>& friction);

}  // namespace collision_response::core
