// The state intake: BodyState messages in, samples in the fixed frame out, and every state that
// cannot be used dropped with a named reason. No node and no master: it reads tf from a
// tf2::BufferCore (the node's tf2_ros::Buffer, or one a test fills by hand).
#pragma once

#include <ros/time.h>
#include <tf2/buffer_core.h>

#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "collision_response/BodyState.h"
#include "collision_response/core/monitor.h"
#include "collision_response/ros/frame_motion.h"

namespace collision_response {

/// Why the monitor dropped a state, a message or an impact, or what else it has to tell: each
/// reason is one counter in diagnostics and one throttled warning per input topic, so the
/// warnings' key space is these reasons times the node's topics, whatever a publisher sends.
enum class Reason {
  kEmptyId,             ///< a state with no id
  kUnknownId,           ///< an id that is not one of the scene's bodies
  kIdMismatch,          ///< on a body's own topic, another body's id
  kDuplicateId,         ///< the same body twice in one message
  kZeroStamp,           ///< header.stamp zero
  kStampAhead,          ///< header.stamp too far ahead of the node's clock
  kNonFinite,           ///< a NaN or infinite number
  kBeyondResolution,    ///< a position past core::kMaxResolvedCoordinate: no contact resolved there
  kTransformMissing,    ///< no transform from the state's frame, after waiting
  kStale,               ///< not newer than the body's last state
  kSetAside,            ///< older than its body's motion in the monitor (found after it)
  kStampOffClock,       ///< a stamp back from its source's clock, the next one continuing it
  kTooManyStates,       ///< a message with more than ~max_states states
  kQueueFull,           ///< the oldest waiting input, dropped for a new one
  kInternalError,       ///< an exception while processing a message
  kImpactNotFinite,     ///< an impact whose numbers the doubles cannot hold: not published
  kContactNotFinite,    ///< a lasting contact whose numbers the doubles cannot hold: not published
  kClockJumpedBack,     ///< a source's stamps went back: every track reset
  kClockOffset,         ///< a source's (or a stamp's) clock differs: placed with an offset
  kStepTruncated,       ///< a guard of the monitor cut a step short
  kSteppedHeld,         ///< a stepped cluster held still over sub-steps it could not solve
  kOverWorkBudget,      ///< bodies the exact model spent its budget on: stepped from then on
  kObstacleTransform,   ///< a tf-attached obstacle keeps its last known motion
  kImpactContradicted,  ///< a state taken after an impact lacks it (the impact stays published)
  kFlightStalled,       ///< a flight through air the integrator could not carry on: held
  kPredictionCutShort,  ///< a ~predict_impacts request that spent ~prediction_cpu_budget
  kObstaclePlacementsLeftOut,  ///< an update's bound left out placements of near obstacles
  kFrameJumped,                ///< a tf frame moved faster than any body could follow
  kOverImpactWork,     ///< bodies of an impact past the update's impact work: cut short or locked
  kOverSteppedWork,    ///< bodies of stepped clusters held still past the update's stepped work
  kBadOrientation,     ///< pose.orientation not a rotation (zero for a shaped body, or not unit)
  kUnmodelledContact,  ///< a shaped body's contact the model does not carry yet: counted, said
};
inline constexpr int kReasonCount = static_cast<int>(Reason::kUnmodelledContact) + 1;

/// The counter's name, as diagnostics shows it: "dropped: unknown id", "clock jumped back", ...
const char* counterName(Reason reason);
/// Whether the reason drops input (a state or a message) or output (an impact, a contact).
bool isDrop(Reason reason);

/// One thing to report: its reason and the text of its warning (which names the state, the
/// field and why: "the state of 'ball': header.stamp: ...").
struct Report {
  Reason reason;
  std::string text;
  std::size_t count = 1;  ///< how many events it stands for (states dropped, say)
  bool warn = true;       ///< false: counted only (an obstacle's first instants, say)
  /// Tells apart warnings of one reason that are throttled apart, from a fixed small set (the
  /// field of a non-finite number: 13 of them; the coordinate of a position beyond resolution).
  int variant = 0;
};

/// The states of an input, in the fixed frame, as the monitor takes them, and each one's own
/// stamp (samples[k] is stamped stamps[k]). A sample's time is set in place once the time line
/// has placed the input (MonitorCycle), so the monitor steps with these samples themselves.
struct StampedSamples {
  std::vector<core::BodyStateSample> samples;
  std::vector<ros::Time> stamps;

  std::size_t size() const { return samples.size(); }
  bool empty() const { return samples.empty(); }
  void clear() {
    samples.clear();
    stamps.clear();
  }
  void resize(std::size_t size) {
    samples.resize(size);
    stamps.resize(size);
  }
  void push_back(const core::BodyStateSample& sample, const ros::Time& stamp) {
    samples.push_back(sample);
    stamps.push_back(stamp);
  }
};

/// What the intake needs to know; from MonitorParams.
struct IntakeSettings {
  std::string fixed_frame = "world";
  double frame_velocity_interval = 0.01;  ///< s: finite difference of a moving frame's velocity
  double transform_timeout = 0.1;         ///< s: for the warning's text
  double future_stamp_tolerance = 300.0;  ///< s: a stamp further ahead of the clock is dropped
};

class StateIntake {
 public:
  /// `body_ids`: the monitor's bodies, by index (ImpactMonitor::body(i).id); `shaped`: by the
  /// same index, whether the body turns as a rigid body of its shape (core::isShapedBody), whose
  /// state needs its orientation (a ball's may be all zero: not given).
  StateIntake(std::vector<std::string> body_ids, std::vector<bool> shaped, IntakeSettings settings);

  enum class Outcome {
    kDone,  ///< every state converted or dropped
    kWait,  ///< a transform is not there yet and the input may wait: nothing was consumed
  };

  /// Converts the states of one input. `own_body`: on a body's own topic, that body's id (an
  /// empty id means it); empty for `body_states`. `clock` is the node's clock now (zero: not
  /// known yet, sim time before the first /clock): a stamp more than future_stamp_tolerance
  /// ahead of it is dropped. `may_wait`: a missing transform makes the input wait (kWait)
  /// rather than drop its states. Each state is converted or dropped (reported), in order.
  Outcome convert(const std::vector<BodyState>& states, const std::string& own_body,
                  const ros::Time& clock, bool may_wait, const tf2::BufferCore& tf,
                  StampedSamples& samples, std::vector<Report>& reports);

  const IntakeSettings& settings() const { return settings_; }

 private:
  /// Where a state stands in its input: in a BodyStateArray (states[index]) or on a body's
  /// own topic.
  struct Place {
    bool array = true;
    std::size_t index = 0;
    std::string text(const std::string& id) const;
  };
  // The stages of convert(), in its order.
  /// The body a state is of, or nothing (reported, but for another body's topic).
  std::optional<std::size_t> bodyOf(const BodyState& state, const Place& place,
                                    const std::string& own_body, std::vector<Report>& reports);
  /// Why a state of body `index` cannot be used (its stamp, a non-finite number, a position past
  /// the monitor's resolution, an orientation that is no rotation), or nothing.
  std::optional<Report> problemOf(const BodyState& state, std::size_t index,
                                  const ros::Time& clock) const;
  /// The state in the fixed frame (the frame's own motion added, its orientation turned by the
  /// frame's and normalised); its time is set later.
  static core::BodyStateSample inFixedFrame(const BodyState& state, std::size_t index,
                                            const FrameMotion& frame_motion);
  /// Adds `sample`, stamped `stamp`, unless its body already has a state in this input (the
  /// newer stamp is kept).
  void keepOncePerInput(const core::BodyStateSample& sample, const ros::Time& stamp,
                        const Place& place, const std::string& id, StampedSamples& samples,
                        std::vector<Report>& reports);
  /// The body's index, or a report of why there is none.
  bool lookUp(const BodyState& state, std::size_t place, std::size_t& index,
              std::vector<Report>& reports);

  std::vector<std::string> body_ids_;
  std::vector<bool> shaped_;  ///< by body index: needs its orientation (core::isShapedBody)
  std::unordered_map<std::string, std::size_t> index_of_;
  IntakeSettings settings_;
  std::vector<std::size_t> index_hints_;  ///< body index of each place of the last input
  /// Duplicate ids in one input: the input that last saw each body, and where in it.
  std::vector<std::uint64_t> seen_in_input_;
  std::vector<std::size_t> seen_at_place_;
  std::vector<std::size_t> seen_at_sample_;
  std::uint64_t input_serial_ = 0;
};

}  // namespace collision_response
