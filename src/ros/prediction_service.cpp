#include "collision_response/ros/prediction_service.h"

#include <tf2_eigen/tf2_eigen.h>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/prediction.h"
#include "collision_response/core/validation.h"
#include "collision_response/ros/conversions.h"
#include "collision_response/ros/frame_motion.h"

namespace collision_response {
namespace {

/// The body the request names: a scene body's own values (mass 0), or every field its own.
core::Expected<core::BodySpec> requestedBody(const Body& body, const core::Scene& scene) {
  if (body.mass == 0.0) {
    for (const core::BodySpec& spec : scene.bodies) {
      if (spec.id == body.id) return spec;
    }
    return core::Error{"body.mass", "is 0, which takes the scene body '" + body.id +
                                        "' as it is, but the scene has no body of that id "
                                        "(give the body's mass, radius and material)"};
  }
  auto parsed = bodyFromMessage(body, "body");
  if (!parsed) return parsed.error();
  if (auto status = core::checkBodyShape(*parsed, "body"); !status) return status.error();
  // A ball as before; a shaped body (a box, cylinder, capsule, or a tensor given) predicted by
  // its own model (the core's shaped prediction).
  core::BodySpec spec = core::shapeSpecOf(*parsed);
  spec.material = body.material;
  return spec;
}

/// The answer's stamps, `stamp` plus instants up to the horizon (at most
/// core::kPredictionMaxHorizon), must be ros::Time's: an error names header.stamp when they would
/// pass its last instant, 4294967295.999999999 (in 2106). A horizon that is not a number > 0 is
/// the core's to name.
core::Status checkStampRoom(const ros::Time& stamp, double horizon) {
  if (!(std::isfinite(horizon) && horizon > 0)) return core::Ok{};
  constexpr std::uint64_t kLastNanosecond = 4294967295ull * 1000000000ull + 999999999ull;
  // Rounded up, and a nanosecond more: ros::Duration rounds an instant to its nanosecond.
  const auto room =
      static_cast<std::uint64_t>(std::ceil(std::min(horizon, core::kPredictionMaxHorizon) * 1e9)) +
      1;
  if (stamp.toNSec() <= kLastNanosecond - room) return core::Ok{};
  return core::Error{"header.stamp", formatStamp(stamp) + " leaves no room for the horizon (" +
                                         core::formatNumber(horizon) +
                                         " s): the answer is stamped up to it after the request's "
                                         "instant, past the last instant a ROS time holds "
                                         "(4294967295.999999999, in 2106)"};
}

/// What the request asks for, in the scene's fixed frame, on the monitor's time line: an error
/// names the field.
core::Expected<core::PredictionRequest> requestInFixedFrame(const PredictImpacts::Request& request,
                                                            const MonitorCycle& cycle,
                                                            const tf2::BufferCore& tf,
                                                            const ros::Time& stamp, double time) {
  const core::Scene& scene = cycle.scene();
  core::PredictionRequest predict;
  if (auto status = checkStampRoom(stamp, request.horizon); !status) return status.error();
  auto body = requestedBody(request.body, scene);
  if (!body) return body.error();
  predict.body = *body;
  if (request.body.mass != 0.0) {
    predict.body.drag_coefficient =
        request.drag_coefficient == 0.0 ? core::kDefaultDragCoefficient : request.drag_coefficient;
    predict.body.lift_coefficient =
        request.lift_coefficient == 0.0 ? core::kDefaultLiftCoefficient : request.lift_coefficient;
  }
  if (request.effects.empty()) predict.effects = scene.effects;
  for (std::size_t i = 0; i < request.effects.size(); ++i) {
    const std::string field = "effects[" + std::to_string(i) + "]";
    if (auto status = core::addEffect(request.effects[i], field, predict.effects); !status) {
      return status.error();
    }
  }
  const std::string frame =
      request.header.frame_id.empty() ? scene.fixed_frame : request.header.frame_id;
  const auto motion = lookupFrameMotion(tf, scene.fixed_frame, frame, stamp,
                                        ros::Duration(cycle.params().frame_velocity_interval));
  if (!motion) return core::Error{"header.frame_id", motion.error().message()};
  const Eigen::Vector3d position = toEigen(request.body.position);
  predict.state.time = time;
  predict.state.position = motion->point(position);
  predict.state.velocity = motion->velocity(position, toEigen(request.body.velocity));
  // The frame's own turning is the body's spin only where the model carries spin (as on the
  // topics, where the monitor then ignores it); without it a spin given is the core's error.
  predict.state.angular_velocity = motion->pose.linear() * toEigen(request.body.angular_velocity);
  // A shaped body turns whatever the effects: its orientation (world from body, in the frame)
  // into the fixed frame, and the frame's turning its own.
  const bool shaped = core::isShapedBody(predict.body);
  if (predict.effects.spin || shaped) predict.state.angular_velocity += motion->angular_velocity;
  if (shaped) {
    const geometry_msgs::Quaternion& q = request.body.orientation;
    predict.state.orientation = Eigen::Quaterniond(motion->pose.linear()) *
                                Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized();
  }
  predict.horizon = request.horizon;
  predict.max_impacts = request.max_impacts;
  predict.sample_period = request.sample_period;
  const Eigen::Vector3d normal = toEigen(request.crossing_normal);
  // Exactly zero is no plane; any other length (1e-300 too) is a direction (the srv).
  if (!(normal.array() == 0.0).all()) {
    if (auto status = core::checkFinite(normal, "crossing_normal"); !status) return status.error();
    const Eigen::Vector3d point = toEigen(request.crossing_point);
    if (auto status = core::checkFinite(point, "crossing_point"); !status) return status.error();
    // Any nonzero length, 1e-200 or 1e200, without under- or overflow.
    const Eigen::Vector3d fixed_normal = motion->pose.linear() * core::unitVector(normal);
    predict.crossing = core::Plane{fixed_normal, fixed_normal.dot(motion->point(point))};
  }
  return predict;
}

/// A state as a BodyState message, stamped `stamp`, in `frame`.
BodyState stateMessage(const core::BodyStateSample& sample, const std::string& id,
                       const std::string& frame, const ros::Time& stamp) {
  BodyState state;
  state.header.stamp = stamp;
  state.header.frame_id = frame;
  state.id = id;
  state.pose.position = toPointMsg(sample.position);
  state.pose.orientation = tf2::toMsg(sample.orientation);
  state.twist.linear = toVector3Msg(sample.velocity);
  state.twist.angular = toVector3Msg(sample.angular_velocity);
  return state;
}

void refuse(const core::Error& error, PredictImpacts::Response& response) {
  response = PredictImpacts::Response{};
  response.success = false;
  response.message = error.message();
}

}  // namespace

core::Expected<PreparedPrediction> preparePredictImpacts(const PredictImpacts::Request& request,
                                                         const MonitorCycle& cycle,
                                                         const tf2::BufferCore& tf,
                                                         const ros::Time& clock) {
  const core::ImpactMonitor& live = cycle.monitor();
  const TimeLine& line = cycle.timeLine();
  PreparedPrediction prepared;
  // The request's instant: on the monitor's line once it has one; before, its own line from 0.
  prepared.stamp = request.header.stamp;
  double time = 0.0;
  if (prepared.stamp.isZero()) {
    if (live.started() && line.stampOf(live.now(), prepared.stamp)) {
      time = live.now();
    } else {
      prepared.stamp = clock;
    }
  } else if (!line.lineTimeOf(prepared.stamp, time)) {
    time = 0.0;
  }
  auto predict = requestInFixedFrame(request, cycle, tf, prepared.stamp, time);
  if (!predict) return predict.error();
  const core::MonitorSettings settings{cycle.params().contact_tolerance,
                                       cycle.params().body_timeout};
  auto start =
      core::startPrediction(cycle.scene(), live.started() ? &live : nullptr, settings, *predict);
  if (!start) return start.error();
  prepared.start = std::move(*start);
  prepared.fixed_frame = cycle.scene().fixed_frame;
  return prepared;
}

bool answerPreparedPrediction(const PreparedPrediction& prepared,
                              const core::PredictionBudget& budget,
                              PredictImpacts::Response& response) {
  const auto prediction = core::runPrediction(prepared.start, budget);
  if (!prediction) {
    refuse(prediction.error(), response);
    return false;
  }

  const std::string& fixed = prepared.fixed_frame;
  const ros::Time& stamp = prepared.stamp;
  const auto stampAt = [&](double after) { return stamp + ros::Duration(after); };
  const core::ImpactMonitor& model = *prediction->model;
  for (const core::ImpactRecord& record : prediction->impacts) {
    auto message = toImpactMessage(record, model, stampAt(record.time), fixed);
    if (!message) {
      refuse(message.error(), response);
      return false;
    }
    response.impacts.push_back(*message);
  }
  for (const core::ContactRecord& record : prediction->contacts) {
    auto message = toContactMessage(record, model, stampAt(record.since));
    if (!message) {
      refuse(message.error(), response);
      return false;
    }
    response.final_contacts.push_back(*message);
  }
  const std::string& id = prepared.start.request.body.id;
  response.final_state =
      stateMessage(prediction->final_state, id, fixed, stampAt(prediction->final_state.time));
  if (prediction->crossing) {
    response.crossed = true;
    response.crossing =
        stateMessage(*prediction->crossing, id, fixed, stampAt(prediction->crossing->time));
  }
  for (const core::BodyStateSample& sample : prediction->samples) {
    response.samples.push_back(stateMessage(sample, id, fixed, stampAt(sample.time)));
  }
  response.success = true;
  response.message = std::to_string(response.impacts.size()) + " impact(s) in " +
                     core::formatNumber(prediction->final_state.time) + " s, effects " +
                     core::toString(prepared.start.request.effects);
  if (prediction->cut_short) response.message += "; cut short: " + prediction->message;
  return prediction->out_of_budget;
}

void answerPredictImpacts(const PredictImpacts::Request& request, const MonitorCycle& cycle,
                          const tf2::BufferCore& tf, const ros::Time& clock,
                          PredictImpacts::Response& response,
                          const core::PredictionBudget& budget) {
  const auto prepared = preparePredictImpacts(request, cycle, tf, clock);
  if (!prepared) return refuse(prepared.error(), response);
  answerPreparedPrediction(*prepared, budget, response);
}

}  // namespace collision_response
