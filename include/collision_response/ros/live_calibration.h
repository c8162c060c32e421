// The live calibration (issue 44, item 3; README, "Calibration"): the tracked bodies' recent
// states, kept as received (in the fixed frame, on the monitor's time line) in a bounded window,
// and ~estimate_restitution's answer for a body from them, by the core's calibrate (the fit of
// `rosrun collision_response calibrate`) against the scene's fixed planes.
//
// Threads (doc/model.md, "Threads"): MonitorCycle records each input's states on the monitor's
// thread; ~estimate_restitution copies a body's window on the services' thread. The window has a
// mutex of its own, held only to append or to copy (never during an update or a fit): a request
// never waits for an update, and an update never for a fit. What else a request reads (the
// planes, the bodies' radii, the scene's gravity) is copied from the scene at construction and
// never changes (live tuning changes detection, the threshold and the combine rule only).
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "collision_response/EstimateRestitution.h"
#include "collision_response/core/calibration.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"

namespace collision_response {

/// The tracked bodies' recent states: those of the last `seconds` of stamps (s on the time line)
/// before the newest state kept of any body. They are kept in one log in the order they came,
/// each linked to its body's state before it: recording appends (no body's storage of its own
/// to reach: 10,000 bodies' states cost as one array's), a copy walks its body's links back
/// from its newest. Bounded: at most kMaxSamples states in all (the log's oldest dropped first,
/// never the newest) and a copy gives at most kMaxSamplesPerBody of a body (its newest). Off
/// (seconds 0): nothing kept, record() returns at once.
class CalibrationWindow {
 public:
  /// At most this many states of a body in a copy: its newest (10 s at 400 Hz).
  static constexpr std::size_t kMaxSamplesPerBody = 4000;
  /// At most this many states kept in all (2^20: 40 MB), shared by the bodies as they come (at
  /// 10,000 bodies' states at 100 Hz, about the last second of each).
  static constexpr std::size_t kMaxSamples = std::size_t{1} << 20;

  /// `max_samples`: kMaxSamples but for tests (rounded down to a power of two, at least 1).
  CalibrationWindow(std::size_t bodies, double seconds, std::size_t max_samples = kMaxSamples);

  bool enabled() const { return seconds_ > 0.0; }
  double seconds() const { return seconds_; }
  /// States kept in all, at most.
  std::size_t capacity() const { return capacity_; }

  /// Appends each state after its body's newest kept (one not newer is not kept: the monitor
  /// drops it as stale), then drops from the log's old end what is older than `seconds` before
  /// the newest state of any body, and past capacity() the oldest.
  void record(const std::vector<core::BodyStateSample>& samples);
  /// Forgets every state (the time line restarted: the kept times are on the old line).
  void clear();

  /// The body's states of the last `seconds` before the newest state kept of any body (a body
  /// no longer tracked has none), at most kMaxSamplesPerBody (its newest), oldest first, as the
  /// calibration takes them (positions only: a tracker's twist is often left zero, which would
  /// read as a known spin).
  std::vector<core::TrackedSample> copy(std::size_t body) const;
  /// States of the body in the log now (however old).
  std::size_t size(std::size_t body) const;
  /// States in the log now, of all bodies.
  std::size_t size() const;

 private:
  struct Entry {
    double time;
    Eigen::Vector3d position;
    std::uint64_t previous;  ///< the body's entry before (its sequence number + 1; 0: none)
  };
  /// Entry `sequence` (while held: begin_ <= sequence < end_).
  const Entry& entry(std::uint64_t sequence) const { return log_[sequence & (log_.size() - 1)]; }
  void append(std::size_t body, double time, const Eigen::Vector3d& position);

  double seconds_;
  std::size_t capacity_;
  mutable std::mutex mutex_;
  /// A ring of a power of two entries (grown by doubling up to capacity_ as it fills): entry s
  /// at log_[s mod size]; the entries begin_ to end_ (sequence numbers, never reused) are held.
  std::vector<Entry> log_;
  std::uint64_t begin_ = 0, end_ = 0;
  /// By body: its newest entry's sequence number + 1 (0, or below begin_ + 1: none held).
  std::vector<std::uint64_t> last_;
  double newest_ = 0.0;  ///< the newest time kept of any body (while begin_ < end_)
};

/// A fit's result for one obstacle pair, for /diagnostics.
struct PairEstimate {
  std::string pair;  ///< "[body material, plane material]"
  std::string body;  ///< the body's id
  core::Coefficients coefficients;
  /// "e 0.89999 (95 %: 0.89989 to 0.90009), mu 0.030000 (95 %: 0.029961 to 0.030038), 5 bounces
  /// at 2.117 to 3.227 m/s of 'ball'"
  std::string summary;
};

/// The window and what a fit needs of the scene (core::sceneCalibration), copied at construction.
class LiveCalibration {
 public:
  LiveCalibration(const core::Scene& scene, double window_seconds);

  CalibrationWindow& window() { return window_; }
  const CalibrationWindow& window() const { return window_; }

  /// ~estimate_restitution for a tracked body (request.body not empty): its window fitted with
  /// the core's calibrate against the scene's fixed planes; the most recent request.max_bounces
  /// bounces (0: all). e from them; mu (the response's friction fields) from the whole window's
  /// fit, its spin before the first bounce request.spin_before (empty: unknown, mu >= only),
  /// carried by the fit through the bounces not asked for. Refused (success false, the message
  /// naming the field or the core's named problem: no bounce, too few samples, a gap across a
  /// bounce, ...) otherwise. Each obstacle pair's estimate is appended to `pairs` when the fit
  /// succeeds. From any thread.
  void answer(const EstimateRestitution::Request& request, EstimateRestitution::Response& response,
              std::vector<PairEstimate>& pairs) const;

 private:
  struct Body {
    std::string id;
    std::string material;
    core::BodyCalibration fit;  ///< what the fit reads of it
  };
  std::vector<Body> bodies_;
  std::unordered_map<std::string, std::size_t> body_index_;
  /// The fit's options but for the body's: the fixed planes, gravity, drag (sceneCalibration).
  core::CalibrationOptions options_;
  std::vector<std::string> plane_materials_;
  /// Why the scene gives no fit (magnus, no fixed plane), or empty.
  std::string scene_refusal_;
  CalibrationWindow window_;
};

}  // namespace collision_response
