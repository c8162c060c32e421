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

/// 1/I of a sphere: 1 / (k m r^2) = w / (k r^2); 0 for an immovable body or a point (r = 0).
inline double inverseInertia(double inverse_mass, double radius, Inertia inertia) {
  if (inverse_mass == 0.0 || radius == 0.0) return 0.0;
  const double k = inertia == Inertia::kSolid ? 2.0 / 5.0 : 2.0 / 3.0;
  return inverse_mass / (k * radius * radius);
}

struct FrictionOutcome {
  double impulse = 0.0;      ///< N s, >= 0, on b against the slip, on a along it
  bool sticking = false;     ///< the slip was stopped (the bound mu J_n allowed it)
  double energy_lost = 0.0;  ///< J, work of the friction impulse, >= 0
};

/// Coulomb friction at an impact whose normal impulse `normal_impulse` has been applied.
///
/// The slip is the tangential velocity of b's surface relative to a's at the contact point
/// (p_a + arm_a n = p_b - arm_b n): u = (v_b + w_b x (-arm_b n)) - (v_a + w_a x (arm_a n)),
/// u_t = u - (u.n) n. Stopping it takes J_stick = |u_t| / W_t, with the tangential inverse mass
/// W_t = w_a + w_b + arm_a^2 / I_a + arm_b^2 / I_b (for a sphere r^2 / I = 1 / (k m)). The impulse
/// is J_t = min(J_stick, mu J_n): the contact sticks when the bound allows, slides otherwise. It
/// never exceeds mu J_n and never reverses the slip (J_t <= J_stick), so the work it does,
/// J_t (2 |u_t| - J_t W_t) / 2, is >= 0: friction never adds energy.
///
/// kSpin: with the spin effect the angular velocities enter the slip and receive the impulse's
/// moment (a ball with topspin kicks forward); without it bodies do not turn (no rotational
/// terms, angular velocities untouched).
template <bool kSpin>
FrictionOutcome applyFriction(ClusterBody& a, ClusterBody& b, const Eigen::Vector3d& normal,
                              double arm_a, double arm_b, double friction, double normal_impulse) {
  FrictionOutcome outcome;
  Eigen::Vector3d slip = b.velocity - a.velocity;
  double tangential_inverse_mass = a.inverse_mass + b.inverse_mass;
  if constexpr (kSpin) {
    slip += b.angular_velocity.cross(-arm_b * normal) - a.angular_velocity.cross(arm_a * normal);
    tangential_inverse_mass +=
        arm_a * arm_a * a.inverse_inertia + arm_b * arm_b * b.inverse_inertia;
  }
  const Eigen::Vector3d tangential = slip - slip.dot(normal) * normal;
  const double slip_speed = tangential.norm();
  if (!(slip_speed > 0) || !(tangential_inverse_mass > 0) || !(normal_impulse > 0)) {
    return outcome;
  }
  const Eigen::Vector3d direction = tangential / slip_speed;
  const double sticking_impulse = slip_speed / tangential_inverse_mass;
  const double bound = friction * normal_impulse;
  outcome.sticking = sticking_impulse <= bound;
  outcome.impulse = std::min(sticking_impulse, bound);
  const Eigen::Vector3d impulse_on_a = outcome.impulse * direction;  // b gets -impulse_on_a
  a.velocity += a.inverse_mass * impulse_on_a;
  b.velocity -= b.inverse_mass * impulse_on_a;
  if constexpr (kSpin) {
    a.angular_velocity += a.inverse_inertia * (arm_a * normal).cross(impulse_on_a);
    b.angular_velocity += b.inverse_inertia * (-arm_b * normal).cross(-impulse_on_a);
  }
  outcome.energy_lost =
      0.5 * outcome.impulse * (2 * slip_speed - outcome.impulse * tangential_inverse_mass);
  return outcome;
}

/// What applyFriction needs of one contact of a cluster besides the bodies.
struct FrictionContact {
  double arm_a = 0.0;           ///< m, from a's centre to the contact along the normal
  double arm_b = 0.0;           ///< m, from b's centre to the contact against the normal
  double friction = 0.0;        ///< mu of the pair
  double normal_impulse = 0.0;  ///< N s, already applied
};

/// applyFriction on every contact of a cluster, in the cluster's (canonical) order, each with
/// the velocities the previous ones left.
template <bool kSpin>
void applyFrictionToCluster(std::vector<ClusterBody>& bodies,
                            const std::vector<ClusterContact>& contacts,
                            const std::vector<FrictionContact>& frictions,
                            std::vector<FrictionOutcome>& outcomes) {
  outcomes.assign(contacts.size(), FrictionOutcome{});
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    outcomes[k] = applyFriction<kSpin>(bodies[contacts[k].a], bodies[contacts[k].b],
                                       contacts[k].normal, frictions[k].arm_a, frictions[k].arm_b,
                                       frictions[k].friction, frictions[k].normal_impulse);
  }
}
using ClusterFrictionStep = void (*)(std::vector<ClusterBody>&, const std::vector<ClusterContact>&,
                                     const std::vector<FrictionContact>&,
                                     std::vector<FrictionOutcome>&);

}  // namespace collision_response::core
