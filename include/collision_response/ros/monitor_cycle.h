// The monitor's update cycle: one input (the states of one message) in, one update out: the
// impacts it revealed, each checked finite, and everything dropped or worth saying, by reason.
// It reads tf from a tf2::BufferCore and needs no node and no master (unit-tested, fuzzed);
// ImpactMonitorRos subscribes, queues, calls it and publishes what it returns.
//
// One input is one step: the monitor advances once, to the input's newest stamp, and each state
// enters at its own stamp (its track starts there). So the work per message is one step however
// many distinct stamps it holds: impacts between its states' stamps are found from the tracks
// before it, as for a message of one stamp.
#pragma once

#include <ros/time.h>
#include <tf2/buffer_core.h>

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "collision_response/BodyState.h"
#include "collision_response/ContactArray.h"
#include "collision_response/ImpactArray.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"
#include "collision_response/ros/frame_motion.h"
#include "collision_response/ros/live_calibration.h"
#include "collision_response/ros/monitor_params.h"
#include "collision_response/ros/state_intake.h"
#include "collision_response/ros/time_line.h"

namespace collision_response {

class MonitorCycle {
 public:
  MonitorCycle(const core::Scene& scene, const MonitorParams& params);

  struct Input {
    const std::vector<BodyState>* states = nullptr;
    std::string topic;      ///< where it came from, resolved
    std::string publisher;  ///< the node that published it (its clock is the source's)
    std::string own_body;   ///< on a body's own topic, its id; empty on body_states
  };

  struct Update {
    /// A transform (of a state's frame or a tf-attached obstacle) is not there yet and the
    /// input may wait: nothing was done; process it again later.
    bool waiting = false;
    bool stepped = false;  ///< the monitor advanced (some state was usable)
    double time = 0.0;     ///< s on the time line: the step's instant
    ros::Time stamp;       ///< the input's newest stamp, in its source's clock
    ImpactArray impacts;   ///< the impacts found, every number finite: to publish
    /// The lasting contacts at the step's time (gravity), every number finite, stamped with the
    /// input's newest stamp: to publish on `contacts` (README, "Topics").
    ContactArray contacts;
    /// Bodies in stepped clusters at the step's end (README, "Scene file":
    /// stepped_cluster_min_bodies).
    std::size_t stepped_bodies = 0;
    /// What was dropped (states, impacts) and what else happened.
    std::vector<Report> reports;
  };

  /// `clock`: the node's clock at the input's arrival (ros::Time::now() then; zero when
  /// unknown); `may_wait`: a missing transform makes the input wait rather than drop. Never
  /// throws on any message content.
  Update process(const Input& input, const ros::Time& clock, bool may_wait,
                 const tf2::BufferCore& tf);

  /// Live tuning (dynamic_reconfigure), validated by the caller: see core::ImpactMonitor::tune.
  void tune(core::Detection detection, double restitution_threshold, core::CombineRule rule);

  const core::ImpactMonitor& monitor() const { return monitor_; }
  /// The scene, as the monitor holds it (tuned by tune).
  const core::Scene& scene() const { return monitor_.scene(); }
  const TimeLine& timeLine() const { return time_line_; }
  const MonitorParams& params() const { return params_; }
  /// The tracked bodies' recent states (~calibration_window) and the live fit of them: safe to
  /// use from any thread without the monitor's lock (live_calibration.h).
  const LiveCalibration& liveCalibration() const { return live_calibration_; }
  /// Steps taken so far: one per input that had a usable state.
  std::uint64_t steps() const { return steps_; }
  /// Bodies in stepped clusters at the end of the last step (0 before the first).
  std::size_t steppedBodies() const { return stepped_bodies_; }

  /// What one update did for the tf-attached obstacles (README, "Finite obstacles"): every
  /// moving obstacle's frame is looked up once, at the input's newest stamp, and placed there; a
  /// frame wholly on /tf_static is looked up once (a few a update looked up again, in turn:
  /// kStaticRechecks); within the update, only the obstacles whose motion may reach some body
  /// are looked up and placed again every ~obstacle_update_period, at most kMaxPlacements
  /// placements in all (what that left out is counted: Reason::kObstaclePlacementsLeftOut).
  struct ObstacleWork {
    std::size_t lookups = 0;     ///< frames looked up in tf
    std::size_t placements = 0;  ///< obstacles placed in the monitor
    std::size_t near = 0;        ///< obstacles placed again within the update
  };
  static constexpr std::size_t kStaticRechecks = 8;
  /// m/s: a tf-attached obstacle whose surface tf moves faster (its centre's speed, and its
  /// turning times its bounding radius) jumped between tf's samples (a frame published anew
  /// elsewhere, a driver's glitch): no robot link or tracked thing moves so (a golf club's
  /// head, about the fastest thing a body swings, reaches about 55 m/s), and a ball it met would
  /// be sent off at up to twice that. The obstacle keeps its last good motion
  /// (Reason::kFrameJumped) until its frame moves slower again.
  static constexpr double kMaxFrameSpeed = 100.0;
  static constexpr std::size_t kMaxPlacements = 1000;
  /// The last input's obstacle work (its waiting attempts included).
  const ObstacleWork& obstacleWork() const { return obstacle_work_; }

 private:
  /// The offset (ns, TimeLine::stampOf) of the clock to stamp an instant `time` of the two
  /// sides in: the clock of the states it was predicted from when they share one; else the
  /// node's clock if one side keeps it, else body_a's.
  std::int64_t clockOf(double time, std::size_t body_a, std::size_t other,
                       bool other_is_obstacle) const;
  // The stages of process(), in its order.
  /// A tf-attached obstacle's frame, looked up at one stamp; empty for a fixed obstacle.
  using ObstacleMotion = std::optional<core::Expected<FrameMotion>>;
  /// Looks up each tf-attached obstacle's frame at `stamp`, once (a static one placed already:
  /// not, but kStaticRechecks of them in turn): `motions` by obstacle index.
  void lookUpObstacles(const ros::Time& stamp, const tf2::BufferCore& tf,
                       std::vector<ObstacleMotion>& motions);
  /// A tf-attached obstacle's frame not known at the input's newest stamp (obstacle_motions_):
  /// the input waits.
  bool obstacleFrameMissing() const;
  /// The held states of `source` (one stamp off its clock) are dropped, said.
  void dropHeldStates(const std::string& source, const TimeLine::Placed& placed, Update& update);
  /// The input's states wait for the source's next input (TimeLine::Event::kHeld).
  void holdStates(const std::string& source);
  /// The source's clock went back and its next input confirmed it: every track is reset and the
  /// held states enter the new line.
  void restartTimeLine(const std::string& source, const TimeLine::Placed& placed,
                       const ros::Time& newest, Update& update);
  /// A source (or a stamp) whose clock differs from the line's is said once.
  void reportClockOffset(const std::string& source, const TimeLine::Placed& placed,
                         const ros::Time& newest, Update& update);
  /// Sets each of the input's samples' time on the line, in place, from its stamp's distance
  /// to the newest (integer nanoseconds); each body's clock remembered.
  void timeSamples(const TimeLine::Placed& placed, const ros::Time& newest);
  /// What the step dropped or fell back on, as reports.
  void reportStep(const core::StepReport& step, Update& update) const;
  /// The warning naming the bodies the step handed to the stepped model over the work budget.
  Report overBudgetReport(const core::StepReport& step) const;
  /// The step's contacts and impacts as messages, stamped in their states' clocks; one that
  /// the doubles or a ros::Time cannot hold is reported, not published.
  void publishContacts(const core::StepReport& step, const ros::Time& newest, Update& update) const;
  void publishImpacts(const core::StepReport& step, const ros::Time& newest, Update& update) const;
  /// Looks up obstacle `i`'s frame at `stamp` into `motion` (a missing frame without an
  /// exception: canTransform first).
  void lookUpObstacle(std::size_t i, const ros::Time& stamp, const tf2::BufferCore& tf,
                      ObstacleMotion& motion);
  /// Places the tf-attached obstacles `which` (all when null) where `motions` has them, at line
  /// time `time`; one whose frame is missing keeps its last known motion (reported once for all
  /// of them); a static one already placed is left where it is.
  void placeObstacles(const std::vector<ObstacleMotion>& motions, double time, Update& update,
                      const std::vector<std::size_t>* which = nullptr);
  /// The moving obstacles whose motion over [from, until] may reach some tracked body's (their
  /// bounding spheres swept: see the definition), into near_obstacles_.
  void findNearObstacles(double from, double until, double end);
  /// Steps the monitor (no states) through the update's time before its first state, every
  /// ~obstacle_update_period, placing the near obstacles again from tf at each (at most
  /// kMaxPlacements in all, what is left out counted); the impacts found are gathered in
  /// `impacts`, what the steps report in `update`.
  void stepMovingObstacles(const TimeLine::Placed& placed, const ros::Time& newest,
                           const tf2::BufferCore& tf, std::vector<core::ImpactRecord>& impacts,
                           Update& update);

  MonitorParams params_;
  core::ImpactMonitor monitor_;
  StateIntake intake_;
  TimeLine time_line_;
  std::set<std::size_t> placed_obstacles_;  ///< tf-attached obstacles placed at least once
  /// The tf-attached obstacles' frames at the input's newest stamp, and at an instant before it
  /// (stepMovingObstacles): working memory, kept between inputs.
  std::vector<ObstacleMotion> obstacle_motions_;
  std::vector<ObstacleMotion> between_motions_;
  /// By obstacle: whether its frame's chain is wholly static (on /tf_static: a lookup at time
  /// zero stamped zero), found at its first lookup.
  enum class FrameKind : std::uint8_t { kFixed, kUnknown, kStatic, kMoving };
  std::vector<FrameKind> frame_kind_;
  /// By obstacle: its frame's last lookup moved faster than kMaxFrameSpeed (its motion is an
  /// error then, but not a missing frame: the input does not wait for it).
  std::vector<char> frame_jumped_;
  std::size_t next_recheck_ = 0;  ///< the static obstacle to look up again next (in turn)
  bool explain_missing_ = true;   ///< the next missing frame of a pass gets tf's text
  /// The frames tf2 does not walk to, composed hop by hop: for one pass of lookups (one
  /// stamp), made when first needed (it holds the pass's tf buffer).
  std::optional<FrameChains> chains_;
  std::vector<std::size_t> near_obstacles_;
  ObstacleWork obstacle_work_;
  /// The input's samples, timed in place (timeSamples): working memory, kept between inputs.
  StampedSamples samples_;
  /// By source: the states of an input whose stamp went back on its clock, until its next
  /// input tells a clock jump from a stamp off the clock (TimeLine::Event::kHeld).
  std::map<std::string, StampedSamples> held_;
  /// By body: the clock offset (ns) of its newest state, and that state's line time.
  std::vector<std::int64_t> body_clock_;
  std::vector<double> body_time_;
  std::vector<std::int64_t> clock_before_;  ///< body_clock_ before the input's states
  std::uint64_t steps_ = 0;
  std::size_t stepped_bodies_ = 0;
  /// Each input's timed states are recorded into its window (off: nothing, at no cost).
  LiveCalibration live_calibration_;
};

/// The impact message of a monitor's record, its stamp `stamp`; or the error naming the first
/// field the doubles cannot hold (the service's refusal, core::checkRepresentable).
core::Expected<Impact> toImpactMessage(const core::ImpactRecord& record,
                                       const core::ImpactMonitor& monitor, const ros::Time& stamp,
                                       const std::string& fixed_frame);

/// The contact message of a monitor's lasting contact, `since` stamped `since`; or the error
/// naming the first field the doubles cannot hold (as toImpactMessage).
core::Expected<Contact> toContactMessage(const core::ContactRecord& record,
                                         const core::ImpactMonitor& monitor,
                                         const ros::Time& since);

}  // namespace collision_response
