// The prediction of a shaped body (issue 42, build step 7, first part): a box, cylinder or
// capsule (or a sphere given a tensor) predicted among the scene's obstacles by its exact flight
// (its centre's parabola, its torque-free rotation: free_rotation.h), its certified first
// contacts (tumbling_contact.h) and its impacts with rotation (rigid_impact.h), and where its
// contact lasts on one flat face by lastingOnFace's closed forms (shaped_lasting.h); where the
// contact lasts otherwise (not modelled yet) the prediction ends there and says so. The motion is
// the engine's (shaped_motion.h); the samples, the crossing and the budgets are the prediction's.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/prediction.h"
#include "monitor/shaped_motion.h"

namespace collision_response::core {

/// The request's checks that only a shaped body has: its mass finite, its shape and tensor
/// (checkBodyShape, principalBody), its orientation.
Status checkShapedRequest(const PredictionRequest& request);

/// Why a prediction was cut short where its flight through air stalled at `stalled` (a ball's or a
/// shaped body's).
std::string stalledFlightCut(double stalled);

/// The prediction of a shaped body: `model` holds the scene ahead (the obstacles where they
/// are placed, the ids of the answer); `began` the budget's clock at the start. The reasons it
/// was cut short are appended to `cut`.
Expected<Prediction> runShapedPrediction(const PredictionStart& start,
                                         const PredictionBudget& budget, double began,
                                         std::shared_ptr<ImpactMonitor> model,
                                         std::vector<std::string>& cut);

}  // namespace collision_response::core
