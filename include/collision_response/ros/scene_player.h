// The scene player: moves the scene's bodies, publishes their states, applies the impacts it
// receives. It closes the loop with the monitor over real topics. The motion is the core's
// (core::Playback); this class only reads its parameters, keeps time, and publishes.
#pragma once

#include <XmlRpcValue.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "collision_response/ImpactArray.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/playback.h"
#include "collision_response/core/scene.h"
#include "collision_response/ros/parameters.h"

namespace collision_response {

/// A frame the player moves in a straight line (for tf-attached obstacles: a paddle).
struct MovingFrame {
  std::string frame;
  std::string parent;                                  ///< empty: the scene's fixed frame
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< m, at the start, in parent
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< m/s, in parent
};

/// The scene player's private parameters, with their defaults (README.md, "Parameters"; what
/// the player does: doc/model.md, "The scene player and the scenes").
struct ScenePlayerParams {
  double rate = 100.0;              ///< Hz: states published this often
  double duration = 0.0;            ///< s played, then the player stops; 0: until stopped
  double start_delay = 1.0;         ///< s waited before the first state
  double contact_tolerance = 1e-9;  ///< as the node's: resting on a plane
  bool report_restitution = false;  ///< print e = sqrt(h'/h) of each first bounce
  /// s: an impact heard up to this long after the newest period played is still applied, by
  /// playing the scene again from its instant (core::Playback's replay window)
  double replay_window = 0.25;
  std::vector<MovingFrame> frames;  ///< `~player/frames`

  /// Every private parameter the player reads (`scene` is loadScene's).
  static const KeyTable<ScenePlayerParams>& keys();
  /// Reads the player's private namespace `tree` (named `ns`): a wrong type, a value out of
  /// range or an unknown parameter is an error naming the key.
  static core::Expected<ScenePlayerParams> load(const XmlRpc::XmlRpcValue& tree,
                                                const std::string& ns);
};

class ScenePlayer {
 public:
  ScenePlayer(const ros::NodeHandle& node, const ros::NodeHandle& private_node);

  /// Reads `~scene` and the parameters above; false (logged, naming the key) on a bad value.
  bool initialize();

 private:
  void onTimer(const ros::TimerEvent& event);
  /// Publishes the periods due by `now` (k / rate s after the start, each once, in order): up to
  /// kMaxCatchUp late ones; further behind, the newest alone, the others counted as skipped and
  /// said (a throttled warning with the figures).
  void playPeriodsDue(const ros::Time& now);
  /// The line that says what was played: periods, states published, periods skipped.
  std::string playedSummary() const;
  void onImpacts(const ImpactArray::ConstPtr& message);
  void publishStates(const ros::Time& time);
  /// Publishes on `apexes` each flight's highest point once it is past; with
  /// ~report_restitution, prints e = sqrt(h'/h) of each body's first bounce off the floor.
  void publishApexes(const ros::Time& time);
  double sinceStart(const ros::Time& time) const { return (time - start_).toSec(); }

  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  core::Scene scene_;
  ScenePlayerParams params_;
  ros::Time created_;
  ros::Time start_;
  /// The monitor's indexing of the scene (bodies by sorted id): the impacts it publishes are
  /// applied through Playback::applyImpact(monitor, record, exact_contact), as the core does.
  std::unique_ptr<core::ImpactMonitor> indexing_;
  std::unique_ptr<core::Playback> playback_;  ///< from the start on (the bodies' motion)
  ros::Publisher state_publisher_;
  ros::Publisher apex_publisher_;
  ros::Subscriber impact_subscriber_;
  tf2_ros::TransformBroadcaster broadcaster_;
  ros::Timer timer_;
  ros::WallTimer stop_timer_;     ///< the summary line goes out before the player stops
  std::int64_t next_period_ = 0;  ///< the next period to publish: k / rate s from the start
  std::int64_t published_ = 0;    ///< states published (one per period played)
  std::int64_t skipped_ = 0;      ///< periods not published: the player fell behind
  double last_period_cpu_ = 0.0;  ///< s of CPU the last period played took
  bool stopping_ = false;
  /// Bodies whose states were sent lacking an impact the player could not resolve itself (on a
  /// tf-attached obstacle): id -> (the impact's instant, the last state's instant, from the
  /// start, whose impacts came along those states). The node's later impacts of the body
  /// revealed up to then are not applied.
  std::map<std::string, std::pair<double, double>> unheard_;
  std::int64_t stale_impacts_ = 0;  ///< impacts not applied for that reason
  std::int64_t late_impacts_ = 0;   ///< impacts heard more than ~replay_window late
};

}  // namespace collision_response
