#include "collision_response/core/collision.h"

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

Status checkEffects(const std::vector<std::string>& effects) {
  for (std::size_t i = 0; i < effects.size(); ++i) {
    const std::string field = "effects[" + std::to_string(i) + "]";
    const std::string& name = effects[i];
    if (name == "gravity" || name == "friction" || name == "spin") {
      return Error{field, "effect '" + name +
                              "' is not available in this version; leave effects empty for the "
                              "seed's frictionless model"};
    }
    return Error{field, "unknown effect '" + name + "'; known: gravity, friction, spin"};
  }
  return Ok{};
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
  if (auto status = checkEffects(request.effects); !status) return status.error();
  const auto line_of_impact = lineOfImpact(request.normal, request.a.position, request.b.position);
  if (!line_of_impact) return line_of_impact.error();
  const auto restitution = chooseRestitution(request, materials);
  if (!restitution) return restitution.error();

  CollisionOutcome outcome;
  outcome.line_of_impact = *line_of_impact;
  outcome.restitution = *restitution;
  outcome.impact = resolveImpact(inverseMass(request.a), request.a.velocity, inverseMass(request.b),
                                 request.b.velocity, outcome.line_of_impact, outcome.restitution);
  outcome.oblique = hasObliqueComponent(request.a.velocity, outcome.line_of_impact) ||
                    hasObliqueComponent(request.b.velocity, outcome.line_of_impact);
  outcome.angular_velocity_a = request.a.angular_velocity;
  outcome.angular_velocity_b = request.b.angular_velocity;
  return outcome;
}

}  // namespace collision_response::core
