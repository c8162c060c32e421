#include "solver/cluster_solver.h"

#include "collision_response/core/impact.h"
#include "solver/friction_impulses.h"
#include "solver/impulse_response.h"

namespace collision_response::core {

template <class Scalar>
Eigen::Matrix<Scalar, 3, 1> tensorTurnOf(const SolverBody& body, const Eigen::Vector3d& lever,
                                         const Eigen::Matrix<Scalar, 3, 1>& impulse) {
  return body.inverse_inertia.cast<Scalar>() * lever.cast<Scalar>().cross(impulse);
}

template Eigen::Vector3d tensorTurnOf<double>(const SolverBody&, const Eigen::Vector3d&,
                                              const Eigen::Vector3d&);
template Eigen::Matrix<long double, 3, 1> tensorTurnOf<long double>(
    const SolverBody&, const Eigen::Vector3d&, const Eigen::Matrix<long double, 3, 1>&);

Eigen::Vector3d turningSlip(const SolverBody& a, const SolverBody& b, const ContactPoint& contact) {
  return turningVelocity(b, -contact.normal, contact.lever_b) -
         turningVelocity(a, contact.normal, contact.lever_a);
}

double tensorTangentialInverseMass(const SolverBody& a, const SolverBody& b,
                                   const ContactPoint& contact, const Eigen::Vector3d& direction) {
  return inverseEffectiveMassAlong(contactSideOf(a, contact.lever_a),
                                   contactSideOf(b, contact.lever_b), direction);
}

namespace {

/// applyFriction's turn of one side by its impulse `impulse_on_body` (`impulse` along
/// `direction` on a, against it on b): a ball's dw = (1/I) (r n x J) = ((w/k) J / r) (n x t),
/// the velocity change w J first, then / r (on both sides: b's -J t acts at -r_b n); a body
/// given by its tensor: I^-1 (r x J) (turnOf).
template <SolveBodies kBodies>
void turnByFriction(ClusterBody& body, const Eigen::Vector3d& normal,
                    const Eigen::Vector3d& direction, double impulse, const Eigen::Vector3d& lever,
                    const Eigen::Vector3d& impulse_on_body) {
  if (kBodies == SolveBodies::kBalls || body.inertia_kind == InverseInertiaKind::kIsotropic) {
    if (body.spin_factor != 0.0) {
      body.angular_velocity +=
          (body.inverse_mass * impulse) * body.spin_factor / body.radius * normal.cross(direction);
    }
  } else if (turns(body)) {
    body.angular_velocity += tensorTurnOf<double>(body, lever, impulse_on_body);
  }
}

/// applyFriction for bodies that are `kBodies`.
template <bool kSpin, SolveBodies kBodies>
FrictionOutcome frictionAt(ClusterBody& a, ClusterBody& b, const ContactPoint& contact,
                           double friction, double normal_impulse) {
  FrictionOutcome outcome;
  const Eigen::Vector3d& normal = contact.normal;
  const Eigen::Vector3d tangential = slipAt<kSpin, kBodies>(a, b, contact);
  const double slip_speed = tangential.norm();
  if (!(slip_speed > 0) || !(normal_impulse > 0)) return outcome;
  const Eigen::Vector3d direction = tangential / slip_speed;
  const double tangential_inverse_mass =
      tangentialInverseMass<kSpin, kBodies>(a, b, contact, [&] { return direction; });
  if (!(tangential_inverse_mass > 0)) return outcome;
  const double sticking_impulse = slip_speed / tangential_inverse_mass;
  const double bound = friction * normal_impulse;
  outcome.sticking = sticking_impulse <= bound;
  outcome.impulse = std::min(sticking_impulse, bound);
  const Eigen::Vector3d impulse_on_a = outcome.impulse * direction;  // b gets -impulse_on_a
  a.velocity += a.inverse_mass * impulse_on_a;
  b.velocity -= b.inverse_mass * impulse_on_a;
  if constexpr (kSpin) {
    turnByFriction<kBodies>(a, normal, direction, outcome.impulse, contact.lever_a, impulse_on_a);
    turnByFriction<kBodies>(b, normal, direction, outcome.impulse, contact.lever_b, -impulse_on_a);
  }
  outcome.energy_lost =
      0.5 * outcome.impulse * (2 * slip_speed - outcome.impulse * tangential_inverse_mass);
  return outcome;
}

}  // namespace

template <bool kSpin>
FrictionOutcome applyFriction(ClusterBody& a, ClusterBody& b, const ContactPoint& contact,
                              double friction, double normal_impulse) {
  // Without spin no body turns: a body's kind does not matter.
  if (!kSpin || (a.inertia_kind == InverseInertiaKind::kIsotropic &&
                 b.inertia_kind == InverseInertiaKind::kIsotropic)) {
    return frictionAt<kSpin, SolveBodies::kBalls>(a, b, contact, friction, normal_impulse);
  }
  return frictionAt<kSpin, SolveBodies::kAny>(a, b, contact, friction, normal_impulse);
}

template FrictionOutcome applyFriction<true>(ClusterBody&, ClusterBody&, const ContactPoint&,
                                             double, double);
template FrictionOutcome applyFriction<false>(ClusterBody&, ClusterBody&, const ContactPoint&,
                                              double, double);

ContactResolution solveContact(ClusterBody& a, ClusterBody& b, const ClusterContact& contact,
                               double friction, const FrictionModel& friction_model) {
  const ImpactResponse<double> response = resolveImpact(
      a.inverse_mass, a.velocity, b.inverse_mass, b.velocity, contact.normal, contact.restitution);
  a.velocity = response.velocity_a;
  b.velocity = response.velocity_b;
  ContactResolution resolution;
  resolution.normal =
      ContactOutcome{response.normal_impulse, response.approach_speed, response.energy_lost};
  if (friction_model) {
    resolution.friction = friction_model.contact(a, b, contact, friction, response.normal_impulse);
  }
  return resolution;
}

template <bool kSpin>
void applyFrictionJointly(std::vector<ClusterBody>& bodies,
                          const std::vector<ClusterContact>& contacts,
                          const std::vector<FrictionContact>& frictions,
                          std::vector<FrictionOutcome>& outcomes, WorkBound* work) {
  std::vector<ForceBody> force_bodies;
  for (const ClusterBody& body : bodies) {
    ForceBody force_body{body};  // no free accelerations
    if constexpr (!kSpin) {      // bodies that do not turn: no rotational terms
      force_body.spin_factor = 0.0;
      force_body.angular_velocity = Eigen::Vector3d::Zero();
    }
    force_bodies.push_back(force_body);
  }
  std::vector<ForceContact> force_contacts;
  std::vector<double> normal_impulses;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    ForceContact contact{contacts[k]};
    contact.friction = frictions[k].friction;
    force_contacts.push_back(contact);
    normal_impulses.push_back(frictions[k].normal_impulse);
  }
  const ContactForceSolution solution =
      solveFrictionImpulses(force_bodies, force_contacts, normal_impulses, work);
  outcomes.assign(contacts.size(), FrictionOutcome{});
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const ContactForce& friction = solution.contacts[k];
    FrictionOutcome& outcome = outcomes[k];
    outcome.impulse = friction.tangential.norm();
    outcome.sticking = friction.mode == ContactMode::kSticking;
    // -T.(u + u') / 2 with u' = u + du (the slip after: du in slip_acceleration).
    outcome.energy_lost =
        -0.5 * friction.tangential.dot(2 * friction.slip + friction.slip_acceleration);
  }
  // The impulses' effects, from the impulses as doubles, summed free of the contacts' order: a
  // tangential impulse T on b (-T on a) changes b's velocity by w_b T and turns it by
  // -(w_b / (k_b r_b)) n x T; a by -w_a T and the same turn with a's values.
  OrderFreeSum velocity(bodies.size()), angular(bodies.size());
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const Eigen::Vector3d& impulse = solution.contacts[k].tangential;
    const Eigen::Vector3d& normal = contacts[k].normal;
    for (const auto& [index, sign] : {std::pair{contacts[k].a, -1.0}, {contacts[k].b, 1.0}}) {
      const ClusterBody& body = bodies[index];
      if (body.inverse_mass == 0.0) continue;
      velocity.add(index, sign * (body.inverse_mass * impulse));
      if (kSpin && turns(body)) {
        // T on b at r_b, -T on a at r_a: -(I^-1 (r' x T)), r' = r_a and -r_b along n.
        const auto lever = [&, sign = sign] {
          return sign < 0 ? contacts[k].lever_a : Eigen::Vector3d(-contacts[k].lever_b);
        };
        angular.add(index, -turnOf<double>(body, normal, lever, impulse));
      }
    }
  }
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    bodies[i].velocity = velocity.total(i, bodies[i].velocity);
    if constexpr (kSpin) bodies[i].angular_velocity = angular.total(i, bodies[i].angular_velocity);
  }
}

template void applyFrictionJointly<true>(std::vector<ClusterBody>&,
                                         const std::vector<ClusterContact>&,
                                         const std::vector<FrictionContact>&,
                                         std::vector<FrictionOutcome>&, WorkBound*);
template void applyFrictionJointly<false>(std::vector<ClusterBody>&,
                                          const std::vector<ClusterContact>&,
                                          const std::vector<FrictionContact>&,
                                          std::vector<FrictionOutcome>&, WorkBound*);

ClusterOutcome solveCluster(std::vector<ClusterBody>& bodies,
                            const std::vector<ClusterContact>& contacts,
                            const std::vector<double>& friction_coefficients,
                            const FrictionModel& friction_model, WorkBound* work) {
  ClusterOutcome outcome;
  if (contacts.size() == 1) {
    const ClusterContact& contact = contacts.front();
    const ContactResolution resolution =
        solveContact(bodies[contact.a], bodies[contact.b], contact,
                     friction_model ? friction_coefficients.front() : 0.0, friction_model);
    outcome.normal.assign(1, resolution.normal);
    outcome.friction.assign(1, resolution.friction);
    return outcome;
  }
  outcome.normal = resolveSimultaneous(bodies, contacts, work);
  if (outcome.normal.empty()) return outcome;  // its work ran out: the bodies as they were
  outcome.friction.assign(contacts.size(), FrictionOutcome{});
  if (friction_model) {
    std::vector<FrictionContact> frictions(contacts.size());
    for (std::size_t c = 0; c < contacts.size(); ++c) {
      frictions[c] = FrictionContact{friction_coefficients[c], outcome.normal[c].impulse};
    }
    friction_model.cluster(bodies, contacts, frictions, outcome.friction, work);
  }
  return outcome;
}

}  // namespace collision_response::core
