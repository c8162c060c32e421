#include "collision_response/ros/state_intake.h"

#include <cmath>
#include <optional>
#include <utility>

#include "collision_response/core/validation.h"
#include "collision_response/ros/conversions.h"
#include "collision_response/ros/frame_motion.h"

namespace collision_response {
namespace {

/// Ids and frames come from publishers: a warning quotes at most this much of one.
constexpr std::size_t kQuotedLength = 64;

std::string quoted(const std::string& text) {
  return "'" + (text.size() > kQuotedLength ? text.substr(0, kQuotedLength) + "..." : text) + "'";
}

/// The first non-finite number of a state, named as its field, and the field's place; empty
/// when all are finite.
std::string firstNonFinite(const BodyState& state, int& field_index) {
  const std::pair<const char*, double> fields[] = {{"pose.position.x", state.pose.position.x},
                                                   {"pose.position.y", state.pose.position.y},
                                                   {"pose.position.z", state.pose.position.z},
                                                   {"pose.orientation.x", state.pose.orientation.x},
                                                   {"pose.orientation.y", state.pose.orientation.y},
                                                   {"pose.orientation.z", state.pose.orientation.z},
                                                   {"pose.orientation.w", state.pose.orientation.w},
                                                   {"twist.linear.x", state.twist.linear.x},
                                                   {"twist.linear.y", state.twist.linear.y},
                                                   {"twist.linear.z", state.twist.linear.z},
                                                   {"twist.angular.x", state.twist.angular.x},
                                                   {"twist.angular.y", state.twist.angular.y},
                                                   {"twist.angular.z", state.twist.angular.z}};
  field_index = 0;
  for (const auto& [name, value] : fields) {
    if (!std::isfinite(value)) {
      return std::string(name) + ": must be a finite number, got " + core::formatNumber(value);
    }
    ++field_index;
  }
  return "";
}

std::string frameOf(const BodyState& state, const std::string& fixed_frame) {
  std::string frame = state.header.frame_id;
  if (!frame.empty() && frame.front() == '/') frame.erase(0, 1);  // tf2 frames have no slash
  return frame.empty() ? fixed_frame : frame;
}

}  // namespace

const char* counterName(Reason reason) {
  switch (reason) {
    case Reason::kEmptyId:
      return "dropped: empty id";
    case Reason::kUnknownId:
      return "dropped: unknown id";
    case Reason::kIdMismatch:
      return "dropped: id does not match the topic";
    case Reason::kDuplicateId:
      return "dropped: id twice in one message";
    case Reason::kZeroStamp:
      return "dropped: zero stamp";
    case Reason::kStampAhead:
      return "dropped: stamp ahead of the clock";
    case Reason::kNonFinite:
      return "dropped: non-finite value";
    case Reason::kBeyondResolution:
      return "dropped: position beyond resolution";
    case Reason::kTransformMissing:
      return "dropped: transform missing";
    case Reason::kStale:
      return "dropped: stamp not newer than the body's last";
    case Reason::kSetAside:
      return "dropped: state older than its body's motion";
    case Reason::kStampOffClock:
      return "dropped: stamp off its source's clock";
    case Reason::kTooManyStates:
      return "dropped: too many states in one message";
    case Reason::kQueueFull:
      return "dropped: input queue full";
    case Reason::kInternalError:
      return "dropped: internal error";
    case Reason::kImpactNotFinite:
      return "impacts dropped: not finite";
    case Reason::kContactNotFinite:
      return "contacts dropped: not finite";
    case Reason::kClockJumpedBack:
      return "clock jumped back";
    case Reason::kClockOffset:
      return "clock offsets applied";
    case Reason::kStepTruncated:
      return "steps truncated";
    case Reason::kSteppedHeld:
      return "stepped sub-steps held";
    case Reason::kOverWorkBudget:
      return "bodies stepped over the exact work budget";
    case Reason::kObstacleTransform:
      return "obstacle transform missing";
    case Reason::kImpactContradicted:
      return "impacts a later state lacks";
    case Reason::kFlightStalled:
      return "flights through air stalled";
    case Reason::kPredictionCutShort:
      return "predictions cut short";
    case Reason::kObstaclePlacementsLeftOut:
      return "obstacle placements left out";
    case Reason::kFrameJumped:
      return "frames jumped";
    case Reason::kOverImpactWork:
      return "bodies of impacts over the impact work bound";
    case Reason::kOverSteppedWork:
      return "bodies held over the stepped work bound";
    case Reason::kBadOrientation:
      return "dropped: orientation not a rotation";
    case Reason::kUnmodelledContact:
      return "contacts of shaped bodies not modelled yet";
  }
  return "unknown";
}

bool isDrop(Reason reason) {
  return reason <= Reason::kContactNotFinite || reason == Reason::kBadOrientation;
}

StateIntake::StateIntake(std::vector<std::string> body_ids, std::vector<bool> shaped,
                         IntakeSettings settings)
    : body_ids_(std::move(body_ids)),
      shaped_(std::move(shaped)),
      settings_(std::move(settings)),
      seen_in_input_(body_ids_.size(), 0),
      seen_at_place_(body_ids_.size(), 0),
      seen_at_sample_(body_ids_.size(), 0) {
  for (std::size_t i = 0; i < body_ids_.size(); ++i) index_of_.emplace(body_ids_[i], i);
}

bool StateIntake::lookUp(const BodyState& state, std::size_t place, std::size_t& index,
                         std::vector<Report>& reports) {
  // A source sends its bodies in the same order every time: the body found at this place in
  // the last input is tried before the lookup by id.
  if (index_hints_.size() <= place) index_hints_.resize(place + 1, 0);
  const std::size_t hint = index_hints_[place];
  if (hint < body_ids_.size() && body_ids_[hint] == state.id) {
    index = hint;
    return true;
  }
  const auto found = index_of_.find(state.id);
  if (found != index_of_.end()) {
    index = index_hints_[place] = found->second;
    return true;
  }
  if (state.id.empty()) {
    reports.push_back({Reason::kEmptyId, "id: is empty"});
  } else {
    reports.push_back({Reason::kUnknownId,
                       "id: unknown body " + quoted(state.id) + " (not in the scene's bodies)"});
  }
  return false;
}

/// Where a state stood in its input, as warnings name it: "states[3] ('ball')", "a state".
std::string StateIntake::Place::text(const std::string& id) const {
  std::string text = array ? "states[" + std::to_string(index) + "]" : std::string("a state");
  return id.empty() ? text : text + " (" + quoted(id) + ")";
}

std::optional<std::size_t> StateIntake::bodyOf(const BodyState& state, const Place& place,
                                               const std::string& own_body,
                                               std::vector<Report>& reports) {
  if (!place.array) {
    const std::string& id = state.id.empty() ? own_body : state.id;
    if (id != own_body) {
      reports.push_back({Reason::kIdMismatch, "dropped a state: id: " + quoted(id) +
                                                  " does not match this topic's body " +
                                                  quoted(own_body)});
      return std::nullopt;
    }
    const auto found = index_of_.find(id);
    if (found == index_of_.end()) return std::nullopt;  // it subscribes to its bodies' topics
    return found->second;
  }
  std::size_t index = 0;
  std::vector<Report> why;
  if (!lookUp(state, place.index, index, why)) {
    reports.push_back({why.front().reason, "dropped " + place.text("") + ": " + why.front().text});
    return std::nullopt;
  }
  return index;
}

std::optional<Report> StateIntake::problemOf(const BodyState& state, std::size_t index,
                                             const ros::Time& clock) const {
  if (state.header.stamp.isZero()) {
    return Report{Reason::kZeroStamp, "header.stamp: is zero; a state needs the instant it holds"};
  }
  if (!clock.isZero() &&
      state.header.stamp.toSec() - clock.toSec() > settings_.future_stamp_tolerance) {
    return Report{Reason::kStampAhead,
                  "header.stamp: " + formatStamp(state.header.stamp) + " is " +
                      core::formatNumber(state.header.stamp.toSec() - clock.toSec()) +
                      " s ahead of this node's clock (" + formatStamp(clock) +
                      "), more than ~future_stamp_tolerance (" +
                      core::formatNumber(settings_.future_stamp_tolerance) +
                      " s): not a measurement yet (a source on another clock? use_sim_time?)"};
  }
  int field_index = 0;
  if (const std::string bad = firstNonFinite(state, field_index); !bad.empty()) {
    Report report{Reason::kNonFinite, bad};
    report.variant = field_index;
    return report;
  }
  // Far enough out, the monitor's sums of two positions overflow and the contacts are lost
  // without a word (a stack at x = 1.7e308 fell through its floor): refused by name.
  if (auto status = core::checkResolvablePosition(toEigen(state.pose.position), "pose.position");
      !status) {
    Report report{Reason::kBeyondResolution, status.error().message()};
    report.variant = static_cast<int>(status.error().field.back() - 'x');
    return report;
  }
  // A shaped body turns by its orientation (world from body): one that is no rotation is refused
  // as ~compute_collision refuses it (core::checkOrientation); a ball's may be all zero (not
  // given: a geometry_msgs/Quaternion's default), as its orientation does not matter.
  const Eigen::Quaterniond orientation = toEigen(state.pose.orientation);
  const bool shaped = index < shaped_.size() && shaped_[index];
  if (!core::isRotation(orientation) && (shaped || !orientation.coeffs().isZero(0.0))) {
    const auto status = core::checkOrientation(orientation, "pose.orientation");
    return Report{
        Reason::kBadOrientation,
        status.error().message() +
            (shaped ? " (a shaped body's state needs its orientation, world from body)" : "")};
  }
  return std::nullopt;
}

core::BodyStateSample StateIntake::inFixedFrame(const BodyState& state, std::size_t index,
                                                const FrameMotion& frame_motion) {
  core::BodyStateSample sample;
  sample.body = index;
  const Eigen::Vector3d position = toEigen(state.pose.position);
  sample.position = frame_motion.point(position);
  sample.velocity = frame_motion.velocity(position, toEigen(state.twist.linear));
  sample.angular_velocity =
      frame_motion.pose.linear() * toEigen(state.twist.angular) + frame_motion.angular_velocity;
  // A rotation (problemOf), or all zero for a ball: the identity then.
  const Eigen::Quaterniond orientation = toEigen(state.pose.orientation);
  if (!orientation.coeffs().isZero(0.0)) {
    sample.orientation =
        (Eigen::Quaterniond(frame_motion.pose.linear()) * orientation.normalized()).normalized();
  }
  return sample;
}

void StateIntake::keepOncePerInput(const core::BodyStateSample& sample, const ros::Time& stamp,
                                   const Place& place, const std::string& id,
                                   StampedSamples& samples, std::vector<Report>& reports) {
  const std::size_t index = sample.body;
  // A body once per input: of two states of one body, the newer stamp is kept (the first of
  // equal ones), and the other is dropped naming both places.
  if (seen_in_input_[index] == input_serial_) {
    const std::size_t kept_place = seen_at_place_[index];
    const std::size_t kept = seen_at_sample_[index];
    const bool newer = stamp > samples.stamps[kept];
    const std::size_t dropped_place = newer ? kept_place : place.index;
    reports.push_back(
        {Reason::kDuplicateId, "dropped " + Place{place.array, dropped_place}.text(id) +
                                   ": id: " + quoted(id) + " is also states[" +
                                   std::to_string(newer ? place.index : kept_place) +
                                   "] of this message (a body once per message; the newer stamp is "
                                   "kept)"});
    if (newer) {
      samples.samples[kept] = sample;
      samples.stamps[kept] = stamp;
      seen_at_place_[index] = place.index;
    }
    return;
  }
  seen_in_input_[index] = input_serial_;
  seen_at_place_[index] = place.index;
  seen_at_sample_[index] = samples.size();
  samples.push_back(sample, stamp);
}

StateIntake::Outcome StateIntake::convert(const std::vector<BodyState>& states,
                                          const std::string& own_body, const ros::Time& clock,
                                          bool may_wait, const tf2::BufferCore& tf,
                                          StampedSamples& samples, std::vector<Report>& reports) {
  const std::size_t samples_before = samples.size();
  const std::size_t reports_before = reports.size();
  ++input_serial_;
  // The states of an input usually share a frame and a stamp: one lookup serves them all.
  std::optional<core::Expected<FrameMotion>> motion;
  std::string motion_frame;
  ros::Time motion_stamp;
  for (std::size_t k = 0; k < states.size(); ++k) {
    const BodyState& state = states[k];
    const Place place{own_body.empty(), k};
    const std::string& id = !place.array && state.id.empty() ? own_body : state.id;
    const auto index = bodyOf(state, place, own_body, reports);
    if (!index) continue;
    if (auto problem = problemOf(state, *index, clock)) {
      problem->text = "dropped " + place.text(id) + ": " + problem->text;
      reports.push_back(std::move(*problem));
      continue;
    }
    const std::string frame = frameOf(state, settings_.fixed_frame);
    if (!motion || frame != motion_frame || state.header.stamp != motion_stamp) {
      motion = lookupFrameMotion(tf, settings_.fixed_frame, frame, state.header.stamp,
                                 ros::Duration(settings_.frame_velocity_interval));
      motion_frame = frame;
      motion_stamp = state.header.stamp;
    }
    if (!*motion) {
      if (may_wait) {
        // Nothing consumed: the whole input is tried again when the transforms may be there.
        samples.resize(samples_before);
        reports.resize(reports_before);
        return Outcome::kWait;
      }
      reports.push_back(
          {Reason::kTransformMissing, "dropped " + place.text(id) + " after waiting " +
                                          core::formatNumber(settings_.transform_timeout) +
                                          " s: header.frame_id: " + motion->error().message()});
      continue;
    }
    const core::BodyStateSample sample = inFixedFrame(state, *index, **motion);
    // A frame far out can carry a resolvable position past the bound (or past the doubles).
    if (auto status = core::checkResolvablePosition(sample.position, "pose.position"); !status) {
      Report report{Reason::kBeyondResolution,
                    "dropped " + place.text(id) + ": " + status.error().field + " (in " +
                        quoted(std::as_const(settings_.fixed_frame)) + ", from " + quoted(frame) +
                        "): " + status.error().reason};
      report.variant = 3 + static_cast<int>(status.error().field.back() - 'x');
      reports.push_back(std::move(report));
      continue;
    }
    keepOncePerInput(sample, state.header.stamp, place, id, samples, reports);
  }
  return Outcome::kDone;
}

}  // namespace collision_response
