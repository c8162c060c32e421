#include "collision_response/ros/impact_monitor_ros.h"

#include <map>
#include <utility>

#include "collision_response/core/validation.h"
#include "collision_response/ros/prediction_service.h"

namespace collision_response {

ImpactMonitorRos::ImpactMonitorRos(ros::NodeHandle node, const core::Scene& scene,
                                   const MonitorParams& params)
    : node_(node), params_(params), cycle_(scene, params), tf_listener_(tf_buffer_, node) {
  array_subscriber_ = node_.subscribe("body_states", 100, &ImpactMonitorRos::onStateArray, this);
  array_topic_ = array_subscriber_.getTopic();
  for (const core::BodySpec& body : scene.bodies) {
    if (body.topic.empty()) continue;
    const std::string topic = node_.resolveName(body.topic);
    body_subscribers_.push_back(node_.subscribe<BodyState>(
        topic, 100, [this, topic, id = body.id](const ros::MessageEvent<const BodyState>& event) {
          onState(event, topic, id);
        }));
  }
  impact_publisher_ = node_.advertise<ImpactArray>("impacts", 100);
  contact_publisher_ = node_.advertise<ContactArray>("contacts", 100);
  marker_publisher_ = node_.advertise<visualization_msgs::MarkerArray>("markers", 10);
  // Retries inputs that wait for transforms; it runs only while some input waits.
  queue_timer_ = node_.createWallTimer(
      ros::WallDuration(0.005), [this](const ros::WallTimerEvent&) { processQueue(); },
      /*oneshot=*/false, /*autostart=*/false);
  figures_ = MonitorFigures::of(cycle_);
}

void ImpactMonitorRos::onStateArray(const ros::MessageEvent<const BodyStateArray>& event) {
  const BodyStateArray::ConstPtr message = event.getConstMessage();
  {
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    diagnostics_.received(message->states.size());
  }
  if (message->states.size() > static_cast<std::size_t>(params_.max_states)) {
    tell(array_topic_,
         {{Reason::kTooManyStates,
           "dropped a message: states: " + std::to_string(message->states.size()) +
               " states exceed ~max_states (" + std::to_string(params_.max_states) + ")"}});
    return;
  }
  enqueue(Pending{ros::WallTime::now(), array_topic_, event.getPublisherName(), "", message, {}});
}

void ImpactMonitorRos::onState(const ros::MessageEvent<const BodyState>& event,
                               const std::string& topic, const std::string& id) {
  {
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    diagnostics_.received(1);
  }
  enqueue(Pending{ros::WallTime::now(),
                  topic,
                  event.getPublisherName(),
                  id,
                  nullptr,
                  {*event.getConstMessage()}});
}

void ImpactMonitorRos::enqueue(Pending pending) {
  // At most ~queue_size inputs and ~max_states states wait: the oldest make room.
  const std::size_t states = pending.states().size();
  while (!queue_.empty() &&
         (queue_.size() >= static_cast<std::size_t>(params_.queue_size) ||
          queued_states_ + states > static_cast<std::size_t>(params_.max_states))) {
    tell(queue_.front().topic,
         {{Reason::kQueueFull,
           "input queue full (" + std::to_string(queue_.size()) + " messages, " +
               std::to_string(queued_states_) + " states waiting for transforms; ~queue_size " +
               std::to_string(params_.queue_size) + ", ~max_states " +
               std::to_string(params_.max_states) + "): dropped the oldest",
           queue_.front().states().size()}});
    queued_states_ -= queue_.front().states().size();
    queue_.pop_front();
  }
  queued_states_ += states;
  queue_.push_back(std::move(pending));
  processQueue();
}

void ImpactMonitorRos::processQueue() {
  while (!queue_.empty()) {
    bool handled = true;
    try {
      handled = processHead();
    } catch (const std::exception& error) {
      // Never let an exception out of a callback: drop the message that caused it and go on.
      tell(queue_.front().topic,
           {{Reason::kInternalError, std::string("dropped a message: ") + error.what(),
             queue_.front().states().size()}});
    }
    if (!handled) break;
    queued_states_ -= queue_.front().states().size();
    queue_.pop_front();
  }
  {
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    waiting_ = queue_.size();
  }
  if (queue_.empty()) {
    queue_timer_.stop();
  } else {
    queue_timer_.start();  // no effect when already running
  }
}

bool ImpactMonitorRos::processHead() {
  const Pending& head = queue_.front();
  const ros::WallTime began = ros::WallTime::now();
  const bool may_wait = (began - head.received).toSec() < params_.transform_timeout;
  const MonitorCycle::Input input{&head.states(), head.topic, head.publisher, head.own_body};
  {
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    update_began_ = began;
  }
  const MonitorCycle::Update update = cycle_.process(input, ros::Time::now(), may_wait, tf_buffer_);
  {
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    update_began_ = ros::WallTime();
    figures_ = MonitorFigures::of(cycle_);
  }
  if (update.waiting) return false;
  tell(head.topic, update.reports);
  if (update.stepped) {
    publish(update);
    const ros::WallTime done = ros::WallTime::now();
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    diagnostics_.stepped((done - began).toSec(), (done - head.received).toSec(),
                         update.impacts.impacts.size());
  }
  return true;
}

void ImpactMonitorRos::publish(const MonitorCycle::Update& update) {
  if (!update.impacts.impacts.empty()) impact_publisher_.publish(update.impacts);
  // At each input while contacts last, and one empty array when the last one ends.
  const bool contacts = !update.contacts.contacts.empty();
  if (contacts || contacts_published_) contact_publisher_.publish(update.contacts);
  contacts_published_ = contacts;
  if (marker_publisher_.getNumSubscribers() > 0) publishMarkers(update);
}

void ImpactMonitorRos::publishMarkers(const MonitorCycle::Update& update) {
  visualization_msgs::MarkerArray markers;
  for (const Impact& impact : update.impacts.impacts) {
    appendImpactMarkers(impact, next_impact_marker_, params_.markers, markers);
    next_impact_marker_ = (next_impact_marker_ + 1) % kImpactIds;
  }
  const ros::WallTime now = ros::WallTime::now();
  if ((now - last_scene_markers_).toSec() >= 1.0 / params_.markers.rate) {
    last_scene_markers_ = now;
    appendSceneMarkers(cycle_.monitor(), update.time, cycle_.scene().fixed_frame, update.stamp,
                       params_.markers, markers);
    appendContactMarkers(update.contacts, contact_markers_, params_.markers, markers);
    contact_markers_ = update.contacts.contacts.size();
  } else if (update.contacts.contacts.size() < contact_markers_) {
    // A contact ended: its markers go at once, not at the next scene markers.
    appendContactMarkers(update.contacts, contact_markers_, params_.markers, markers);
    contact_markers_ = update.contacts.contacts.size();
  }
  if (!markers.markers.empty()) marker_publisher_.publish(markers);
}

void ImpactMonitorRos::tell(const std::string& topic, const std::vector<Report>& reports) {
  // Grouped by reason: one warning (throttled) stands for all the reports of its reason.
  struct Group {
    const Report* first = nullptr;
    std::size_t events = 0;
  };
  std::map<std::pair<Reason, int>, Group> groups;
  std::unique_lock<std::mutex> lock(diagnostics_mutex_);
  for (const Report& report : reports) {
    diagnostics_.count(report.reason, report.count);
    if (report.reason == Reason::kBeyondResolution) diagnostics_.noteBeyondResolution(report.text);
    if (report.reason == Reason::kOverWorkBudget) diagnostics_.noteOverWorkBudget(report.text);
    Group& group = groups[{report.reason, report.variant}];
    group.events += report.count;
    if (report.warn && group.first == nullptr) group.first = &report;
  }
  lock.unlock();
  for (const auto& [key, group] : groups) {
    if (group.first == nullptr) continue;
    std::string text = group.first->text;
    if (group.events > group.first->count) {
      text += " (" + std::to_string(group.events - group.first->count) + " more in this message)";
    }
    warnings_.warn(topic, key.first, text, group.events, key.second);
  }
}

void ImpactMonitorRos::tune(core::Detection detection, double restitution_threshold,
                            core::CombineRule rule) {
  cycle_.tune(detection, restitution_threshold, rule);
  std::lock_guard<std::mutex> lock(diagnostics_mutex_);
  figures_ = MonitorFigures::of(cycle_);
}

void ImpactMonitorRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(diagnostics_mutex_);
  const double running =
      update_began_.isZero() ? 0.0 : (ros::WallTime::now() - update_began_).toSec();
  // An update that has run for 1 s turns the summary to WARN.
  diagnostics_.report(status, figures_, waiting_, running, 1.0);
}

void ImpactMonitorRos::predict(const PredictImpacts::Request& request,
                               PredictImpacts::Response& response) const {
  answerPredictImpacts(request, cycle_, tf_buffer_, ros::Time::now(), response);
}

}  // namespace collision_response
