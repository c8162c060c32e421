#include "collision_response/ros/impact_monitor_ros.h"

#include <algorithm>
#include <functional>
#include <map>
#include <utility>

#include "collision_response/core/prediction.h"
#include "collision_response/core/validation.h"
#include "collision_response/ros/prediction_service.h"

namespace collision_response {

namespace {

/// A call of `function` on a callback queue (the monitor's wake-up).
class FunctionCall : public ros::CallbackInterface {
 public:
  explicit FunctionCall(std::function<void()> function) : function_(std::move(function)) {}
  CallResult call() override {
    function_();
    return Success;
  }

 private:
  std::function<void()> function_;
};

/// Whether a reason drops input states (the others: outputs, or nothing dropped).
bool dropsInput(Reason reason) {
  return isDrop(reason) && reason != Reason::kImpactNotFinite &&
         reason != Reason::kContactNotFinite;
}

}  // namespace

ImpactMonitorRos::ImpactMonitorRos(ros::NodeHandle node, const core::Scene& scene,
                                   const MonitorParams& params)
    : node_(node), params_(params), cycle_(scene, params), tf_listener_(tf_buffer_, node) {
  // The subscriptions on the intake's queue. Its callbacks take microseconds and never wait for
  // an update, so roscpp's queue (as long as ours, ~queue_size, and at least the 100 it had)
  // fills only if the intake's thread cannot run for that many messages' time (10 s at 100 Hz
  // by default); what ours cannot hold is dropped and counted.
  ros::NodeHandle intake(node_);
  intake.setCallbackQueue(&intake_queue_);
  const auto roscpp_queue = static_cast<std::uint32_t>(std::max(params_.queue_size, 100));
  array_subscriber_ =
      intake.subscribe("body_states", roscpp_queue, &ImpactMonitorRos::onStateArray, this);
  array_topic_ = array_subscriber_.getTopic();
  for (const core::BodySpec& body : scene.bodies) {
    if (body.topic.empty()) continue;
    const std::string topic = node_.resolveName(body.topic);
    // Typed as taking the event, so that roscpp hands over the connection's header (the
    // publisher's name, the state's source on the time line); a lambda converted to a
    // callback of the message alone gets an event of "unknown_publisher".
    const boost::function<void(const ros::MessageEvent<const BodyState>&)> callback =
        [this, topic, id = body.id](const ros::MessageEvent<const BodyState>& event) {
          onState(event, topic, id);
        };
    body_subscribers_.push_back(
        intake.subscribe<const ros::MessageEvent<const BodyState>&>(topic, roscpp_queue, callback));
  }
  impact_publisher_ = node_.advertise<ImpactArray>("impacts", 100);
  contact_publisher_ = node_.advertise<ContactArray>("contacts", 100);
  marker_publisher_ = node_.advertise<visualization_msgs::MarkerArray>("markers", 10);
  // Retries inputs that wait for transforms; it runs only while the head waits.
  queue_timer_ = node_.createWallTimer(
      ros::WallDuration(0.005), [this](const ros::WallTimerEvent&) { processQueue(); },
      /*oneshot=*/false, /*autostart=*/false);
  figures_ = MonitorFigures::of(cycle_);
  intake_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &intake_queue_);
  intake_spinner_->start();
}

ImpactMonitorRos::~ImpactMonitorRos() {
  intake_spinner_->stop();
  array_subscriber_.shutdown();
  for (ros::Subscriber& subscriber : body_subscribers_) subscriber.shutdown();
  node_.getCallbackQueue()->removeByID(reinterpret_cast<std::uint64_t>(this));
  queue_timer_.stop();
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
               " states exceed ~max_states (" + std::to_string(params_.max_states) + ")",
           message->states.size()}});
    return;
  }
  enqueue(Pending{ros::WallTime::now(),
                  ros::Time::now(),
                  array_topic_,
                  event.getPublisherName(),
                  "",
                  message,
                  {}});
}

void ImpactMonitorRos::onState(const ros::MessageEvent<const BodyState>& event,
                               const std::string& topic, const std::string& id) {
  {
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    diagnostics_.received(1);
  }
  enqueue(Pending{ros::WallTime::now(),
                  ros::Time::now(),
                  topic,
                  event.getPublisherName(),
                  id,
                  nullptr,
                  {*event.getConstMessage()}});
}

void ImpactMonitorRos::enqueue(Pending pending) {
  // At most ~queue_size inputs and ~max_states states wait (the head the monitor has taken
  // among them): the oldest waiting make room.
  const std::size_t states = pending.states().size();
  std::vector<Pending> dropped;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    while (
        !queue_.empty() &&
        (queue_.size() + taken_inputs_ >= static_cast<std::size_t>(params_.queue_size) ||
         queued_states_ + taken_states_ + states > static_cast<std::size_t>(params_.max_states))) {
      dropped.push_back(std::move(queue_.front()));
      queued_states_ -= dropped.back().states().size();
      queue_.pop_front();
    }
    queued_states_ += states;
    queue_.push_back(std::move(pending));
  }
  for (const Pending& oldest : dropped) {
    tell(oldest.topic, {{Reason::kQueueFull,
                         "input queue full (~queue_size " + std::to_string(params_.queue_size) +
                             " messages, ~max_states " + std::to_string(params_.max_states) +
                             " states, waiting for the update in progress or for transforms): "
                             "dropped the oldest",
                         oldest.states().size()}});
  }
  // One wake-up at a time: the monitor's thread takes every input queued when it runs.
  if (!wake_posted_.exchange(true)) {
    node_.getCallbackQueue()->addCallback(boost::make_shared<FunctionCall>([this] {
                                            wake_posted_ = false;
                                            processQueue();
                                          }),
                                          reinterpret_cast<std::uint64_t>(this));
  }
}

void ImpactMonitorRos::processQueue() {
  bool waits = false;
  while (!waits) {
    Pending head;
    {
      std::lock_guard<std::mutex> lock(queue_mutex_);
      if (queue_.empty()) break;
      head = std::move(queue_.front());
      queue_.pop_front();
      taken_inputs_ = 1;
      taken_states_ = head.states().size();
      queued_states_ -= taken_states_;
    }
    bool handled = true;
    try {
      handled = processHead(head);
    } catch (const std::exception& error) {
      // Never let an exception out of a callback: drop the message that caused it and go on.
      tell(head.topic, {{Reason::kInternalError, std::string("dropped a message: ") + error.what(),
                         head.states().size()}});
    }
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (!handled) {  // back at the head, to wait for its transforms
      queued_states_ += taken_states_;
      queue_.push_front(std::move(head));
      waits = true;
    }
    taken_inputs_ = taken_states_ = 0;
  }
  if (waits) {
    queue_timer_.start();  // no effect when already running
  } else {
    queue_timer_.stop();
  }
}

bool ImpactMonitorRos::processHead(const Pending& head) {
  const ros::WallTime began = ros::WallTime::now();
  const double cpu_began = core::threadCpuSeconds();
  const bool may_wait = (began - head.received).toSec() < params_.transform_timeout;
  const MonitorCycle::Input input{&head.states(), head.topic, head.publisher, head.own_body};
  {
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    update_began_ = began;
  }
  MonitorCycle::Update update;
  MonitorFigures figures;
  {
    std::lock_guard<std::mutex> lock(monitor_mutex_);
    update = cycle_.process(input, head.clock, may_wait, tf_buffer_);
    figures = MonitorFigures::of(cycle_);
  }
  {
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    update_began_ = ros::WallTime();
    figures_ = std::move(figures);
  }
  if (update.waiting) return false;
  tell(head.topic, update.reports);
  std::size_t dropped = 0;
  for (const Report& report : update.reports) {
    if (dropsInput(report.reason)) dropped += report.count;
  }
  const std::size_t states = head.states().size();
  {
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    diagnostics_.used(states - std::min(states, dropped));
  }
  if (update.stepped) {
    publish(update);
    const ros::WallTime done = ros::WallTime::now();
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    diagnostics_.stepped((done - began).toSec(), core::threadCpuSeconds() - cpu_began,
                         (done - head.received).toSec(), update.impacts.impacts.size());
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
    {
      // A const query of the monitor may integrate a curved contact's motion on (its caches):
      // not at once with a prediction's reading of it.
      std::lock_guard<std::mutex> lock(monitor_mutex_);
      appendSceneMarkers(cycle_.monitor(), update.time, cycle_.scene().fixed_frame, update.stamp,
                         params_.markers, markers);
    }
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
  // warnings_ is shared by the intake's thread and the monitor's: under a lock of its own, so
  // that /diagnostics and the counting never wait for a log line.
  const std::lock_guard<std::mutex> warning(warnings_mutex_);
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
  MonitorFigures figures;
  {
    std::lock_guard<std::mutex> lock(monitor_mutex_);
    cycle_.tune(detection, restitution_threshold, rule);
    figures = MonitorFigures::of(cycle_);
  }
  std::lock_guard<std::mutex> lock(diagnostics_mutex_);
  figures_ = std::move(figures);
}

void ImpactMonitorRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::size_t waiting = 0;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    waiting = queue_.size();
  }
  std::lock_guard<std::mutex> lock(diagnostics_mutex_);
  const double running =
      update_began_.isZero() ? 0.0 : (ros::WallTime::now() - update_began_).toSec();
  // An update that has run for 1 s turns the summary to WARN.
  diagnostics_.report(status, figures_, waiting, running, 1.0);
  for (const auto& [pair, text] : restitution_estimates_) {
    status.add("restitution estimate " + pair, text);
  }
}

void ImpactMonitorRos::estimateRestitution(const EstimateRestitution::Request& request,
                                           EstimateRestitution::Response& response) {
  std::vector<PairEstimate> pairs;
  cycle_.liveCalibration().answer(request, response, pairs);
  if (pairs.empty()) return;
  std::lock_guard<std::mutex> lock(diagnostics_mutex_);
  for (const PairEstimate& estimate : pairs) {
    restitution_estimates_[estimate.pair] = estimate.summary;
  }
}

void ImpactMonitorRos::predict(const PredictImpacts::Request& request,
                               PredictImpacts::Response& response) {
  // What the prediction needs of the monitor, between two of its updates; then without it.
  const auto prepared = [&] {
    std::lock_guard<std::mutex> lock(monitor_mutex_);
    return preparePredictImpacts(request, cycle_, tf_buffer_, ros::Time::now());
  }();
  if (!prepared) {
    response = PredictImpacts::Response{};
    response.success = false;
    response.message = prepared.error().message();
    return;
  }
  core::PredictionBudget budget;
  budget.seconds = params_.prediction_cpu_budget;
  budget.name = "~prediction_cpu_budget";
  if (answerPreparedPrediction(*prepared, budget, response)) {
    std::lock_guard<std::mutex> lock(diagnostics_mutex_);
    diagnostics_.count(Reason::kPredictionCutShort);
  }
}

}  // namespace collision_response
