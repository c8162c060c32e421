#include "solver/stepped_friction.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>

#include "solver/impulse_response.h"

namespace collision_response::core {
namespace {

/// b's surface relative to a's at the contact, perpendicular to the normal: the slip
/// (impulse_response.h).
template <bool kSpin, SolveBodies kBodies>
Eigen::Vector3d slipOf(const std::vector<ClusterBody>& bodies, const ClusterContact& contact) {
  return slipAt<kSpin, kBodies>(bodies[contact.a], bodies[contact.b], contact);
}

/// A tangential impulse `impulse` on b (-impulse on a) applied to the bodies: b's velocity by
/// w_b T, a's by -w_a T, and (kSpin) each turned by I^-1 (r_b x T), I^-1 (r_a x -T), which is
/// -(I^-1 (r' x T)) with r' = r_a and -r_b along n: for a ball -(w / (k r)) n x T (turnOf).
template <bool kSpin, SolveBodies kBodies>
void applyImpulse(std::vector<ClusterBody>& bodies, const ClusterContact& contact,
                  const Eigen::Vector3d& impulse) {
  for (const auto& [index, sign] : {std::pair{contact.a, -1.0}, {contact.b, 1.0}}) {
    ClusterBody& body = bodies[index];
    if (body.inverse_mass == 0.0) continue;
    body.velocity += sign * (body.inverse_mass * impulse);
    if constexpr (kSpin) {
      if (turns<kBodies>(body)) {
        const auto lever = [&, sign = sign] {
          return sign < 0 ? contact.lever_a : Eigen::Vector3d(-contact.lever_b);
        };
        body.angular_velocity -= turnOf<double, kBodies>(body, contact.normal, lever, impulse);
      }
    }
  }
}

/// `impulse` within the disc of radius `bound`.
Eigen::Vector3d withinDisc(const Eigen::Vector3d& impulse, double bound) {
  const double length = impulse.norm();
  return length > bound ? Eigen::Vector3d(impulse * (bound / length)) : impulse;
}

/// applyFrictionBySweeps for bodies that are `kBodies`.
template <bool kSpin, SolveBodies kBodies>
SweptFrictionReport frictionBySweeps(std::vector<ClusterBody>& bodies,
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
    // A ball's coupling is the same along every tangent; a shaped body's is not (a 2 x 2 block:
    // not yet, every stepped body is a ball), here along one of them.
    const double d = tangentialInverseMass<kSpin, kBodies>(
        bodies[contacts[k].a], bodies[contacts[k].b], contacts[k],
        [&] { return contacts[k].normal.unitOrthogonal(); });
    if (frictions[k].bound > 0 && d > 0) coupling[k] = d;
  }
  // The warm start, kept where it removes energy: E(T) = T.(s + s') / 2, s and s' the slips
  // before and after it (the velocities before it kept, the only part of a body it changes).
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> before(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    before[i] = {bodies[i].velocity, bodies[i].angular_velocity};
  }
  std::vector<Eigen::Vector3d> slip_before(count);
  for (std::size_t k = 0; k < count; ++k) {
    if (coupling[k] == 0.0) continue;
    const Eigen::Vector3d& n = contacts[k].normal;
    const Eigen::Vector3d& warm = frictions[k].warm;
    outcomes[k].impulse = withinDisc(warm - warm.dot(n) * n, frictions[k].bound);
    slip_before[k] = slipOf<kSpin, kBodies>(bodies, contacts[k]);
  }
  for (std::size_t k = 0; k < count; ++k) {
    if (coupling[k] != 0.0) applyImpulse<kSpin, kBodies>(bodies, contacts[k], outcomes[k].impulse);
  }
  double energy = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    if (coupling[k] == 0.0) continue;
    energy +=
        0.5 * outcomes[k].impulse.dot(slip_before[k] + slipOf<kSpin, kBodies>(bodies, contacts[k]));
  }
  if (!(energy <= 0)) {
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      bodies[i].velocity = before[i].first;
      bodies[i].angular_velocity = before[i].second;
    }
    for (SweptFrictionOutcome& outcome : outcomes) outcome.impulse.setZero();
    report.cold = true;
  }
  // The sweeps: each contact's exact minimum with the others held.
  for (; report.sweeps < max_sweeps && !report.converged; ++report.sweeps) {
    double largest = 0.0;
    for (std::size_t k = 0; k < count; ++k) {
      if (coupling[k] == 0.0) continue;
      Eigen::Vector3d& impulse = outcomes[k].impulse;
      const Eigen::Vector3d slip = slipOf<kSpin, kBodies>(bodies, contacts[k]);
      const Eigen::Vector3d next = withinDisc(impulse - slip / coupling[k], frictions[k].bound);
      const Eigen::Vector3d change = next - impulse;
      if (change.isZero(0.0)) continue;
      applyImpulse<kSpin, kBodies>(bodies, contacts[k], change);
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

}  // namespace

template <bool kSpin>
SweptFrictionReport applyFrictionBySweeps(std::vector<ClusterBody>& bodies,
                                          const std::vector<ClusterContact>& contacts,
                                          const std::vector<SweptFrictionContact>& frictions,
                                          double tolerance, int max_sweeps,
                                          std::vector<SweptFrictionOutcome>& outcomes) {
  if (allBalls(bodies)) {
    return frictionBySweeps<kSpin, SolveBodies::kBalls>(bodies, contacts, frictions, tolerance,
                                                        max_sweeps, outcomes);
  }
  return frictionBySweeps<kSpin, SolveBodies::kAny>(bodies, contacts, frictions, tolerance,
                                                    max_sweeps, outcomes);
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
