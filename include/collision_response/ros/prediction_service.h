// ~predict_impacts: the monitor's model run ahead of time for one body (core::predictImpacts),
// the request read from any tf frame and the answer stamped on the node's clock. A plain function
// of the update cycle (its monitor, scene, time line) and tf: no node, no master needed.
#pragma once

#include <ros/time.h>
#include <tf2/buffer_core.h>

#include <string>

#include "collision_response/PredictImpacts.h"
#include "collision_response/core/prediction.h"
#include "collision_response/ros/monitor_cycle.h"

namespace collision_response {

/// What a request needs of the update cycle (its monitor, scene, time line), taken at once
/// (quick: no motion computed), so that the prediction runs without the cycle: off the monitor's
/// thread while it steps on.
struct PreparedPrediction {
  core::PredictionStart start;
  ros::Time stamp;          ///< the request's instant: the prediction's 0
  std::string fixed_frame;  ///< the scene's
};

/// The part that reads `cycle` (called under the monitor's lock, between its updates); a
/// refused request is an error naming the field and the reason. `clock`: the node's clock now,
/// the request's instant when its stamp is zero and the monitor has no update yet.
core::Expected<PreparedPrediction> preparePredictImpacts(const PredictImpacts::Request& request,
                                                         const MonitorCycle& cycle,
                                                         const tf2::BufferCore& tf,
                                                         const ros::Time& clock);

/// Runs the prepared prediction within `budget` and fills `response` (refused: success false,
/// `message` naming the field and the reason; cut short: "cut short: " and why). Returns whether
/// `budget` ran out (the answer then ends where the prediction got to).
bool answerPreparedPrediction(const PreparedPrediction& prepared,
                              const core::PredictionBudget& budget,
                              PredictImpacts::Response& response);

/// Both at once: fills `response` from the prediction. Reads `cycle`: called between its updates.
void answerPredictImpacts(const PredictImpacts::Request& request, const MonitorCycle& cycle,
                          const tf2::BufferCore& tf, const ros::Time& clock,
                          PredictImpacts::Response& response,
                          const core::PredictionBudget& budget = {});

}  // namespace collision_response
