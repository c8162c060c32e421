#include "collision_response/core/collision.h"

#include <cmath>

#include "collision_response/core/friction.h"
#include "collision_response/core/scene.h"
#include "collision_response/core/validation.h"
#include "solver/cluster_solver.h"

namespace collision_response::core {
namespace {

Expected<double> chooseRestitution(const CollisionRequest& request,
                                   const MaterialTable& materials) {
  const bool a_named = !request.a.material.empty();
  const bool b_named = !request.b.material.empty();
  if (a_named && b_named) {
    const auto pair =
        materials.restitution(request.a.material, request.b.material, "a.material", "b.material");
    if (!pair) return pair;
    if (request.restitution != 0.0) {
      return Error{"restitution",
                   "must be 0 when both bodies name a material: the pair's coefficient " +
                       formatNumber(*pair) + " is used, got " + formatNumber(request.restitution)};
    }
    return pair;
  }
  if (a_named != b_named) {
    const std::string named = a_named ? "a" : "b";
    const std::string unnamed = a_named ? "b" : "a";
    return Error{unnamed + ".material",
                 "is empty while " + named +
                     ".material is set: name both materials (their "
                     "pair's coefficient is used) or neither (restitution is used)"};
  }
  if (auto status = checkRestitution(request.restitution, "restitution"); !status) {
    return status.error();
  }
  return request.restitution;
}

Expected<Effects> parseEffects(const std::vector<std::string>& names) {
  Effects effects;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (auto status = addEffect(names[i], "effects[" + std::to_string(i) + "]", effects); !status) {
      return status.error();
    }
  }
  return effects;
}

Expected<double> chooseFriction(const CollisionRequest& request, const MaterialTable& materials) {
  if (!request.a.material.empty() && !request.b.material.empty()) {
    const auto pair =
        materials.friction(request.a.material, request.b.material, "a.material", "b.material");
    if (pair && request.friction != 0.0) {
      return Error{"friction",
                   "must be 0 when both bodies name a material: the pair's "
                   "coefficient " +
                       formatNumber(*pair) + " is used, got " + formatNumber(request.friction)};
    }
    return pair;
  }
  if (auto status = checkFriction(request.friction, "friction"); !status) return status.error();
  return request.friction;
}

/// A body of the request as the cluster solver sees it (with spin, its moment of inertia).
ClusterBody clusterBody(const Body& body, bool spin) {
  ClusterBody cluster_body;
  cluster_body.inverse_mass = inverseMass(body);
  cluster_body.velocity = body.velocity;
  cluster_body.angular_velocity = body.angular_velocity;
  cluster_body.radius = body.radius;
  if (spin)
    cluster_body.spin_factor = spinFactor(cluster_body.inverse_mass, body.radius, body.inertia);
  return cluster_body;
}

}  // namespace

Expected<CollisionOutcome> computeCollision(const CollisionRequest& request,
                                            const MaterialTable& materials) {
  if (auto status = checkBody(request.a, "a"); !status) return status.error();
  if (auto status = checkBody(request.b, "b"); !status) return status.error();
  if (isImmovable(request.a) && isImmovable(request.b)) {
    return Error{"b.mass",
                 "a and b are both immovable (mass .inf): at least one body must have "
                 "a finite mass"};
  }
  if (!request.a.id.empty() && request.a.id == request.b.id) {
    return Error{"b.id",
                 "is the same as a.id ('" + request.a.id + "'): a body cannot collide with itself"};
  }
  const auto effects = parseEffects(request.effects);
  if (!effects) return effects.error();
  const auto line_of_impact = lineOfImpact(request.normal, request.a.position, request.b.position);
  if (!line_of_impact) return line_of_impact.error();
  const auto restitution = chooseRestitution(request, materials);
  if (!restitution) return restitution.error();
  if (!effects->friction && request.friction != 0.0) {
    return Error{"friction", "is " + formatNumber(request.friction) +
                                 " but the friction effect is not requested (add \"friction\" "
                                 "to effects)"};
  }
  const auto friction =
      effects->friction ? chooseFriction(request, materials) : Expected<double>(0.0);
  if (!friction) return friction.error();

  // A cluster of one contact, through the monitor's solver: friction and spin are chosen in one
  // place (frictionModelFor), and one contact alone is resolveImpact, exact to the last bit.
  const Effects runnable = runnableEffects(*effects);
  ClusterBody a = clusterBody(request.a, runnable.spin);
  ClusterBody b = clusterBody(request.b, runnable.spin);
  ClusterContact contact;
  contact.a = 0;
  contact.b = 1;
  contact.normal = *line_of_impact;
  contact.lever_a = request.a.radius * contact.normal;  // the balls' lever arms
  contact.lever_b = -request.b.radius * contact.normal;
  contact.restitution = *restitution;
  const ContactResolution solved =
      solveContact(a, b, contact, *friction, frictionModelFor(runnable));

  CollisionOutcome outcome;
  outcome.line_of_impact = *line_of_impact;
  outcome.restitution = *restitution;
  outcome.impact.velocity_a = a.velocity;
  outcome.impact.velocity_b = b.velocity;
  outcome.impact.normal_impulse = solved.normal.impulse;
  outcome.impact.approach_speed = solved.normal.approach_speed;
  outcome.impact.approaching = solved.normal.approach_speed > 0;
  outcome.impact.energy_lost = solved.normal.energy_lost;
  outcome.oblique = hasObliqueComponent(request.a.velocity, outcome.line_of_impact) ||
                    hasObliqueComponent(request.b.velocity, outcome.line_of_impact);
  outcome.angular_velocity_a = a.angular_velocity;
  outcome.angular_velocity_b = b.angular_velocity;
  if (runnable.friction) {
    outcome.friction_impulse = solved.friction.impulse;
    outcome.sticking = solved.friction.sticking;
    outcome.impact.energy_lost += solved.friction.energy_lost;
  }
  // Finite inputs whose answer is beyond the doubles (masses and speeds of 1e200: an energy of
  // 1e600 J) are refused by name rather than answered with an infinity.
  if (auto status =
          checkRepresentable({namedResult("velocity_a", outcome.impact.velocity_a),
                              namedResult("velocity_b", outcome.impact.velocity_b),
                              namedResult("angular_velocity_a", outcome.angular_velocity_a),
                              namedResult("angular_velocity_b", outcome.angular_velocity_b),
                              namedResult("impulse", outcome.impact.normal_impulse),
                              namedResult("friction_impulse", outcome.friction_impulse),
                              namedResult("energy_lost", outcome.impact.energy_lost)});
      !status) {
    return status.error();
  }
  return outcome;
}

}  // namespace collision_response::core
