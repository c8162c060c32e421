#include "collision_response/ros/monitor_cycle.h"

#include <tf2/exceptions.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/validation.h"
#include "collision_response/ros/conversions.h"
#include "collision_response/ros/frame_motion.h"

namespace collision_response {
namespace {

std::vector<std::string> bodyIds(const core::ImpactMonitor& monitor) {
  std::vector<std::string> ids;
  ids.reserve(monitor.bodyCount());
  for (std::size_t i = 0; i < monitor.bodyCount(); ++i) ids.push_back(monitor.body(i).id);
  return ids;
}

/// By body index: whether its state needs its orientation (a body that turns by its shape).
std::vector<bool> shapedBodies(const core::ImpactMonitor& monitor) {
  std::vector<bool> shaped;
  shaped.reserve(monitor.bodyCount());
  for (std::size_t i = 0; i < monitor.bodyCount(); ++i) {
    shaped.push_back(core::isShapedBody(monitor.body(i)));
  }
  return shaped;
}

IntakeSettings intakeSettings(const core::Scene& scene, const MonitorParams& params) {
  IntakeSettings settings;
  settings.fixed_frame = scene.fixed_frame;
  settings.frame_velocity_interval = params.frame_velocity_interval;
  settings.transform_timeout = params.transform_timeout;
  settings.future_stamp_tolerance = params.future_stamp_tolerance;
  return settings;
}

std::int64_t nanoseconds(const ros::Time& stamp) {
  return static_cast<std::int64_t>(stamp.sec) * 1000000000 + static_cast<std::int64_t>(stamp.nsec);
}

geometry_msgs::Twist toTwist(const Eigen::Vector3d& linear, const Eigen::Vector3d& angular) {
  geometry_msgs::Twist twist;
  twist.linear = toVector3Msg(linear);
  twist.angular = toVector3Msg(angular);
  return twist;
}

/// "'a' and 'b'": the two sides of an impact or a contact, for a warning.
std::string sides(const core::ImpactMonitor& monitor, std::size_t body_a, std::size_t other,
                  bool other_is_obstacle) {
  return "'" + monitor.body(body_a).id + "' and '" +
         (other_is_obstacle ? monitor.obstacle(other).id : monitor.body(other).id) + "'";
}

/// "'a', 'b' and 3 more": the first `named` of `count` things (name_of(k) the k-th's), quoted,
/// and how many more, for a report whose count says how many in all.
template <class NameOf>
std::string namedList(std::size_t count, std::size_t named, const NameOf& name_of) {
  std::string names;
  for (std::size_t k = 0; k < count && k < named; ++k)
    names += (k ? ", '" : "'") + name_of(k) + "'";
  if (count > named) names += " and " + std::to_string(count - named) + " more";
  return names;
}

/// The bodies `bodies` named, at most eight of them.
std::string namedBodies(const core::ImpactMonitor& monitor,
                        const std::vector<std::size_t>& bodies) {
  return namedList(bodies.size(), 8, [&](std::size_t k) { return monitor.body(bodies[k]).id; });
}

}  // namespace

core::Expected<Impact> toImpactMessage(const core::ImpactRecord& record,
                                       const core::ImpactMonitor& monitor, const ros::Time& stamp,
                                       const std::string& fixed_frame) {
  using core::namedResult;
  if (auto status = core::checkRepresentable(
          {namedResult("contact_point", record.contact_point), namedResult("normal", record.normal),
           namedResult("restitution", record.restitution), namedResult("impulse", record.impulse),
           namedResult("friction_impulse", record.friction_impulse),
           namedResult("velocity_a_before", record.velocity_a_before),
           namedResult("velocity_a_before", record.angular_velocity_a_before),
           namedResult("velocity_a_after", record.velocity_a_after),
           namedResult("velocity_a_after", record.angular_velocity_a_after),
           namedResult("velocity_b_before", record.velocity_b_before),
           namedResult("velocity_b_before", record.angular_velocity_b_before),
           namedResult("velocity_b_after", record.velocity_b_after),
           namedResult("velocity_b_after", record.angular_velocity_b_after),
           namedResult("energy_lost", record.energy_lost)});
      !status) {
    return status.error();
  }
  Impact impact;
  impact.header.stamp = stamp;
  impact.header.frame_id = fixed_frame;
  impact.body_a = monitor.body(record.body_a).id;
  impact.body_b =
      record.other_is_obstacle ? monitor.obstacle(record.other).id : monitor.body(record.other).id;
  impact.contact_point = toPointMsg(record.contact_point);
  impact.normal = toVector3Msg(record.normal);
  impact.restitution = record.restitution;
  impact.impulse = record.impulse;
  impact.friction_impulse = record.friction_impulse;
  impact.oblique = record.oblique;
  impact.velocity_a_before = toTwist(record.velocity_a_before, record.angular_velocity_a_before);
  impact.velocity_a_after = toTwist(record.velocity_a_after, record.angular_velocity_a_after);
  impact.velocity_b_before = toTwist(record.velocity_b_before, record.angular_velocity_b_before);
  impact.velocity_b_after = toTwist(record.velocity_b_after, record.angular_velocity_b_after);
  impact.energy_lost = record.energy_lost;
  return impact;
}

core::Expected<Contact> toContactMessage(const core::ContactRecord& record,
                                         const core::ImpactMonitor& monitor,
                                         const ros::Time& since) {
  using core::namedResult;
  if (auto status = core::checkRepresentable(
          {namedResult("contact_point", record.contact_point), namedResult("normal", record.normal),
           namedResult("normal_force", record.normal_force),
           namedResult("friction_force", record.friction_force)});
      !status) {
    return status.error();
  }
  Contact contact;
  contact.body_a = monitor.body(record.body_a).id;
  contact.body_b =
      record.other_is_obstacle ? monitor.obstacle(record.other).id : monitor.body(record.other).id;
  contact.contact_point = toPointMsg(record.contact_point);
  contact.normal = toVector3Msg(record.normal);
  contact.normal_force = record.normal_force;
  contact.friction_force = toVector3Msg(record.friction_force);
  contact.state = core::toString(record.state);
  contact.since = since;
  return contact;
}

MonitorCycle::MonitorCycle(const core::Scene& scene, const MonitorParams& params)
    : params_(params),
      monitor_(scene, core::MonitorSettings{params.contact_tolerance, params.body_timeout}),
      intake_(bodyIds(monitor_), shapedBodies(monitor_), intakeSettings(scene, params)),
      time_line_(params.clock_jump_back),
      live_calibration_(scene, params.calibration_window) {
  frame_jumped_.assign(monitor_.obstacleCount(), 0);
  frame_kind_.reserve(monitor_.obstacleCount());
  for (std::size_t i = 0; i < monitor_.obstacleCount(); ++i) {
    frame_kind_.push_back(monitor_.obstacle(i).frame.empty() ? FrameKind::kFixed
                                                             : FrameKind::kUnknown);
  }
}

MonitorCycle::Update MonitorCycle::process(const Input& input, const ros::Time& clock,
                                           bool may_wait, const tf2::BufferCore& tf) {
  Update update;
  samples_.clear();
  obstacle_work_ = {};
  if (intake_.convert(*input.states, input.own_body, clock, may_wait, tf, samples_,
                      update.reports) == StateIntake::Outcome::kWait) {
    update.waiting = true;
    return update;
  }
  if (samples_.empty()) return update;
  const ros::Time newest = *std::max_element(samples_.stamps.begin(), samples_.stamps.end());
  // The tf-attached obstacles' frames at the newest stamp: looked up once, both to tell
  // whether the input must wait for them and to place them for the step.
  lookUpObstacles(newest, tf, obstacle_motions_);
  if (may_wait && obstacleFrameMissing()) {
    update.waiting = true;
    update.reports.clear();
    return update;
  }
  // The input's newest stamp places it on the time line; its other states keep their distance
  // from it (integer nanoseconds).
  const std::string source = input.topic + " from " + input.publisher;
  const TimeLine::Placed placed = time_line_.place(source, newest, clock, monitor_.now());
  if (placed.dropped_held) dropHeldStates(source, placed, update);
  if (placed.event == TimeLine::Event::kHeld) {
    holdStates(source);
    return update;
  }
  if (placed.event == TimeLine::Event::kJumpedBack) {
    restartTimeLine(source, placed, newest, update);
  } else {
    reportClockOffset(source, placed, newest, update);
  }
  update.stamp = newest;
  update.time = placed.time;
  timeSamples(placed, newest);
  // The states as received (in the fixed frame, on the line), before the monitor takes them.
  live_calibration_.window().record(samples_.samples);
  std::vector<core::ImpactRecord> earlier_impacts;
  stepMovingObstacles(placed, newest, tf, earlier_impacts, update);
  placeObstacles(obstacle_motions_, placed.time, update);
  core::StepReport step = monitor_.step(placed.time, samples_.samples);
  step.impacts.insert(step.impacts.begin(), earlier_impacts.begin(), earlier_impacts.end());
  update.stepped = true;
  ++steps_;
  reportStep(step, update);
  update.stepped_bodies = step.stepped_bodies;
  stepped_bodies_ = step.stepped_bodies;
  publishContacts(step, newest, update);
  publishImpacts(step, newest, update);
  return update;
}

bool MonitorCycle::obstacleFrameMissing() const {
  // The tf-attached obstacles must be known up to the newest stamp as well.
  for (std::size_t i = 0; i < obstacle_motions_.size(); ++i) {
    const ObstacleMotion& motion = obstacle_motions_[i];
    if (motion && !*motion && !frame_jumped_[i]) return true;
  }
  return false;
}

namespace {

/// The bodies of impacts the update's impact work bound cut short (core::StepReport::
/// over_impact_work), named, at most a few: the count says how many.
Report overImpactWorkReport(const core::ImpactMonitor& monitor, const core::StepReport& step) {
  return {Reason::kOverImpactWork,
          "the impacts of " + namedBodies(monitor, step.over_impact_work) +
              " at one instant ran over the update's impact work (" +
              std::to_string(core::MonitorSettings{}.max_impact_work_per_step) +
              " contact iterations): their friction was cut short, or they were locked together "
              "with what touches them (no energy gained, none left approaching another; "
              "doc/model.md, \"Simultaneous contacts\")",
          step.over_impact_work.size()};
}

/// "N s behind" or "N s ahead of" for a clock offset (ns) from the time line.
std::string offsetText(std::int64_t offset) {
  return core::formatNumber(std::abs(static_cast<double>(offset)) * 1e-9) + " s " +
         (offset > 0 ? "behind" : "ahead of");
}

}  // namespace

void MonitorCycle::dropHeldStates(const std::string& source, const TimeLine::Placed& placed,
                                  Update& update) {
  const auto held = held_.find(source);
  const std::size_t states = held == held_.end() ? 1 : held->second.size();
  update.reports.push_back(
      {Reason::kStampOffClock,
       "dropped " + std::to_string(states) + " state(s) of " + source + " stamped header.stamp " +
           formatStamp(placed.held_stamp) +
           ", more than ~clock_jump_back before its clock, and its next message continued "
           "that clock (one stamp off its clock, or a publisher interleaving two clocks): "
           "nothing was reset",
       states});
  if (held != held_.end()) held_.erase(held);
}

void MonitorCycle::holdStates(const std::string& source) {
  // Until the source's next input says whether its clock went back: nothing is stepped.
  if (held_.size() >= TimeLine::kMaxSources && held_.count(source) == 0) {
    held_.erase(held_.begin());
  }
  held_[source] = samples_;
}

void MonitorCycle::restartTimeLine(const std::string& source, const TimeLine::Placed& placed,
                                   const ros::Time& newest, Update& update) {
  update.reports.push_back(
      {Reason::kClockJumpedBack,
       "time jumped back: " + source + " sent header.stamp " + formatStamp(placed.held_stamp) +
           ", more than ~clock_jump_back (" + core::formatNumber(params_.clock_jump_back) +
           " s) before its last, and its next message continued from there (a bag played "
           "with --loop? a simulator restarted?): every track is reset and the time line "
           "starts again there"});
  monitor_.reset();
  live_calibration_.window().clear();
  placed_obstacles_.clear();
  body_clock_.assign(monitor_.bodyCount(), 0);
  body_time_.assign(monitor_.bodyCount(), -std::numeric_limits<double>::infinity());
  // The held input's states enter the new line before this one's (a body in both: this
  // one's).
  const auto held = held_.find(source);
  if (held != held_.end()) {
    const StampedSamples& held_samples = held->second;
    for (std::size_t k = 0; k < held_samples.size(); ++k) {
      const core::BodyStateSample& sample = held_samples.samples[k];
      const bool newer =
          std::any_of(samples_.samples.begin(), samples_.samples.end(),
                      [&](const core::BodyStateSample& x) { return x.body == sample.body; });
      if (!newer && held_samples.stamps[k] <= newest) {
        samples_.push_back(sample, held_samples.stamps[k]);
      }
    }
  }
  held_.clear();  // the line forgot every other source's held stamp too
}

void MonitorCycle::reportClockOffset(const std::string& source, const TimeLine::Placed& placed,
                                     const ros::Time& newest, Update& update) {
  if (placed.event == TimeLine::Event::kOffsetChanged ||
      (placed.event == TimeLine::Event::kStarted && placed.clock_offset != 0)) {
    update.reports.push_back(
        {Reason::kClockOffset,
         source + "'s stamps are " + offsetText(placed.clock_offset) +
             " the time line (this node's clock; the line was started by " +
             time_line_.firstSource() + "; header.stamp " + formatStamp(newest) +
             "): its clock differs. Its states are shifted onto the line by that much (instants "
             "across sources are as good as that alignment; synchronise the clocks for exact "
             "ones); impacts among its bodies keep its clock"});
  } else if (placed.event == TimeLine::Event::kNewClock ||
             placed.event == TimeLine::Event::kSecondClock) {
    const bool second = placed.event == TimeLine::Event::kSecondClock;
    Report report{
        Reason::kClockOffset,
        source + " sent header.stamp " + formatStamp(newest) + ", off its clock by more than " +
            "~clock_jump_back (" + core::formatNumber(params_.clock_jump_back) + " s)" +
            (second ? ": it interleaves two clocks; this one is placed on the line on its own, "
                    : ", or ahead of this node's clock by more than a tenth of it: one odd "
                      "stamp, a publisher interleaving two clocks, or its clock leapt ahead or "
                      "runs fast (a bag played faster than it was recorded, without "
                      "use_sim_time)? Placed on a clock of its own, ") +
            offsetText(placed.clock_offset) +
            " the time line; its other clock and every other source keep theirs"};
    report.variant = second ? 1 : 2;
    update.reports.push_back(std::move(report));
  }
}

void MonitorCycle::timeSamples(const TimeLine::Placed& placed, const ros::Time& newest) {
  if (body_clock_.size() != monitor_.bodyCount()) {
    body_clock_.assign(monitor_.bodyCount(), 0);
    body_time_.assign(monitor_.bodyCount(), -std::numeric_limits<double>::infinity());
  }
  clock_before_ = body_clock_;
  const std::int64_t newest_ns = nanoseconds(newest);
  for (std::size_t k = 0; k < samples_.size(); ++k) {
    core::BodyStateSample& sample = samples_.samples[k];
    sample.time =
        placed.time - static_cast<double>(newest_ns - nanoseconds(samples_.stamps[k])) * 1e-9;
    if (sample.body < body_time_.size() && sample.time > body_time_[sample.body]) {
      body_time_[sample.body] = sample.time;
      body_clock_[sample.body] = placed.clock_offset;
    }
  }
}

void MonitorCycle::reportStep(const core::StepReport& step, Update& update) const {
  if (step.stale_states > 0) {
    update.reports.push_back({Reason::kStale,
                              "dropped " + std::to_string(step.stale_states) +
                                  " state(s) not newer than their body's last state",
                              step.stale_states});
  }
  if (step.states_set_aside > 0) {
    update.reports.push_back(
        {Reason::kSetAside,
         "dropped " + std::to_string(step.states_set_aside) +
             " state(s) older than their body's motion in the monitor (an impact or a change of "
             "lasting contact it found after the state's instant, in the same update): the "
             "monitor's motion from there is kept",
         step.states_set_aside});
  }
  for (const core::ContradictedImpact& contradicted : step.contradicted) {
    // One a body and update, throttled with the others of its reason (doc/model.md, "Bad
    // input, in full").
    update.reports.push_back(
        {Reason::kImpactContradicted,
         "the state of '" + monitor_.body(contradicted.body).id + "' " +
             core::formatNumber(contradicted.state_time - contradicted.impact_time) +
             " s after its impact lacks it (its velocity falls short of the one after the "
             "impact by " +
             core::formatNumber(contradicted.missing) +
             " m/s along the impact's change, more than half of it): the state is its motion from "
             "there, the impact stays published (a source that applies the impacts sends that "
             "state before it hears of it; any other source says the impact did not happen)"});
  }
  if (step.refused_states > 0) {
    // The intake refuses such states first (naming the field): a count here is a state the
    // intake took and the shaped body's motion could not start from.
    update.reports.push_back(
        {Reason::kBadOrientation,
         "dropped " + std::to_string(step.refused_states) +
             " state(s) of shaped bodies whose motion could not start from them (an orientation "
             "that is not a rotation, or a value not finite): their tracks are kept",
         step.refused_states});
  }
  for (const core::UnmodelledContact& contact : step.unmodelled) {
    // Each once, when it begins (a counter, not a drop: the summary stays OK), throttled with
    // the others of its reason; what the model does with the body meanwhile is core::StepReport's.
    update.reports.push_back(
        {Reason::kUnmodelledContact,
         "the contact of " +
             sides(monitor_, contact.body, contact.other, contact.other_is_obstacle) + ", begun " +
             core::formatNumber(monitor_.now() - contact.time) +
             " s before this update's end: " + contact.what +
             (contact.other_is_obstacle ? " (the body is held where it is until its next state)"
                                        : "") +
             " (doc/model.md, \"Shaped bodies in the monitor\")"});
  }
  for (const core::StalledFlight& flight : step.stalled) {
    update.reports.push_back(
        {Reason::kFlightStalled,
         "the flight through air of '" + monitor_.body(flight.body).id + "' stalled " +
             core::formatNumber(monitor_.now() - flight.stalled) +
             " s before this update's end: its integrator could take no further step (a speed "
             "or an air factor too large for it), and the body is held where it got to until "
             "its next state or impact"});
  }
  if (step.truncated) {
    // What remained was resolved by a fallback that puts no body into another
    // (doc/model.md, "Lasting contact"): as one inelastic cluster, or the step's bodies held.
    update.reports.push_back(
        {Reason::kStepTruncated,
         "too many impacts at one instant or in one step; " + std::to_string(step.fallbacks) +
             " fallback(s) (any held sub-step of a stepped cluster among them) resolved the "
             "rest inelastically or held the bodies, outside each other"});
  } else if (step.fallbacks > step.over_budget.size()) {
    // Besides the work budget's, only stepped clusters fall back without truncating the step
    // (core::StepReport): a sub-step whose solve found no velocities keeping every gap held its
    // movable bodies still.
    const std::size_t held = step.fallbacks - step.over_budget.size();
    update.reports.push_back(
        {Reason::kSteppedHeld,
         "a stepped cluster found no velocities that keep every gap open over " +
             std::to_string(held) +
             " sub-step(s) (a body squeezed between immovable bodies or obstacles closing on "
             "it?): its bodies were held still there, and what closes on them may overlap them",
         held});
  }
  if (!step.over_budget.empty()) update.reports.push_back(overBudgetReport(step));
  if (!step.over_impact_work.empty()) {
    update.reports.push_back(overImpactWorkReport(monitor_, step));
  }
  if (!step.over_stepped_work.empty()) {
    update.reports.push_back(
        {Reason::kOverSteppedWork,
         "the stepped clusters of " + namedBodies(monitor_, step.over_stepped_work) +
             " ran over the update's stepped work (" +
             std::to_string(core::MonitorSettings{}.max_stepped_work_per_step) +
             " contact iterations): they were held still over the rest of a sub-step (none "
             "goes into another, no energy gained; doc/model.md, \"Lasting contact\")",
         step.over_stepped_work.size()});
  }
}

Report MonitorCycle::overBudgetReport(const core::StepReport& step) const {
  return {Reason::kOverWorkBudget,
          "the exact model's work on " + namedBodies(monitor_, step.over_budget) +
              " ran over ~scene/exact_work_budget (" +
              std::to_string(monitor_.scene().exact_work_budget) +
              ") in one update (an inelastic collapse, a chattering slip): from there they and "
              "the bodies near them are a stepped cluster until they part (doc/model.md, "
              "\"Lasting contact\")",
          step.over_budget.size()};
}

void MonitorCycle::publishContacts(const core::StepReport& step, const ros::Time& newest,
                                   Update& update) const {
  update.contacts.header.stamp = newest;
  update.contacts.header.frame_id = monitor_.scene().fixed_frame;
  update.contacts.contacts.reserve(step.contacts.size());
  for (const core::ContactRecord& record : step.contacts) {
    ros::Time since;
    const bool stamped = time_line_.stampOf(
        record.since, clockOf(record.since, record.body_a, record.other, record.other_is_obstacle),
        since);
    auto contact = toContactMessage(record, monitor_, since);
    if (contact && stamped) {
      update.contacts.contacts.push_back(std::move(contact.value()));
      continue;
    }
    const std::string why =
        contact ? "since: the instant is not a valid ros::Time" : contact.error().message();
    update.reports.push_back(
        {Reason::kContactNotFinite,
         "did not publish the contact of " +
             sides(monitor_, record.body_a, record.other, record.other_is_obstacle) + ": " + why +
             "; the states were finite, the answer is not"});
  }
}

void MonitorCycle::publishImpacts(const core::StepReport& step, const ros::Time& newest,
                                  Update& update) const {
  update.impacts.header.stamp = newest;
  update.impacts.header.frame_id = monitor_.scene().fixed_frame;
  update.impacts.impacts.reserve(step.impacts.size());
  for (const core::ImpactRecord& record : step.impacts) {
    ros::Time stamp;
    const bool stamped = time_line_.stampOf(
        record.time, clockOf(record.time, record.body_a, record.other, record.other_is_obstacle),
        stamp);
    auto impact = toImpactMessage(record, monitor_, stamp, monitor_.scene().fixed_frame);
    if (impact && stamped) {
      update.impacts.impacts.push_back(std::move(impact.value()));
      continue;
    }
    const std::string why =
        impact ? "header.stamp: the instant is not a valid ros::Time" : impact.error().message();
    update.reports.push_back(
        {Reason::kImpactNotFinite,
         "did not publish the impact of " +
             sides(monitor_, record.body_a, record.other, record.other_is_obstacle) + ": " + why +
             "; the states were finite, the answer is not"});
  }
}

std::int64_t MonitorCycle::clockOf(double time, std::size_t body_a, std::size_t other,
                                   bool other_is_obstacle) const {
  // A body's clock at `time`: its newest state's if that state had entered by then, else the
  // one before (the track the instant was predicted from).
  const auto clockOfBody = [&](std::size_t body) {
    if (body >= body_clock_.size()) return std::int64_t{0};
    return time >= body_time_[body] || body >= clock_before_.size() ? body_clock_[body]
                                                                    : clock_before_[body];
  };
  const std::int64_t a = clockOfBody(body_a);
  if (other_is_obstacle) return a;
  const std::int64_t b = clockOfBody(other);
  return a != b && b == 0 ? b : a;
}

void MonitorCycle::stepMovingObstacles(const TimeLine::Placed& placed, const ros::Time& newest,
                                       const tf2::BufferCore& tf,
                                       std::vector<core::ImpactRecord>& impacts, Update& update) {
  const double period = params_.obstacle_update_period;
  if (!(period > 0) || !monitor_.started()) return;
  // Up to the update's first state (the monitor takes states in time order).
  double until = placed.time;
  for (const core::BodyStateSample& sample : samples_.samples) until = std::min(until, sample.time);
  const double from = monitor_.now();
  const double span = until - from;
  if (!(span > period)) return;
  // Only the obstacles that may reach a body are placed again within the update: a robot's far
  // links cost nothing here, and the placements are bounded (kMaxPlacements).
  findNearObstacles(from, until, placed.time);
  if (near_obstacles_.empty()) return;
  // Sub-steps, the last at `until` (10 ms of 1 ms periods are 10, whatever the rounding).
  const double wanted = std::ceil(span / period - 1e-9);
  const std::size_t near = near_obstacles_.size();
  const double affordable =
      std::floor(static_cast<double>(kMaxPlacements) / static_cast<double>(near)) + 1;
  const int count = static_cast<int>(std::max(1.0, std::min(wanted, affordable)));
  obstacle_work_.near = near;
  if (count < wanted) {
    const auto left_out = static_cast<std::size_t>(wanted - count) * near;
    const std::string names =
        namedList(near, 4, [&](std::size_t k) { return monitor_.obstacle(near_obstacles_[k]).id; });
    update.reports.push_back(
        {Reason::kObstaclePlacementsLeftOut,
         "placed the " + std::to_string(near) + " tf-attached obstacle(s) that may reach a body (" +
             names + ") every " + core::formatNumber(span / count) + " s over this update's " +
             core::formatNumber(span) + " s instead of every ~obstacle_update_period (" +
             core::formatNumber(period) + " s): at most " + std::to_string(kMaxPlacements) +
             " placements an update; " + std::to_string(left_out) +
             " left out (the obstacles moved straight on between the placements made)",
         left_out});
  }
  for (int k = 1; k < count; ++k) {
    const double time = from + span * k / count;
    const ros::Time stamp = newest - ros::Duration(placed.time - time);
    between_motions_.resize(monitor_.obstacleCount());
    explain_missing_ = true;
    chains_.reset();
    for (const std::size_t i : near_obstacles_) lookUpObstacle(i, stamp, tf, between_motions_[i]);
    placeObstacles(between_motions_, time, update, &near_obstacles_);
    const core::StepReport step = monitor_.step(time, {});
    reportStep(step, update);
    impacts.insert(impacts.end(), step.impacts.begin(), step.impacts.end());
  }
}

void MonitorCycle::findNearObstacles(double from, double until, double end) {
  // Bounding spheres, swept. An obstacle's centre goes from c0 (its last placement, at t0,
  // moving at v0) to c1 (its frame's lookup at the update's end, moving at v1): along a path
  // no faster than max(|v0|, |v1|) it stays within that speed times (end - t0) of c1, and along
  // an arc no longer than a half circle within |c1 - c0| of c1 (a half circle's points are
  // nearer either end than its chord); the larger of the two, plus the shape's bounding radius.
  // A tracked body moves from p (its predicted position at `from`) at no more than its speed,
  // what gravity adds (|g| span^2 / 2) and what a moving obstacle's strike can add (twice the
  // fastest obstacle surface's speed): within that distance of p, plus its radius.
  near_obstacles_.clear();
  struct Sphere {
    Eigen::Vector3d centre;
    double radius;
  };
  std::vector<Sphere> links;
  std::vector<std::size_t> indices;
  double fastest = 0.0;  // m/s: the fastest surface point of a moving obstacle
  for (std::size_t i = 0; i < frame_kind_.size(); ++i) {
    if (frame_kind_[i] != FrameKind::kMoving) continue;
    const ObstacleMotion& end_motion = obstacle_motions_[i];
    if (!end_motion || !*end_motion) continue;  // its frame is missing: not looked up again
    const std::optional<core::PlacedShape> last = monitor_.obstaclePose(i);
    if (!last) {  // not placed yet: where it is within the update is not known
      near_obstacles_.push_back(i);
      continue;
    }
    const double reach = core::boundingRadiusOf(last->shape);
    const FrameMotion& motion = end_motion->value();
    const Eigen::Vector3d& offset = monitor_.obstacle(i).position;  // its centre in its frame
    const Eigen::Vector3d c1 = motion.point(offset);
    const double v1 = motion.velocity(offset, Eigen::Vector3d::Zero()).norm();
    const Eigen::Vector3d& c0 = last->pose.transform.translation();
    const double v0 = last->pose.velocity.norm();
    const double speed = std::max(v0, v1);
    const double turning =
        std::max(last->pose.angular_velocity.norm(), motion.angular_velocity.norm());
    if (!std::isfinite(reach)) {  // a plane on a frame: always near
      near_obstacles_.push_back(i);
      continue;
    }
    fastest = std::max(fastest, speed + turning * reach);
    links.push_back({c1, std::max((c1 - c0).norm(), speed * (end - last->pose.time)) + reach});
    indices.push_back(i);
  }
  if (links.empty()) return;
  const double span = until - from;
  const double gravity = monitor_.scene().effects.gravity ? monitor_.scene().gravity.norm() : 0.0;
  std::vector<Sphere> bodies;
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (std::size_t b = 0; b < monitor_.bodyCount(); ++b) {
    const auto state = monitor_.predictedState(b, from);
    if (!state) continue;
    const double reach = monitor_.body(b).radius + (state->second.norm() + 2 * fastest) * span +
                         0.5 * gravity * span * span;
    bodies.push_back({state->first, reach});
    low = low.cwiseMin((state->first.array() - reach).matrix());
    high = high.cwiseMax((state->first.array() + reach).matrix());
  }
  for (std::size_t k = 0; k < links.size(); ++k) {
    const Sphere& link = links[k];
    // The bodies' common box first: a robot's links far from every body cost one test each.
    if ((link.centre.array() + link.radius < low.array()).any() ||
        (link.centre.array() - link.radius > high.array()).any()) {
      continue;
    }
    for (const Sphere& body : bodies) {
      if ((link.centre - body.centre).norm() <= link.radius + body.radius) {
        near_obstacles_.push_back(indices[k]);
        break;
      }
    }
  }
  std::sort(near_obstacles_.begin(), near_obstacles_.end());
}

void MonitorCycle::lookUpObstacle(std::size_t i, const ros::Time& stamp, const tf2::BufferCore& tf,
                                  ObstacleMotion& motion) {
  const std::string& fixed = monitor_.scene().fixed_frame;
  const std::string& frame = monitor_.obstacle(i).frame;
  ++obstacle_work_.lookups;
  // A frame tf does not have is told without an exception and, but for the first of a pass (the
  // one a report names), without tf's text (2,000 missing links an update; a chain deeper than
  // tf walks lists every frame in it).
  const ros::Duration interval(params_.frame_velocity_interval);
  if (frame != fixed && !tf.canTransform(fixed, frame, stamp)) {
    // A chain deeper than tf2 walks (1,000 frames) is followed hop by hop.
    if (tf._frameExists(frame)) {
      if (!chains_) chains_.emplace(tf, fixed);
      motion = chains_->motion(frame, stamp, interval);
    }
    if (!tf._frameExists(frame) || !*motion) {
      std::string why = "not available";
      if (explain_missing_) {
        tf.canTransform(fixed, frame, stamp, &why);
        explain_missing_ = false;
      }
      motion = core::Expected<FrameMotion>(
          core::Error{frame, "no transform to '" + fixed + "' at " + std::to_string(stamp.toSec()) +
                                 ": " + tfErrorText(why)});
      return;
    }
    if (frame_kind_[i] == FrameKind::kUnknown) {
      // Static when the chains of both the frame and the fixed frame are (the one tf2 path
      // beside, a lookup at time zero, asks the same of both).
      frame_kind_[i] = chains_->wholeStatic(frame) && chains_->wholeStatic(fixed)
                           ? FrameKind::kStatic
                           : FrameKind::kMoving;
    }
  } else {
    motion = lookupFrameMotion(tf, fixed, frame, stamp, interval);
  }
  frame_jumped_[i] = 0;
  if (*motion) {
    // Its surface's speed: its centre's, and its turning's at its bounding radius (once placed).
    const FrameMotion& found = motion->value();
    const std::optional<core::PlacedShape> last = monitor_.obstaclePose(i);
    const double reach = last ? core::boundingRadiusOf(last->shape) : 0.0;
    const double turning = found.angular_velocity.norm();
    const double speed =
        found.velocity(monitor_.obstacle(i).position, Eigen::Vector3d::Zero()).norm() +
        (turning > 0 ? turning * reach : 0.0);
    if (!(speed <= kMaxFrameSpeed)) {
      frame_jumped_[i] = 1;
      motion = core::Expected<FrameMotion>(core::Error{
          frame, "moves at " + core::formatNumber(speed) + " m/s at " +
                     std::to_string(stamp.toSec()) + " (tf's backward difference over " +
                     core::formatNumber(params_.frame_velocity_interval) + " s), faster than " +
                     core::formatNumber(kMaxFrameSpeed) +
                     " m/s: a jump between its tf samples, which no body could follow"});
      return;
    }
  }
  if (frame_kind_[i] != FrameKind::kUnknown || !*motion) return;
  // Wholly on /tf_static: tf stamps its latest transform zero (no time in the chain).
  try {
    frame_kind_[i] = tf.lookupTransform(fixed, frame, ros::Time(0)).header.stamp.isZero()
                         ? FrameKind::kStatic
                         : FrameKind::kMoving;
  } catch (const tf2::TransformException&) {
    frame_kind_[i] = FrameKind::kMoving;
  }
}

void MonitorCycle::lookUpObstacles(const ros::Time& stamp, const tf2::BufferCore& tf,
                                   std::vector<ObstacleMotion>& motions) {
  motions.resize(monitor_.obstacleCount());
  explain_missing_ = true;
  chains_.reset();
  std::size_t rechecks = 0;
  for (std::size_t i = 0; i < monitor_.obstacleCount(); ++i) {
    if (frame_kind_[i] == FrameKind::kFixed) {
      motions[i].reset();
      continue;
    }
    // A static frame known and placed stays where it is; a few are looked up again in turn
    // (a static transform published anew), below.
    if (frame_kind_[i] == FrameKind::kStatic && motions[i] && *motions[i] &&
        placed_obstacles_.count(i) != 0) {
      continue;
    }
    lookUpObstacle(i, stamp, tf, motions[i]);
  }
  for (std::size_t n = 0; n < frame_kind_.size() && rechecks < kStaticRechecks; ++n) {
    const std::size_t i = next_recheck_++ % frame_kind_.size();
    if (frame_kind_[i] != FrameKind::kStatic || placed_obstacles_.count(i) == 0 || !motions[i] ||
        !*motions[i]) {
      continue;
    }
    ++rechecks;
    const Eigen::Isometry3d was = (*motions[i])->pose;
    lookUpObstacle(i, stamp, tf, motions[i]);
    if (!*motions[i] || !(*motions[i])->pose.isApprox(was, 0.0)) placed_obstacles_.erase(i);
  }
}

void MonitorCycle::placeObstacles(const std::vector<ObstacleMotion>& motions, double time,
                                  Update& update, const std::vector<std::size_t>* which) {
  // The frames missing, said in one report each for those placed before (warned) and those
  // never placed (counted only: tf has no history yet for their velocity).
  constexpr std::size_t kNamed = 4;
  struct Missing {
    std::size_t count = 0;
    std::string names, first_error;
  } missing[3];  // never placed, placed before, jumped
  const std::size_t n = which ? which->size() : motions.size();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = which ? (*which)[k] : k;
    if (!motions[i]) continue;  // a fixed obstacle
    const core::Expected<FrameMotion>& motion = *motions[i];
    if (!motion) {
      Missing& m = missing[frame_jumped_[i] ? 2 : placed_obstacles_.count(i) != 0 ? 1 : 0];
      if (m.count < kNamed) m.names += (m.count ? ", '" : "'") + monitor_.obstacle(i).id + "'";
      if (m.count == 0) m.first_error = motion.error().message();
      ++m.count;
      continue;
    }
    if (frame_kind_[i] == FrameKind::kStatic && !placed_obstacles_.insert(i).second) continue;
    placed_obstacles_.insert(i);
    ++obstacle_work_.placements;
    core::RigidPose frame;  // the core places the obstacle's shape on it
    frame.time = time;
    frame.transform = motion->pose;
    frame.velocity = motion->linear_velocity;
    frame.angular_velocity = motion->angular_velocity;
    monitor_.setObstaclePose(i, frame);
  }
  for (int kind = 0; kind < 3; ++kind) {
    const Missing& m = missing[kind];
    if (m.count == 0) continue;
    const std::string more =
        m.count > kNamed ? " and " + std::to_string(m.count - kNamed) + " more" : "";
    Report item{kind == 2 ? Reason::kFrameJumped : Reason::kObstacleTransform,
                (m.count == 1 ? "obstacle " + m.names + " keeps its last known motion: "
                              : "obstacles " + m.names + more + " keep their last known motion; " +
                                    "the first's: ") +
                    m.first_error,
                m.count};
    item.warn = kind != 0;
    update.reports.push_back(std::move(item));
  }
}

void MonitorCycle::tune(core::Detection detection, double restitution_threshold,
                        core::CombineRule rule) {
  // The monitor holds the scene: the new rule is set on its materials, and its scene says the
  // tuned values from then on.
  core::MaterialTable materials = monitor_.scene().materials;
  materials.setCombineRule(rule);
  monitor_.tune(detection, restitution_threshold, materials);
}

}  // namespace collision_response
