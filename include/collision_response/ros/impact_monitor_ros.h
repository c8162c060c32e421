// The impact monitor on ROS: a thin wrapper that subscribes to the body states, queues the
// inputs, hands each input to the update cycle (MonitorCycle) and publishes what it returns:
// impacts, lasting contacts, markers, warnings and diagnostics.
//
// Threads (doc/model.md, "Threads"):
// - intake: the subscriptions' callbacks run on a callback queue and thread of their own. They
//   only count what arrives, refuse a message past ~max_states, and append it to the node's own
//   bounded queue (~queue_size inputs, ~max_states states; past them the oldest waiting input is
//   dropped and counted), under queue_mutex_, then wake the monitor's thread. They never wait for
//   an update, so roscpp's own subscriber queue never fills: every message received is used or
//   counted with its reason.
// - the monitor: the queue is processed, and the cycle used, on the callback queue of the node
//   handle given (the node's global queue, or a nodelet's), one input at a time: the cycle is
//   changed only there, under monitor_mutex_ (an update, live tuning).
// - ~predict_impacts (CollisionResponseNode) runs on a thread of its own: predict() takes what
//   the prediction needs of the cycle under monitor_mutex_ (between two updates; quick: no motion
//   is computed), then predicts without it, within ~prediction_cpu_budget.
// - estimateRestitution() (~estimate_restitution given a tracked body, on the services' thread)
//   copies the body's states under the calibration window's own mutex, which an update holds
//   only to append its input's states (live_calibration.h), and fits them without any lock.
// - diagnose() is called from the diagnostics' own thread, so that /diagnostics is published
//   while an update runs: it reads only the counters and the figures copied after each update,
//   under diagnostics_mutex_, and the queue's length under queue_mutex_.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "collision_response/BodyState.h"
#include "collision_response/BodyStateArray.h"
#include "collision_response/EstimateRestitution.h"
#include "collision_response/ImpactArray.h"
#include "collision_response/PredictImpacts.h"
#include "collision_response/core/scene.h"
#include "collision_response/ros/markers.h"
#include "collision_response/ros/monitor_cycle.h"
#include "collision_response/ros/monitor_diagnostics.h"
#include "collision_response/ros/monitor_params.h"
#include "collision_response/ros/throttled_warning.h"

namespace collision_response {

class ImpactMonitorRos {
 public:
  /// Subscribes `body_states` and the bodies' own topics (checked by checkBodyTopics first),
  /// advertises `impacts`, `contacts` and `markers`.
  ImpactMonitorRos(ros::NodeHandle node, const core::Scene& scene, const MonitorParams& params);
  /// Stops the intake's thread and takes back its wake-ups from the monitor's queue.
  ~ImpactMonitorRos();
  ImpactMonitorRos(const ImpactMonitorRos&) = delete;
  ImpactMonitorRos& operator=(const ImpactMonitorRos&) = delete;

  /// Live tuning (dynamic_reconfigure), validated by the caller: see core::ImpactMonitor::tune.
  void tune(core::Detection detection, double restitution_threshold, core::CombineRule rule);

  /// ~predict_impacts (prediction_service.h), from any thread but the monitor's: what it needs
  /// of the monitor is taken between two updates, the prediction then runs on the caller's
  /// thread within ~prediction_cpu_budget of its CPU time (one cut short is counted).
  void predict(const PredictImpacts::Request& request, PredictImpacts::Response& response);
  /// ~estimate_restitution for a tracked body (request.body set), from any thread but the
  /// monitor's: the body's window copied under its own lock, fitted without any
  /// (LiveCalibration::answer); each pair's estimate kept for /diagnostics.
  void estimateRestitution(const EstimateRestitution::Request& request,
                           EstimateRestitution::Response& response);
  /// The monitor's status for /diagnostics: rates, bodies tracked, drops by reason, timing.
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

 private:
  /// An input waiting for its transforms: an array kept as received (no copy of its states;
  /// a nodelet's publisher's message itself), or one state.
  struct Pending {
    ros::WallTime received;
    /// The node's clock at its arrival: the time line's present for it (a long queue
    /// ahead of it does not make its stamps look late).
    ros::Time clock;
    std::string topic;
    std::string publisher;
    std::string own_body;  ///< a body's own topic: its id
    BodyStateArray::ConstPtr array;
    std::vector<BodyState> single;
    const std::vector<BodyState>& states() const { return array ? array->states : single; }
  };

  void onStateArray(const ros::MessageEvent<const BodyStateArray>& event);
  void onState(const ros::MessageEvent<const BodyState>& event, const std::string& topic,
               const std::string& id);
  /// On the intake's thread: appends to the queue (the oldest waiting dropped past its bounds)
  /// and wakes the monitor's thread.
  void enqueue(Pending pending);
  /// On the monitor's thread: processes the queue until it is empty or its head must wait.
  void processQueue();
  /// true when `head` was handled (processed or dropped), false to wait.
  bool processHead(const Pending& head);
  /// Each output of an update, in turn: a new topic is one more publisher and one more line.
  void publish(const MonitorCycle::Update& update);
  void publishMarkers(const MonitorCycle::Update& update);
  /// Counts every report and warns once per reason (the first report's text and the count).
  void tell(const std::string& topic, const std::vector<Report>& reports);

  ros::NodeHandle node_;
  MonitorParams params_;
  /// Held by the monitor's thread while it changes the cycle (an update, live tuning) or queries
  /// its motion (markers: a const query may integrate a curved contact's motion on, in caches),
  /// and by predict() while it reads it.
  std::mutex monitor_mutex_;
  MonitorCycle cycle_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  ros::Subscriber array_subscriber_;
  std::string array_topic_;
  std::vector<ros::Subscriber> body_subscribers_;
  ros::Publisher impact_publisher_;
  ros::Publisher contact_publisher_;
  ros::Publisher marker_publisher_;
  /// Whether the last `contacts` published held some: one empty array is published when the
  /// last contact ends, then nothing until contacts exist again (README, "Topics").
  bool contacts_published_ = false;
  /// Lasting-contact markers drawn last (ids 0 .. n-1): the ids past a new count are deleted.
  std::size_t contact_markers_ = 0;
  ros::WallTime last_scene_markers_;
  int next_impact_marker_ = 0;
  ros::WallTimer queue_timer_;
  /// Guards the queue: the intake's thread appends, the monitor's takes the head (and puts it
  /// back while it waits for transforms). Never held during an update.
  std::mutex queue_mutex_;
  std::deque<Pending> queue_;
  std::size_t queued_states_ = 0;
  /// The head the monitor's thread has taken (0 or 1 input, its states): in the bounds too.
  std::size_t taken_inputs_ = 0, taken_states_ = 0;
  /// A wake-up is posted to the monitor's queue and has not begun: no second one is posted.
  std::atomic<bool> wake_posted_{false};
  ThrottledWarning warnings_;
  std::mutex warnings_mutex_;  ///< warnings_'s: tell runs on the intake's thread and the monitor's
  /// Guards what diagnose() reads from the diagnostics' thread: the counters, the figures of
  /// the monitor after its last update, the update in progress and the inputs waiting.
  std::mutex diagnostics_mutex_;
  MonitorDiagnostics diagnostics_;
  MonitorFigures figures_;
  ros::WallTime update_began_;  ///< zero: no update in progress
  /// The last live estimate of each obstacle pair ("[a, b]" -> its /diagnostics line), from
  /// ~estimate_restitution's answers (no periodic fit); one a pair of materials: bounded.
  std::map<std::string, std::string> restitution_estimates_;
  // The intake's own queue and thread; its subscriptions are declared above and shut down (the
  // thread stopped first) in the destructor.
  ros::CallbackQueue intake_queue_;
  std::unique_ptr<ros::AsyncSpinner> intake_spinner_;
};

}  // namespace collision_response
