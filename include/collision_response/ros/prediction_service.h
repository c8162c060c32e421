// ~predict_impacts: the monitor's model run ahead of time for one body (core::predictImpacts),
// the request read from any tf frame and the answer stamped on the node's clock. A plain function
// of the update cycle (its monitor, scene, time line) and tf: no node, no master needed.
#pragma once

#include <ros/time.h>
#include <tf2/buffer_core.h>

#include "collision_response/PredictImpacts.h"
#include "collision_response/ros/monitor_cycle.h"

namespace collision_response {

/// Fills `response` from the prediction; a refused request has success = false and `message`
/// naming the field and the reason. `clock`: the node's clock now, the request's instant when
/// its stamp is zero and the monitor has no update yet. Reads `cycle` only: called between its
/// updates (on the monitor's queue).
void answerPredictImpacts(const PredictImpacts::Request& request, const MonitorCycle& cycle,
                          const tf2::BufferCore& tf, const ros::Time& clock,
                          PredictImpacts::Response& response);

}  // namespace collision_response
