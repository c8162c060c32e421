#include "collision_response/core/collision.h"

#include <cmath>

#include "collision_response/core/friction.h"
#include "collision_response/core/scene.h"
#include "collision_response/core/validation.h"

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

  CollisionOutcome outcome;
  outcome.line_of_impact = *line_of_impact;
  outcome.restitution = *restitution;
  outcome.impact = resolveImpact(inverseMass(request.a), request.a.velocity, inverseMass(request.b),
                                 request.b.velocity, outcome.line_of_impact, outcome.restitution);
  outcome.oblique = hasObliqueComponent(request.a.velocity, outcome.line_of_impact) ||
                    hasObliqueComponent(request.b.velocity, outcome.line_of_impact);
  outcome.angular_velocity_a = request.a.angular_velocity;
  outcome.angular_velocity_b = request.b.angular_velocity;
#ifndef COLLISION_RESPONSE_NO_EFFECTS
  if (effects->friction) {
    ClusterBody a{inverseMass(request.a), outcome.impact.velocity_a, request.a.angular_velocity,
                  0.0, request.a.radius};
    ClusterBody b{inverseMass(request.b), outcome.impact.velocity_b, request.b.angular_velocity,
                  0.0, request.b.radius};
    FrictionOutcome friction_outcome;
    if (effects->spin) {
      a.spin_factor = spinFactor(a.inverse_mass, request.a.radius, request.a.inertia);
      b.spin_factor = spinFactor(b.inverse_mass, request.b.radius, request.b.inertia);
      friction_outcome = applyFriction<true>(a, b, outcome.line_of_impact, *friction,
                                             outcome.impact.normal_impulse);
    } else {
      friction_outcome = applyFriction<false>(a, b, outcome.line_of_impact, *friction,
                                              outcome.impact.normal_impulse);
    }
    outcome.impact.velocity_a = a.velocity;
    outcome.impact.velocity_b = b.velocity;
    outcome.angular_velocity_a = a.angular_velocity;
    outcome.angular_velocity_b = b.angular_velocity;
    outcome.friction_impulse = friction_outcome.impulse;
    outcome.sticking = friction_outcome.sticking;
    outcome.impact.energy_lost += friction_outcome.energy_lost;
  }
#endif
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
