// The impact monitor on ROS: a thin wrapper that subscribes to the body states, queues the
// inputs whose transforms are not there yet, hands each input to the update cycle
// (MonitorCycle) and publishes what it returns: impacts, lasting contacts, markers, warnings and
// diagnostics.
//
// Threads: every callback of this class, and every use of the cycle, runs on the callback queue
// of the node handle it is given (the node's global queue, or a nodelet's single-threaded one),
// one at a time: the monitor's state is only ever touched from there. The collision services
// run on a thread of their own (CollisionResponseNode) and never touch the monitor. diagnose()
// is called from the diagnostics' own thread, so that /diagnostics is published while an update
// runs: it reads only the counters and the figures copied after each update, under a mutex.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <deque>
#include <mutex>
#include <string>
#include <vector>

#include "collision_response/BodyState.h"
#include "collision_response/BodyStateArray.h"
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

  /// Live tuning (dynamic_reconfigure), validated by the caller: see core::ImpactMonitor::tune.
  void tune(core::Detection detection, double restitution_threshold, core::CombineRule rule);

  /// ~predict_impacts (prediction_service.h): reads the monitor, so it is called on the
  /// monitor's queue, between updates.
  void predict(const PredictImpacts::Request& request, PredictImpacts::Response& response) const;
  /// The monitor's status for /diagnostics: rates, bodies tracked, drops by reason, timing.
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

 private:
  /// An input waiting for its transforms: an array kept as received (no copy of its states;
  /// a nodelet's publisher's message itself), or one state.
  struct Pending {
    ros::WallTime received;
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
  void enqueue(Pending pending);
  void processQueue();
  /// true when the head of the queue was handled (processed or dropped), false to wait.
  bool processHead();
  /// Each output of an update, in turn: a new topic is one more publisher and one more line.
  void publish(const MonitorCycle::Update& update);
  void publishMarkers(const MonitorCycle::Update& update);
  /// Counts every report and warns once per reason (the first report's text and the count).
  void tell(const std::string& topic, const std::vector<Report>& reports);

  ros::NodeHandle node_;
  MonitorParams params_;
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
  std::deque<Pending> queue_;
  std::size_t queued_states_ = 0;
  ThrottledWarning warnings_;
  /// Guards what diagnose() reads from the diagnostics' thread: the counters, the figures of
  /// the monitor after its last update, the update in progress and the inputs waiting.
  std::mutex diagnostics_mutex_;
  MonitorDiagnostics diagnostics_;
  MonitorFigures figures_;
  ros::WallTime update_began_;  ///< zero: no update in progress
  std::size_t waiting_ = 0;
};

}  // namespace collision_response
