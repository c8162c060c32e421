#include "collision_response/core/cluster_solver.h"

#include "collision_response/core/impact.h"

namespace collision_response::core {

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
    resolution.friction =
        friction_model.contact(a, b, contact.normal, friction, response.normal_impulse);
  }
  return resolution;
}

ClusterOutcome solveCluster(std::vector<ClusterBody>& bodies,
                            const std::vector<ClusterContact>& contacts,
                            const std::vector<double>& friction_coefficients,
                            const FrictionModel& friction_model) {
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
  outcome.normal = resolveSimultaneous(bodies, contacts);
  outcome.friction.assign(contacts.size(), FrictionOutcome{});
  if (friction_model) {
    std::vector<FrictionContact> frictions(contacts.size());
    for (std::size_t c = 0; c < contacts.size(); ++c) {
      frictions[c] = FrictionContact{friction_coefficients[c], outcome.normal[c].impulse};
    }
    friction_model.cluster(bodies, contacts, frictions, outcome.friction);
  }
  return outcome;
}

}  // namespace collision_response::core
