#include "solver/stepped_friction.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace collision_response::core {
namespace {

/// b's surface relative to a's at the contact, perpendicular to the normal: the slip (friction.h).
template <bool kSpin>
Eigen::Vector3d slipOf(const std::vector<ClusterBody>& bodies, const ClusterContact& contact) {
  const ClusterBody& a = bodies[contact.a];
  const ClusterBody& b = bodies[contact.b];
  Eigen::Vector3d slip = b.velocity - a.velocity;
  if constexpr (kSpin) {
    slip += b.angular_velocity.cross(-b.radius * contact.normal) -
            a.angular_velocity.cross(a.radius * contact.normal);
  }
  return slip - slip.dot(contact.normal) * contact.normal;
}

/// A tangential impulse `impulse` on b (-impulse on a) applied to the bodies: b's velocity by
/// w_b T, a's by -w_a T, and (kSpin) each turned by -(w / (k r)) n x T (friction.h).
template <bool kSpin>
void applyImpulse(std::vector<ClusterBody>& bodies, const ClusterContact& contact,
                  const Eigen::Vector3d& impulse) {
  for (const auto& [index, sign] : {std::pair{contact.a, -1.0}, {contact.b, 1.0}}) {
    ClusterBody& body = bodies[index];
    if (body.inverse_mass == 0.0) continue;
    body.velocity += sign * (body.inverse_mass * impulse);
    if constexpr (kSpin) {
      if (body.spin_factor != 0.0) {
        body.angular_velocity -=
            (body.inverse_mass * body.spin_factor / body.radius) * contact.normal.cross(impulse);
      }
    }
  }
}

/// `impulse` within the disc of radius `bound`.
Eigen::Vector3d withinDisc(const Eigen::Vector3d& impulse, double bound) {
  const double length = impulse.norm();
  return length > bound ? Eigen::Vector3d(impulse * (bound / length)) : impulse;
}

}  // namespace

template <bool kSpin>
SweptFrictionReport applyFrictionBySweeps(std::vector<ClusterBody>& bodies,
                                          const std::vector<ClusterContact>& contacts,
                                          const std::vector<SweptFrictionContact>& frictions,
                                          double tolerance, int max_sweeps,
                                          std::vector<SweptFrictionOutcome>& outcomes) {
  const std::size_t count = contacts.size();
  SweptFrictionReport report;
  outcomes.assign(count, SweptFrictionOutcome{});
  // Each contact's D_k (0: it takes no friction).
  std::vector<double> coupling(count, 0.0);
  for (std::size_t k = 0; k < count; ++k) {
    const ClusterBody& a = bodies[contacts[k].a];
    const ClusterBody& b = bodies[contacts[k].b];
    double d = a.inverse_mass + b.inverse_mass;
    if constexpr (kSpin) d += a.inverse_mass * a.spin_factor + b.inverse_mass * b.spin_factor;
    if (frictions[k].bound > 0 && d > 0) coupling[k] = d;
  }
  // The warm start, kept where it removes energy: E(T) = T.(s + s') / 2, s and s' the slips
  // before and after it.
  const std::vector<ClusterBody> before = bodies;
  std::vector<Eigen::Vector3d> slip_before(count);
  for (std::size_t k = 0; k < count; ++k) {
    if (coupling[k] == 0.0) continue;
    const Eigen::Vector3d& n = contacts[k].normal;
    const Eigen::Vector3d& warm = frictions[k].warm;
    outcomes[k].impulse = withinDisc(warm - warm.dot(n) * n, frictions[k].bound);
    slip_before[k] = slipOf<kSpin>(bodies, contacts[k]);
  }
  for (std::size_t k = 0; k < count; ++k) {
    if (coupling[k] != 0.0) applyImpulse<kSpin>(bodies, contacts[k], outcomes[k].impulse);
  }
  double energy = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    if (coupling[k] == 0.0) continue;
    energy += 0.5 * outcomes[k].impulse.dot(slip_before[k] + slipOf<kSpin>(bodies, contacts[k]));
  }
  if (!(energy <= 0)) {
    bodies = before;
    for (SweptFrictionOutcome& outcome : outcomes) outcome.impulse.setZero();
    report.cold = true;
  }
  // The sweeps: each contact's exact minimum with the others held.
  for (; report.sweeps < max_sweeps && !report.converged; ++report.sweeps) {
    double largest = 0.0;
    for (std::size_t k = 0; k < count; ++k) {
      if (coupling[k] == 0.0) continue;
      Eigen::Vector3d& impulse = outcomes[k].impulse;
      const Eigen::Vector3d slip = slipOf<kSpin>(bodies, contacts[k]);
      const Eigen::Vector3d next = withinDisc(impulse - slip / coupling[k], frictions[k].bound);
      const Eigen::Vector3d change = next - impulse;
      if (change.isZero(0.0)) continue;
      applyImpulse<kSpin>(bodies, contacts[k], change);
      impulse = next;
      largest = std::max(largest, coupling[k] * change.norm());
    }
    report.converged = largest <= tolerance;
  }
  for (std::size_t k = 0; k < count; ++k) {
    outcomes[k].sticking =
        coupling[k] != 0.0 && outcomes[k].impulse.norm() < frictions[k].bound * (1 - 1e-9);
  }
  return report;
}

template SweptFrictionReport applyFrictionBySweeps<true>(std::vector<ClusterBody>&,
                                                         const std::vector<ClusterContact>&,
                                                         const std::vector<SweptFrictionContact>&,
                                                         double, int,
                                                         std::vector<SweptFrictionOutcome>&);
template SweptFrictionReport applyFrictionBySweeps<false>(std::vector<ClusterBody>&,
                                                          const std::vector<ClusterContact>&,
                                                          const std::vector<SweptFrictionContact>&,
                                                          double, int,
                                                          std::vector<SweptFrictionOutcome>&);

}  // namespace collision_response::core
