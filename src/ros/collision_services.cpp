#include "collision_response/ros/collision_services.h"

#include <tuple>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/collision.h"
#include "collision_response/core/restitution.h"
#include "collision_response/core/validation.h"
#include "collision_response/ros/conversions.h"

namespace collision_response {

void answerComputeCollision(const ComputeCollision::Request& request,
                            const core::MaterialTable& materials,
                            ComputeCollision::Response& response) {
  response = ComputeCollision::Response();
  core::CollisionRequest core_request;
  core_request.normal = toEigen(request.normal);
  core_request.restitution = request.restitution;
  core_request.friction = request.friction;
  core_request.effects = request.effects;
  if (request.contact_point_given) core_request.contact_point = toEigen(request.contact_point);
  for (const auto& [body, message, prefix] :
       {std::make_tuple(&core_request.a, &request.a, std::string("a")),
        std::make_tuple(&core_request.b, &request.b, std::string("b"))}) {
    auto parsed = bodyFromMessage(*message, prefix);
    if (!parsed) {
      response.success = false;
      response.message = parsed.error().message();
      return;
    }
    *body = std::move(parsed.value());
  }
  const auto outcome = core::computeCollision(core_request, materials);
  if (!outcome) {
    response.success = false;
    response.message = outcome.error().message();
    return;
  }
  const core::ImpactResponse<double>& impact = outcome->impact;
  response.success = true;
  response.velocity_a = toVector3Msg(impact.velocity_a);
  response.velocity_b = toVector3Msg(impact.velocity_b);
  response.angular_velocity_a = toVector3Msg(outcome->angular_velocity_a);
  response.angular_velocity_b = toVector3Msg(outcome->angular_velocity_b);
  response.normal = toVector3Msg(outcome->line_of_impact);
  response.contact_point = toPointMsg(outcome->contact_point);
  response.restitution = outcome->restitution;
  response.impulse = impact.normal_impulse;
  response.oblique = outcome->oblique;
  response.approaching = impact.approaching;
  response.friction_impulse = outcome->friction_impulse;
  response.sticking = outcome->sticking;
  response.energy_lost = impact.energy_lost;
  response.message =
      impact.approaching
          ? std::string(outcome->oblique ? "oblique" : "direct") +
                " impact, e = " + core::formatNumber(outcome->restitution) + ", impulse " +
                core::formatNumber(impact.normal_impulse) + " N s"
          : "not approaching ((v_b - v_a).normal = " + core::formatNumber(-impact.approach_speed) +
                " m/s >= 0): velocities unchanged";
  if (outcome->surface_gap) {
    // Two shaped bodies whose contact was found: how far apart the caller's poses had them.
    response.message += *outcome->surface_gap > 0
                            ? "; contact found from the shapes, their surfaces " +
                                  core::formatNumber(*outcome->surface_gap) + " m apart"
                            : "; contact found from the shapes, touching";
  }
}

void answerEstimateRestitution(const EstimateRestitution::Request& request,
                               const core::MaterialTable& materials,
                               EstimateRestitution::Response& response) {
  response = EstimateRestitution::Response();
  const auto restitution = core::restitutionFromHeights(request.drop_height, request.bounce_height);
  if (!restitution) {
    response.success = false;
    response.message = restitution.error().message();
    return;
  }
  const core::NearestMaterial nearest = core::nearestMaterial(materials, *restitution);
  response.success = true;
  response.restitution = *restitution;
  response.nearest_material = nearest.name;
  response.nearest_material_restitution = nearest.restitution;
  response.message = "e = sqrt(" + core::formatNumber(request.bounce_height) + " / " +
                     core::formatNumber(request.drop_height) +
                     ") = " + core::formatNumber(*restitution) +
                     "; nearest material: " + nearest.name + " (" +
                     core::formatNumber(nearest.restitution) + " on concrete)";
}

}  // namespace collision_response
