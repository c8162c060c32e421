// The two services as plain functions of request -> response: no node, no master needed.
#pragma once

#include "collision_response/ComputeCollision.h"
#include "collision_response/EstimateRestitution.h"
#include "collision_response/core/materials.h"

namespace collision_response {

/// Fills `response` from the core's answer; on a refused request success = false, message names
/// the field and the reason, and the numeric fields stay zero.
void answerComputeCollision(const ComputeCollision::Request& request,
                            const core::MaterialTable& materials,
                            ComputeCollision::Response& response);

void answerEstimateRestitution(const EstimateRestitution::Request& request,
                               const core::MaterialTable& materials,
                               EstimateRestitution::Response& response);

}  // namespace collision_response
