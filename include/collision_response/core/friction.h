// Coulomb friction at an impact, and the spheres' moments of inertia it turns.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/simultaneous.h"

namespace collision_response::core {

/// How a sphere's mass is spread: I = k m r^2, k = 2/5 (solid) or 2/3 (hollow, a thin shell).
enum class Inertia { kSolid, kHollow };
/// "solid" | "hollow" | "" (solid); anything else is an error naming `field`.
Expected<Inertia> parseInertia(const std::string& name, const std::string& field);
const char* toString(Inertia inertia);

/// 1/k of a sphere's I = k m r^2 (5/2 solid, 3/2 hollow), as ClusterBody::spin_factor; 0 for an
/// immovable body or a point (r = 0), which do not turn.
inline double spinFactor(double inverse_mass, double radius, Inertia inertia) {
  if (inverse_mass == 0.0 || radius == 0.0) return 0.0;
  return inertia == Inertia::kSolid ? 5.0 / 2.0 : 3.0 / 2.0;
}

struct FrictionOutcome {
  double impulse = 0.0;      ///< N s, >= 0, on b against the slip, on a along it
  bool sticking = false;     ///< the slip was stopped (the bound mu J_n allowed it)
  double energy_lost = 0.0;  ///< J, work of the friction impulse, >= 0
};

/// Coulomb friction at an impact whose normal impulse `normal_impulse` has been applied.
///
/// The slip is the tangential velocity of b's surface relative to a's at the contact point
/// (p_a + r_a n = p_b - r_b n): u = (v_b + w_b x (-r_b n)) - (v_a + w_a x (r_a n)),
/// u_t = u - (u.n) n. Stopping it takes J_stick = |u_t| / W_t, with the tangential inverse mass
/// W_t = w_a + w_b + r_a^2 / I_a + r_b^2 / I_b, where r^2 / I = w / k for a sphere (for a body
/// with an inertia tensor, t.K.t of its effective mass along the slip's direction t). The impulse
/// is J_t = min(J_stick, mu J_n): the contact sticks when the bound allows, slides otherwise. It
/// never exceeds mu J_n and never reverses the slip (J_t <= J_stick), so the work it does,
/// J_t (2 |u_t| - J_t W_t) / 2, is >= 0: friction never adds energy.
///
/// kSpin: with the spin effect the angular velocities enter the slip and receive the impulse's
/// moment (a ball with topspin kicks forward); without it bodies do not turn (no rotational
/// terms, angular velocities untouched). Defined, for both, in the solver room
/// (src/core/solver/cluster_solver.cpp), whose shared turn, slip and tangential inverse mass it
/// uses.
template <bool kSpin>
FrictionOutcome applyFriction(ClusterBody& a, ClusterBody& b, const ContactPoint& contact,
                              double friction, double normal_impulse);

/// What applyFriction needs of one contact of a cluster besides the bodies.
struct FrictionContact {
  double friction = 0.0;        ///< mu of the pair
  double normal_impulse = 0.0;  ///< N s, already applied
};

}  // namespace collision_response::core
