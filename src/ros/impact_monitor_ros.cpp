#include "collision_response/ros/impact_monitor_ros.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "collision_response/core/validation.h"
#include "collision_response/ros/conversions.h"
#include "collision_response/ros/frame_motion.h"

namespace collision_response {
namespace {

/// The first non-finite number of a state, named as its field; empty when all are finite.
std::string firstNonFinite(const BodyState& state) {
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
  for (const auto& [name, value] : fields) {
    if (!std::isfinite(value)) {
      return std::string(name) + ": must be a finite number, got " + core::formatNumber(value);
    }
  }
  return "";
}

std::string frameOf(const BodyState& state, const std::string& fixed_frame) {
  std::string frame = state.header.frame_id;
  if (!frame.empty() && frame.front() == '/') frame.erase(0, 1);  // tf2 frames have no slash
  return frame.empty() ? fixed_frame : frame;
}

geometry_msgs::Twist toTwist(const Eigen::Vector3d& linear, const Eigen::Vector3d& angular) {
  geometry_msgs::Twist twist;
  twist.linear = toVector3Msg(linear);
  twist.angular = toVector3Msg(angular);
  return twist;
}

core::Status readPositive(const ros::NodeHandle& node, const std::string& key, double& value,
                          bool allow_zero) {
  node.param(key, value, value);
  if (!std::isfinite(value) || value < 0.0 || (!allow_zero && value == 0.0)) {
    return core::Error{node.resolveName(key), std::string("must be a finite number ") +
                                                  (allow_zero ? ">= 0" : "> 0") + ", got " +
                                                  core::formatNumber(value)};
  }
  return core::Ok{};
}

}  // namespace

core::Expected<MonitorParams> MonitorParams::load(const ros::NodeHandle& private_node) {
  MonitorParams params;
  if (auto s = readPositive(private_node, "transform_timeout", params.transform_timeout, true);
      !s) {
    return s.error();
  }
  if (auto s = readPositive(private_node, "frame_velocity_interval", params.frame_velocity_interval,
                            false);
      !s) {
    return s.error();
  }
  if (auto s = readPositive(private_node, "body_timeout", params.body_timeout, false); !s) {
    return s.error();
  }
  if (auto s = readPositive(private_node, "contact_tolerance", params.contact_tolerance, true);
      !s) {
    return s.error();
  }
  if (auto s = readPositive(private_node, "clock_jump_back", params.clock_jump_back, false); !s) {
    return s.error();
  }
  for (const auto& [key, value] :
       {std::make_pair("marker_rate", &params.markers.rate),
        std::make_pair("impact_marker_lifetime", &params.markers.impact_lifetime),
        std::make_pair("impulse_marker_scale", &params.markers.impulse_scale),
        std::make_pair("plane_marker_size", &params.markers.plane_size),
        std::make_pair("contact_marker_diameter", &params.markers.contact_diameter)}) {
    if (auto s = readPositive(private_node, key, *value, false); !s) return s.error();
  }
  private_node.param("max_states", params.max_states, params.max_states);
  if (params.max_states < 1) {
    return core::Error{private_node.resolveName("max_states"),
                       "must be >= 1, got " + std::to_string(params.max_states)};
  }
  private_node.param("queue_size", params.queue_size, params.queue_size);
  if (params.queue_size < 1) {
    return core::Error{private_node.resolveName("queue_size"),
                       "must be >= 1, got " + std::to_string(params.queue_size)};
  }
  return params;
}

ImpactMonitorRos::ImpactMonitorRos(ros::NodeHandle node, const core::Scene& scene,
                                   const MonitorParams& params)
    : node_(node),
      params_(params),
      scene_(scene),
      monitor_(scene, core::MonitorSettings{params.contact_tolerance, params.body_timeout}),
      tf_listener_(tf_buffer_, node) {
  array_subscriber_ = node_.subscribe("body_states", 100, &ImpactMonitorRos::onStateArray, this);
  for (const core::BodySpec& body : scene_.bodies) {
    if (body.topic.empty()) continue;
    body_subscribers_.push_back(node_.subscribe<BodyState>(
        body.topic, 100, [this, topic = body.topic, id = body.id](const BodyState::ConstPtr& m) {
          onState(m, topic, id);
        }));
  }
  impact_publisher_ = node_.advertise<ImpactArray>("impacts", 100);
  marker_publisher_ = node_.advertise<visualization_msgs::MarkerArray>("markers", 10);
  // Retries inputs that wait for transforms; it runs only while some input waits.
  queue_timer_ = node_.createWallTimer(
      ros::WallDuration(0.005), [this](const ros::WallTimerEvent&) { processQueue(); },
      /*oneshot=*/false, /*autostart=*/false);
}

void ImpactMonitorRos::onStateArray(const BodyStateArray::ConstPtr& message) {
  const std::string topic = array_subscriber_.getTopic();
  ++period_.messages;
  period_.states += message->states.size();
  if (message->states.size() > static_cast<std::size_t>(params_.max_states)) {
    count("dropped: too many states in one message");
    warnings_.warn(topic + " size",
                   topic +
                       ": dropped a message: states: " + std::to_string(message->states.size()) +
                       " states exceed ~max_states (" + std::to_string(params_.max_states) + ")");
    return;
  }
  enqueue(Pending{ros::WallTime::now(), topic, message, {}});
}

void ImpactMonitorRos::onState(const BodyState::ConstPtr& message, const std::string& topic,
                               const std::string& id) {
  ++period_.messages;
  ++period_.states;
  BodyState state = *message;
  if (state.id.empty()) state.id = id;  // the topic names the body
  if (state.id != id) {
    count("dropped: id does not match the topic");
    warnings_.warn(topic + " id", topic + ": dropped a state: id: '" + state.id +
                                      "' does not match this topic's body '" + id + "'");
    return;
  }
  enqueue(Pending{ros::WallTime::now(), topic, nullptr, {state}});
}

void ImpactMonitorRos::enqueue(Pending pending) {
  if (queue_.size() >= static_cast<std::size_t>(params_.queue_size)) {
    count("dropped: input queue full");
    ROS_WARN_STREAM_THROTTLE(1.0, "collision_response: input queue full ("
                                      << params_.queue_size << " messages waiting for transforms); "
                                      << "dropped the oldest");
    queue_.pop_front();
  }
  queue_.push_back(std::move(pending));
  processQueue();
}

void ImpactMonitorRos::processQueue() {
  try {
    while (!queue_.empty() && processHead()) queue_.pop_front();
  } catch (const std::exception& error) {
    // Never let an exception out of a callback: drop the message that caused it and go on.
    count("dropped: internal error");
    ROS_ERROR_STREAM_THROTTLE(1.0, "collision_response: dropped a message: " << error.what());
    if (!queue_.empty()) queue_.pop_front();
  }
  if (queue_.empty()) {
    queue_timer_.stop();
  } else {
    queue_timer_.start();  // no effect when already running
  }
}

bool ImpactMonitorRos::processHead() {
  const Pending& head = queue_.front();
  const bool may_wait = (ros::WallTime::now() - head.received).toSec() < params_.transform_timeout;
  std::vector<Converted> converted;
  converted.reserve(head.states().size());
  std::optional<core::Expected<FrameMotion>> motion;
  std::string motion_frame;
  ros::Time motion_stamp;
  const std::vector<BodyState>& states = head.states();
  if (index_hints_.size() < states.size()) index_hints_.resize(states.size(), 0);
  for (std::size_t place = 0; place < states.size(); ++place) {
    const BodyState& state = states[place];
    // A source sends its bodies in the same order every time: the body found at this place
    // in the last array is tried before the lookup by id.
    std::optional<std::size_t> index;
    const std::size_t hint = index_hints_[place];
    if (hint < monitor_.bodyCount() && monitor_.body(hint).id == state.id) {
      index = hint;
    } else {
      index = monitor_.bodyIndex(state.id);
      if (index) index_hints_[place] = *index;
    }
    if (!index) {
      count("dropped: unknown id");
      warnings_.warn(
          head.source + " id " + state.id,
          head.source + ": dropped a state: id: " +
              (state.id.empty() ? std::string("is empty")
                                : "unknown body '" + state.id + "' (not in the scene's bodies)"));
      continue;
    }
    if (state.header.stamp.isZero()) {
      count("dropped: zero stamp");
      warnings_.warn(head.source + " stamp", head.source + ": dropped the state of '" + state.id +
                                                 "': header.stamp: is zero; a state needs the "
                                                 "instant it holds");
      continue;
    }
    if (const std::string bad = firstNonFinite(state); !bad.empty()) {
      count("dropped: non-finite value");
      warnings_.warn(head.source + " " + bad.substr(0, bad.find(':')),
                     head.source + ": dropped the state of '" + state.id + "': " + bad);
      continue;
    }
    const std::string frame = frameOf(state, scene_.fixed_frame);
    // The states of an array usually share a frame and a stamp: one lookup serves them all.
    if (!motion || frame != motion_frame || state.header.stamp != motion_stamp) {
      motion = lookupFrameMotion(tf_buffer_, scene_.fixed_frame, frame, state.header.stamp,
                                 ros::Duration(params_.frame_velocity_interval));
      motion_frame = frame;
      motion_stamp = state.header.stamp;
    }
    if (!*motion) {
      if (may_wait) return false;
      count("dropped: transform missing");
      warnings_.warn(head.source + " frame " + frame,
                     head.source + ": dropped the state of '" + state.id + "' after waiting " +
                         core::formatNumber(params_.transform_timeout) +
                         " s: header.frame_id: " + motion->error().message());
      continue;
    }
    const Eigen::Vector3d position = toEigen(state.pose.position);
    Converted item;
    item.stamp = state.header.stamp;
    item.sample.body = *index;
    const FrameMotion& frame_motion = **motion;
    item.sample.position = frame_motion.point(position);
    item.sample.velocity = frame_motion.velocity(position, toEigen(state.twist.linear));
    item.sample.angular_velocity =
        frame_motion.pose.linear() * toEigen(state.twist.angular) + frame_motion.angular_velocity;
    converted.push_back(item);
  }
  if (converted.empty()) return true;

  // The tf-attached obstacles must be known up to the newest stamp as well.
  const ros::Time newest =
      std::max_element(converted.begin(), converted.end(), [](const auto& x, const auto& y) {
        return x.stamp < y.stamp;
      })->stamp;
  if (may_wait) {
    for (const core::ObstacleSpec& obstacle : scene_.obstacles) {
      if (!obstacle.frame.empty() &&
          !lookupFrameMotion(tf_buffer_, scene_.fixed_frame, obstacle.frame, newest,
                             ros::Duration(params_.frame_velocity_interval))) {
        return false;
      }
    }
  }

  // One step per distinct stamp, oldest first.
  const auto older = [](const Converted& x, const Converted& y) { return x.stamp < y.stamp; };
  if (!std::is_sorted(converted.begin(), converted.end(), older)) {
    std::stable_sort(converted.begin(), converted.end(), older);
  }
  for (std::size_t begin = 0; begin < converted.size();) {
    std::size_t end = begin;
    std::vector<core::BodyStateSample> samples;
    samples.reserve(converted.size() - begin);
    while (end < converted.size() && converted[end].stamp == converted[begin].stamp) {
      samples.push_back(converted[end].sample);
      ++end;
    }
    step(converted[begin].stamp, samples);
    begin = end;
  }
  const double latency = (ros::WallTime::now() - head.received).toSec();
  period_.latency_seconds += latency;
  period_.latency_seconds_max = std::max(period_.latency_seconds_max, latency);
  ++period_.latencies;
  return true;
}

void ImpactMonitorRos::step(const ros::Time& stamp,
                            const std::vector<core::BodyStateSample>& samples) {
  const ros::WallTime began = ros::WallTime::now();
  if (!monitor_.started()) epoch_ = stamp;
  if (monitor_.started() && toLine(stamp) < monitor_.now() - params_.clock_jump_back) {
    count("clock jumped back");
    ROS_WARN_STREAM("collision_response: time jumped back by "
                    << monitor_.now() - toLine(stamp)
                    << " s (a bag played with --loop?): every track is reset");
    monitor_.reset();
    epoch_ = stamp;
  }
  std::vector<core::BodyStateSample> timed = samples;
  for (core::BodyStateSample& sample : timed) sample.time = toLine(stamp);
  updateObstacles(stamp);
  const core::StepReport report = monitor_.step(toLine(stamp), timed);
  if (report.stale_states > 0) {
    counters_["dropped: stamp not newer than the body's last"] += report.stale_states;
    ROS_WARN_STREAM_THROTTLE(1.0, "collision_response: dropped "
                                      << report.stale_states
                                      << " state(s) not newer than their body's last state");
  }
  if (report.truncated) {
    count("steps truncated");
    ROS_WARN_STREAM_THROTTLE(1.0,
                             "collision_response: too many impacts at one instant or in one "
                             "step; the step was cut short");
  }
  publish(stamp, report);
  const double seconds = (ros::WallTime::now() - began).toSec();
  period_.step_seconds += seconds;
  period_.step_seconds_max = std::max(period_.step_seconds_max, seconds);
  ++period_.steps;
}

void ImpactMonitorRos::updateObstacles(const ros::Time& stamp) {
  for (std::size_t i = 0; i < monitor_.obstacleCount(); ++i) {
    const core::ObstacleSpec& spec = monitor_.obstacle(i);
    if (spec.frame.empty()) continue;
    const auto motion = lookupFrameMotion(tf_buffer_, scene_.fixed_frame, spec.frame, stamp,
                                          ros::Duration(params_.frame_velocity_interval));
    if (!motion) {
      count("obstacle transform missing");
      if (placed_obstacles_.count(i) == 0) {
        // The frame's first instants: tf has no history yet for its velocity.
        ROS_DEBUG_STREAM("collision_response: obstacle '"
                         << spec.id << "' not placed yet: " << motion.error().message());
      } else {
        ROS_WARN_STREAM_THROTTLE(
            1.0, "collision_response: obstacle '"
                     << spec.id << "' keeps its last known motion: " << motion.error().message());
      }
      continue;
    }
    placed_obstacles_.insert(i);
    core::ObstaclePose pose;
    pose.time = toLine(stamp);
    pose.angular_velocity = motion->angular_velocity;
    if (spec.shape == core::ObstacleShape::kSphere) {
      pose.position = motion->point(spec.position);
      pose.velocity = motion->velocity(spec.position, Eigen::Vector3d::Zero());
    } else {
      const Eigen::Vector3d unit_normal = spec.normal.normalized();
      pose.normal = motion->pose.linear() * unit_normal;
      pose.position = motion->point(unit_normal * spec.offset);  // a point of the plane
      pose.offset = pose.normal.dot(pose.position);
      pose.velocity = motion->velocity(unit_normal * spec.offset, Eigen::Vector3d::Zero());
    }
    monitor_.setObstaclePose(i, pose);
  }
}

void ImpactMonitorRos::publish(const ros::Time& stamp, const core::StepReport& report) {
  ImpactArray array;
  array.header.stamp = stamp;
  array.header.frame_id = scene_.fixed_frame;
  for (const core::ImpactRecord& record : report.impacts) {
    Impact impact;
    impact.header.stamp = epoch_ + ros::Duration(record.time);
    impact.header.frame_id = scene_.fixed_frame;
    impact.body_a = monitor_.body(record.body_a).id;
    impact.body_b = record.other_is_obstacle ? monitor_.obstacle(record.other).id
                                             : monitor_.body(record.other).id;
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
    array.impacts.push_back(impact);
    ROS_DEBUG_STREAM("impact " << impact.body_a << " -> " << impact.body_b << " at "
                               << impact.header.stamp << ", impulse " << impact.impulse);
  }
  if (!array.impacts.empty()) {
    counters_["impacts published"] += array.impacts.size();
    period_.impacts += array.impacts.size();
    impact_publisher_.publish(array);
  }
  if (marker_publisher_.getNumSubscribers() > 0) publishMarkers(stamp, array);
}

void ImpactMonitorRos::publishMarkers(const ros::Time& stamp, const ImpactArray& impacts) {
  visualization_msgs::MarkerArray markers;
  for (const Impact& impact : impacts.impacts) {
    appendImpactMarkers(impact, next_impact_marker_, params_.markers, markers);
    next_impact_marker_ = (next_impact_marker_ + 1) % kImpactIds;
  }
  const ros::WallTime now = ros::WallTime::now();
  if ((now - last_scene_markers_).toSec() >= 1.0 / params_.markers.rate) {
    last_scene_markers_ = now;
    const double time = toLine(stamp);
    for (std::size_t i = 0; i < monitor_.bodyCount(); ++i) {
      const auto state = monitor_.predictedState(i, time);
      markers.markers.push_back(
          bodyMarker(monitor_.body(i), static_cast<int>(i),
                     state ? std::optional<Eigen::Vector3d>(state->first) : std::nullopt,
                     scene_.fixed_frame, stamp));
    }
    for (std::size_t i = 0; i < monitor_.obstacleCount(); ++i) {
      const auto pose = monitor_.obstaclePose(i);
      if (!pose) continue;  // a tf-attached obstacle not placed yet
      const core::ObstacleSpec& spec = monitor_.obstacle(i);
      const Eigen::Vector3d position = spec.shape == core::ObstacleShape::kSphere
                                           ? Eigen::Vector3d(pose->position)
                                           : Eigen::Vector3d(pose->offset * pose->normal);
      markers.markers.push_back(obstacleMarker(spec, static_cast<int>(i), position, pose->normal,
                                               scene_.fixed_frame, stamp, params_.markers));
    }
  }
  if (!markers.markers.empty()) marker_publisher_.publish(markers);
}

void ImpactMonitorRos::tune(core::Detection detection, double restitution_threshold,
                            core::CombineRule rule) {
  scene_.detection = detection;
  scene_.restitution_threshold = restitution_threshold;
  scene_.materials.setCombineRule(rule);
  monitor_.tune(detection, restitution_threshold, scene_.materials);
}

void ImpactMonitorRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const ros::WallTime now = ros::WallTime::now();
  const double seconds = std::max((now - period_.start).toSec(), 1e-9);
  std::map<std::string, std::uint64_t> dropped;  // in this period, by reason
  for (const auto& [what, count] : counters_) {
    const std::uint64_t before = period_.counters.count(what) ? period_.counters.at(what) : 0;
    if (count > before && what.rfind("dropped", 0) == 0) dropped[what] = count - before;
  }
  if (!dropped.empty()) {
    std::string reasons;
    for (const auto& [what, count] : dropped) {
      reasons += (reasons.empty() ? "" : "; ") + what.substr(std::string("dropped: ").size()) +
                 " (" + std::to_string(count) + ")";
    }
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "states dropped: " + reasons);
  } else if (period_.messages == 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                   "no states received in the last " + core::formatNumber(seconds) + " s");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                   std::to_string(monitor_.trackedBodies()) + " bodies tracked");
  }
  status.add("detection", core::toString(scene_.detection));
  status.add("restitution threshold (m/s)", scene_.restitution_threshold);
  status.add("combine rule", core::toString(scene_.materials.combineRule()));
  status.add("bodies in the scene", monitor_.bodyCount());
  status.add("bodies tracked", monitor_.trackedBodies());
  status.add("input messages per second", static_cast<double>(period_.messages) / seconds);
  status.add("states per second", static_cast<double>(period_.states) / seconds);
  status.add("impacts per second", static_cast<double>(period_.impacts) / seconds);
  status.add("updates", period_.steps);
  status.add("processing time per update, mean (ms)",
             period_.steps ? 1e3 * period_.step_seconds / static_cast<double>(period_.steps) : 0.0);
  status.add("processing time per update, max (ms)", 1e3 * period_.step_seconds_max);
  status.add("arrival to publication, mean (ms)",
             period_.latencies
                 ? 1e3 * period_.latency_seconds / static_cast<double>(period_.latencies)
                 : 0.0);
  status.add("arrival to publication, max (ms)", 1e3 * period_.latency_seconds_max);
  status.add("messages waiting for transforms", queue_.size());
  const auto total = [this](const std::string& what) {
    const auto found = counters_.find(what);
    return found == counters_.end() ? std::uint64_t{0} : found->second;
  };
  status.add("transforms missing (states dropped, total)", total("dropped: transform missing"));
  status.add("obstacle transforms missing (total)", total("obstacle transform missing"));
  for (const auto& [what, count] : counters_) status.add(what + " (total)", count);
  period_ = Period{};
  period_.counters = counters_;
}

}  // namespace collision_response
