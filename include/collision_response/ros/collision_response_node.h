// The collision_response node: loads the scene and the parameters, serves the collision services
// and runs the impact monitor on the scene's bodies.
//
// Threads (doc/model.md, "Threads"): the monitor (its queue, updates and live tuning) runs on the
// callback queue of `node`, its subscriptions' intake on a thread of its own (ImpactMonitorRos);
// /diagnostics on a thread of its own; ~predict_impacts on a thread of its own, one request at a
// time (ImpactMonitorRos::predict: it reads the monitor between two updates, then predicts
// without it within ~prediction_cpu_budget); and the two collision services on a thread of their
// own, so that neither a long step nor a prediction delays an answer. The collision services
// read the material table, which they take as an immutable snapshot (a shared pointer swapped
// under a mutex when live tuning changes the combine rule); ~estimate_restitution given a
// tracked body copies that body's kept states under the window's own mutex and fits them
// without any (live_calibration.h): it never takes the monitor's.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <boost/thread/recursive_mutex.hpp>

#include <memory>
#include <mutex>

#include "collision_response/ComputeCollision.h"
#include "collision_response/EstimateRestitution.h"
#include "collision_response/MonitorConfig.h"
#include "collision_response/PredictImpacts.h"
#include "collision_response/core/materials.h"
#include "collision_response/ros/impact_monitor_ros.h"
#include "collision_response/ros/monitor_params.h"

namespace collision_response {

class CollisionResponseNode {
 public:
  /// `node` resolves topics (relative names), `private_node` the `~` parameters and services.
  CollisionResponseNode(const ros::NodeHandle& node, const ros::NodeHandle& private_node);
  ~CollisionResponseNode();

  /// Reads and validates the private parameters (`~scene` and the monitor's), advertises the
  /// services and starts the monitor. On a bad parameter it logs the error (naming the
  /// parameter and the reason) and returns false; it never throws.
  bool initialize();

 private:
  bool start();
  bool onComputeCollision(ComputeCollision::Request& request, ComputeCollision::Response& response);
  bool onEstimateRestitution(EstimateRestitution::Request& request,
                             EstimateRestitution::Response& response);
  bool onPredictImpacts(PredictImpacts::Request& request, PredictImpacts::Response& response);
  void logScene(const core::Scene& scene, const MonitorParams& params) const;
  /// dynamic_reconfigure: checks each value as the scene file's; a refused value is put back
  /// to the one in use (in `config`, which the server then reports) with an error naming it.
  void onReconfigure(MonitorConfig& config, std::uint32_t level);
  std::shared_ptr<const core::MaterialTable> materials() const;
  /// Publishes /diagnostics once ~diagnostic_period has passed, re-reading that parameter first.
  void updateDiagnostics();
  /// ~diagnostic_period as set now, checked as at start-up: a refused value (one a
  /// ros::Duration cannot hold, say) keeps the period in use, with one warning naming the key.
  void rereadDiagnosticPeriod();

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  mutable std::mutex materials_mutex_;
  std::shared_ptr<const core::MaterialTable> materials_ =
      std::make_shared<const core::MaterialTable>(core::MaterialTable::seed());
  std::unique_ptr<ImpactMonitorRos> monitor_;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;
  ros::WallTimer diagnostics_timer_;
  double diagnostic_period_ = 1.0;  ///< s, ~diagnostic_period as last accepted
  double next_diagnostics_ = 0.0;   ///< ros::Time::now() in s at which to publish next
  std::string period_refused_;      ///< the last refusal warned of ("" while the value is good)
  boost::recursive_mutex reconfigure_mutex_;  ///< the server's, so updateConfig is safe
  std::unique_ptr<dynamic_reconfigure::Server<MonitorConfig>> reconfigure_;
  MonitorConfig config_;  ///< the values in use
  /// ~predict_impacts on a queue and thread of its own (one request at a time): a prediction
  /// never holds up the monitor's updates, nor an update a prediction for longer than it lasts.
  ros::CallbackQueue predict_queue_;
  ros::ServiceServer predict_impacts_server_;
  std::unique_ptr<ros::AsyncSpinner> predict_spinner_;
  // The diagnostics' own queue and thread (their timer), so that /diagnostics is published
  // while an update runs on the node's queue; declared after what it reads, so that its thread
  // stops first.
  ros::CallbackQueue diagnostics_queue_;
  std::unique_ptr<ros::AsyncSpinner> diagnostics_spinner_;
  // The services' own queue and thread; declared last so that the thread stops first.
  ros::CallbackQueue service_queue_;
  ros::ServiceServer compute_collision_server_;
  ros::ServiceServer estimate_restitution_server_;
  std::unique_ptr<ros::AsyncSpinner> service_spinner_;
};

}  // namespace collision_response
