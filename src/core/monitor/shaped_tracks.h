// The monitor's shaped bodies (issue 42, steps 6 and 7): each one's track is its last state
// (position, velocity, angular velocity, orientation) and its motion from there: the engine's
// flights and impacts with the obstacles (shaped_motion.h), a lasting motion on one flat face
// (shaped_lasting.h), or held where it is from the instant its contact is not modelled yet, which
// is reported (UnmodelledContact), never passed through. The balls' world (monitor_world.h) does
// not see them: their tracks there stay unknown.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/monitor.h"
#include "contact/shaped_lasting.h"
#include "model/monitor_world.h"
#include "monitor/shaped_motion.h"

namespace collision_response::core::monitor {

/// A shaped body's motion from its last state.
class ShapedTrack {
 public:
  enum class Mode { kFlying, kLasting, kHeld };

  /// The motion from `state` among `obstacles`; an Error where the engine refuses the state (a
  /// value not finite: TumblingBody::create).
  static Expected<ShapedTrack> start(const PrincipalBody& principal,
                                     std::vector<ShapedObstacle> obstacles,
                                     const ShapedScene& scene, const BodyStateSample& state,
                                     std::size_t revision);

  /// On to `time`: the impacts with obstacles in (reached, time] appended to `impacts`, and the
  /// contact whose model is missing, where the body is held from (once, when it begins), to
  /// `unmodelled`. The velocity change of the latest impact is noted (impactChange).
  void advanceTo(double time, std::vector<ImpactRecord>& impacts,
                 std::vector<UnmodelledContact>& unmodelled);

  /// The body's state at `time` (at or after since(), within what was advanced): its centre's,
  /// and its body frame's orientation.
  BodyStateSample stateAt(double time) const;
  /// The instant its current motion holds from (its state, an impact, a lasting motion's
  /// start, the instant it was held).
  double since() const { return since_; }
  Mode mode() const { return mode_; }
  /// s: up to when (at most `horizon`) its present motion holds with nothing happening: where it
  /// flies, its flight's next event (looked at on a copy of its engine: an impact, a graze, a
  /// contact that lasts); where it is held or rests still, `horizon`; where it moves in lasting
  /// contact, now (its motion is no flight: see still()).
  double quietUntil(double horizon) const;
  /// Held, or resting still (no velocity, no acceleration: a lasting rest) until at least
  /// `horizon`.
  bool still(double horizon) const;
  /// Its flight from since() on (kFlying), else none.
  const TumblingBody* flight() const {
    return mode_ == Mode::kFlying ? &motion_.flight() : nullptr;
  }
  /// s: where its flight through air stalled (ShapedMotion::stalledAt; kFlying), else infinite.
  double stalledAt() const {
    return mode_ == Mode::kFlying ? motion_.stalledAt() : std::numeric_limits<double>::infinity();
  }
  /// Its lasting contacts at `time`, one record per point of the manifold (kLasting).
  std::vector<ContactRecord> contacts(double time) const;
  /// The obstacle it lasts on or is held against (kLasting, kHeld; none where it is held
  /// touching a body: holdTouching).
  std::optional<std::size_t> against() const { return against_; }
  /// Held where it is at `time` (at or after since()): its contact with another body lasts,
  /// which is not modelled yet (shaped_pairs.h); reported by the caller.
  void holdTouching(double time);
  /// The obstacles as placed now (a revision of its room), looked at from `time` on, its motion
  /// kept (a lasting one's).
  void placeObstacles(std::vector<ShapedObstacle> placed, double time, std::size_t revision);
  /// The ShapedRoom::revision its motion was started with.
  std::size_t revision() const { return revision_; }

  double last_state_time = -std::numeric_limits<double>::infinity();
  double last_impact_time = -std::numeric_limits<double>::infinity();
  Eigen::Vector3d impact_change = Eigen::Vector3d::Zero();  ///< m/s, the latest impact's
  Eigen::Quaterniond last_orientation = Eigen::Quaterniond::Identity();  ///< its last state's
  /// s: the instant its flight through air stalled that was last reported (StepReport::stalled).
  double stall_reported = std::numeric_limits<double>::quiet_NaN();

 private:
  ShapedTrack(ShapedMotion motion, std::size_t revision)
      : motion_(std::move(motion)), since_(motion_.time()), revision_(revision) {}
  /// Where its lasting motion ends: asked again, its events on from there, or held.
  void endLasting(std::vector<UnmodelledContact>& unmodelled);
  /// The contact the engine found to last: on one flat face by lastingOnFace, or held.
  void enterLasting(double time, std::vector<UnmodelledContact>& unmodelled);
  void startLasting(const LastingBody& body, const std::vector<FlatFace>& faces,
                    std::vector<UnmodelledContact>& unmodelled);
  void struck(const ShapedMotion::Strike& strike, std::vector<UnmodelledContact>& unmodelled);
  void hold(const BodyStateSample& state, std::size_t obstacle, const std::string& what,
            std::vector<UnmodelledContact>& unmodelled);

  ShapedMotion motion_;
  Mode mode_ = Mode::kFlying;
  double since_ = 0.0;
  bool fresh_ = true;     // not advanced yet: whether it starts inside an obstacle is asked first
  bool leaving_ = false;  // after an impact: the struck points to part first (ShapedMotion::leave)
  std::optional<double> rests_from_;  // a flat landing's bounces accumulate then
  ResumeGuard resumes_;               // a tipping's hand-overs to its events
  std::optional<LastingMotion> lasting_;
  std::vector<FlatFace> faces_;            // its lasting motion's, one per obstacle of ...
  std::vector<std::size_t> lasting_with_;  // ... these (model indices)
  double lasting_since_ = 0.0;
  double watched_until_ = 0.0;  // no other obstacle meets its lasting motion before it
  std::optional<std::size_t> against_;
  BodyStateSample held_;
  std::size_t revision_ = 0;
};

/// The shaped bodies of one monitor, by body index (balls: none), and the contacts not modelled
/// that hold at the last step's end (each reported once, when it begins).
struct ShapedRoom {
  std::vector<std::optional<PrincipalBody>> principal;
  std::vector<std::optional<ShapedTrack>> tracks;
  std::set<std::tuple<std::size_t, std::size_t, bool>> unmodelled_now;
  /// Pairs of shaped bodies (lower index first) just struck or grazing, not yet apart by the
  /// touching band, and the instant they are known apart from (looked at again from there):
  /// their touch is their parting, not a lasting contact.
  std::map<std::pair<std::size_t, std::size_t>, double> parting;
  /// Changes of what the shaped motion reads of the monitor (an obstacle placed: setObstaclePose,
  /// placeObstacle; the coefficients tuned: tune) so far: a flying track started before the
  /// latest starts again from where it is, among the obstacles and coefficients as they are now.
  std::size_t revision = 0;

  bool any() const;
  bool shaped(std::size_t body) const { return body < principal.size() && principal[body]; }
};

/// The shaped body `body` of `room` (its track known) at `time` as a tumbling body, with no
/// acceleration: its state there (for its gap to another body); empty where none is made.
std::optional<TumblingBody> tumblingAt(const ShapedRoom& room, std::size_t body, double time);

/// Touching: overlapping, or apart by no more than the manifold's band.
bool touching(const SurfaceGap& gap);

/// Whether `world`'s balls move as rigid spheres among its shaped bodies (doc/model.md, "Balls
/// among shaped bodies"): where the scene has a shaped body, and spin is on or friction off (a
/// shaped body turns).
bool ballsMoveAsShaped(const World& world);

/// The shaped bodies of `world`'s scene (validateScene took them: principalBody holds), and
/// where ballsMoveAsShaped, its movable balls, as rigid spheres of their inertia.
ShapedRoom shapedRoomOf(const World& world);

/// A shaped body's track starts again from `state` (the obstacles as placed in `world`).
/// False where its motion is refused (the track is kept as it was).
bool restartShaped(const World& world, ShapedRoom& room, const BodyStateSample& state);

/// The shaped bodies' step from `from` (the monitor's time before it) to `time`: each known track
/// advanced (its impacts in (now, time]),
/// then `states` of shaped bodies taken as in the balls' applyStates (stale, set aside,
/// contradicted) and advanced to `time`; a shaped body touching a ball or another shaped body at
/// `time` reported as unmodelled (once, when it begins); the lasting contacts at `time`.
void stepShaped(const World& world, ShapedRoom& room, double from, double time,
                const std::vector<BodyStateSample>& states, const BallPositions& balls,
                StepReport& report);

/// As stepShaped, the states imposed at their instants (Playback: the motion just after an
/// impact, the orientation kept) instead of taken at the step's end.
void advanceShaped(const World& world, ShapedRoom& room, double from, double time,
                   const std::vector<BodyStateSample>& imposed, const BallPositions& balls,
                   StepReport& report);

}  // namespace collision_response::core::monitor
