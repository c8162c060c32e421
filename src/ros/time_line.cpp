#include "collision_response/ros/time_line.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace collision_response {
namespace {

std::int64_t nanoseconds(const ros::Time& stamp) {
  return static_cast<std::int64_t>(stamp.sec) * 1000000000 + static_cast<std::int64_t>(stamp.nsec);
}

std::int64_t toNanoseconds(double seconds) {
  return static_cast<std::int64_t>(std::llround(seconds * 1e9));
}

ros::Time fromNanoseconds(std::int64_t at) {
  ros::Time stamp;
  stamp.sec = static_cast<std::uint32_t>(at / 1000000000);
  stamp.nsec = static_cast<std::uint32_t>(at % 1000000000);
  return stamp;
}

}  // namespace

TimeLine::TimeLine(double clock_jump_back)
    : jump_ns_(toNanoseconds(clock_jump_back)), ahead_ns_(jump_ns_ / kAheadFraction) {}

TimeLine::Placed TimeLine::start(const std::string& source, std::int64_t first, std::int64_t at,
                                 std::int64_t clock, Event event) {
  reset();
  started_ = true;
  // Line zero is `first` in the node's clock: a stamp far from the node's clock (one
  // arriving first, say) starts the line at the node's present, not at the stamp.
  // Alone on the line at its start: ~clock_jump_back either way.
  const std::int64_t offset =
      clock != 0 && !agrees(at, clock, false) ? clock - at : std::int64_t{0};
  epoch_ = first + offset;
  last_clock_ = clock;
  first_source_ = source;
  Source& known = sources_[source];
  known.clocks.push_back(
      Clock{offset, std::max(first, at), ++heard_, 1, at + offset - epoch_, clock});
  known.heard = heard_;
  Placed placed;
  placed.time = static_cast<double>(at - first) * 1e-9;
  placed.event = event;
  placed.clock_offset = offset;
  return placed;
}

bool TimeLine::agrees(std::int64_t at, std::int64_t clock, bool clock_runs) const {
  // Behind it by its messages' latency, which load can make long; ahead of it only by the
  // difference of two clocks that agree (another machine's, a /clock heard a tick late).
  return clock - at <= jump_ns_ && at - clock <= (clock_runs ? ahead_ns_ : jump_ns_);
}

std::int64_t TimeLine::newOffset(std::int64_t at, std::int64_t clock,
                                 const Present& present) const {
  if (clock == 0 || agrees(at, clock, present.clock_runs && present.shared)) return 0;
  // A clock off the node's that another source keeps, which this stamp continues: on it, the
  // stamp is no more than ~clock_jump_back before that source's last one, nor ahead of where
  // that source is now (its last instant plus the node's time since). The two share it (two
  // topics of one machine or of one bag, two `rostopic pub` of hand-made stamps), and instants
  // across them stay exact. The node's own clock is never shared this way: a stamp off it is
  // another clock. Of several, the one where that source is now closest.
  const Clock* shared = nullptr;
  std::int64_t closest = 0;
  for (const auto& entry : sources_) {
    for (const Clock& other : entry.second.clocks) {
      if (other.offset == 0 || other.last_clock == 0) continue;
      const std::int64_t line = at + other.offset - epoch_;
      const std::int64_t expected = other.last_line + (clock - other.last_clock);
      if (line < other.last_line - jump_ns_ || line > expected + jump_ns_) continue;
      const std::int64_t distance = std::abs(line - expected);
      if (shared == nullptr || distance < closest) {
        closest = distance;
        shared = &other;
      }
    }
  }
  return shared != nullptr ? shared->offset : present.line - (at - epoch_);
}

bool TimeLine::sharedWith(const std::string& source, std::int64_t node_clock) const {
  if (node_clock == 0) return false;
  for (const auto& [name, known] : sources_) {
    if (name == source) continue;
    for (const Clock& clock : known.clocks) {
      // Heard lately, on the node's clock and not ahead of it when last placed: a source whose
      // states a lead of this one's would put in the monitor's past. Sources that run ahead
      // alike, or on clocks of their own (two topics of one burst of hand-made stamps), are
      // not held back for each other.
      if (clock.offset == 0 && clock.last_clock != 0 && node_clock - clock.last_clock <= jump_ns_ &&
          clock.last_line <= clock.last_clock - epoch_ + ahead_ns_) {
        return true;
      }
    }
  }
  return false;
}

bool TimeLine::continues(const Clock& clock, std::int64_t at, const Present& present) const {
  if (at < clock.last_stamp - jump_ns_) return false;  // went back
  if (present.clock_runs && !present.shared && clock.last_clock != 0) {
    // Alone on the line: leapt ahead of where its own clock is now (its last instant plus the
    // node's time since) by more than ~clock_jump_back, a stamp off it.
    return at + clock.offset - epoch_ <=
           clock.last_line + (present.node_clock - clock.last_clock) + jump_ns_;
  }
  // Leapt ahead of the line's present (judged only with a running node's clock; without it, a
  // source's stamps going forward are its own business): the node's clock, by more than two
  // clocks that agree differ; a clock of its own (placed at the present), by more than
  // ~clock_jump_back, a stamp off it.
  return !present.clock_runs ||
         at + clock.offset - epoch_ <= present.line + (clock.offset == 0 ? ahead_ns_ : jump_ns_);
}

bool TimeLine::continues(const Held& held, std::int64_t at, std::int64_t node_clock) const {
  if (at < held.last - jump_ns_) return false;
  return node_clock == 0 || held.clock == 0 || at - held.last <= node_clock - held.clock + jump_ns_;
}

TimeLine::Source& TimeLine::sourceOf(const std::string& source, bool& is_new) {
  auto found = sources_.find(source);
  is_new = found == sources_.end();
  if (is_new) {
    if (sources_.size() >= kMaxSources) {
      auto oldest = sources_.begin();
      for (auto it = sources_.begin(); it != sources_.end(); ++it) {
        if (it->second.heard < oldest->second.heard) oldest = it;
      }
      sources_.erase(oldest);
    }
    found = sources_.emplace(source, Source{}).first;
  }
  return found->second;
}

TimeLine::Placed TimeLine::on(Clock& clock, std::int64_t at, std::int64_t node_clock,
                              std::int64_t now, const Present& present) {
  Placed placed;
  clock.heard = heard_;
  ++clock.messages;
  if (at > clock.last_stamp) clock.last_stamp = at;
  std::int64_t line = at + clock.offset - epoch_;
  if (present.clock_runs && present.shared && clock.offset != 0 && line > present.line) {
    // A clock of its own running ahead of the node's (a bag played faster than it was recorded,
    // without sim time): placed at the line's present, never past it, its offset following, so
    // that it moves no instant of another source (the monitor cannot step back to a state of
    // the past). Said when it got its clock, not again.
    clock.offset -= line - present.line;
    line = present.line;
  } else if (line < (present.clock_runs ? std::min(now, present.line) : now) - jump_ns_) {
    // Behind the line although its own clock did not go back: another clock (a source that
    // joins after another one moved the line ahead, a bag played slower than it was recorded).
    // Shifted onto the line's present; said when it leaves the node's clock, not again.
    if (clock.offset == 0) placed.event = Event::kOffsetChanged;
    clock.offset += present.line - line;
    line = present.line;
  }
  if (node_clock != 0) last_clock_ = node_clock;
  clock.last_line = line;
  clock.last_clock = node_clock;
  placed.time = static_cast<double>(line) * 1e-9;
  placed.clock_offset = clock.offset;
  return placed;
}

TimeLine::Clock& TimeLine::addClock(Source& known, const Clock& added) {
  if (known.clocks.size() >= kMaxClocks) {
    known.clocks.erase(
        std::min_element(known.clocks.begin(), known.clocks.end(),
                         [](const Clock& x, const Clock& y) { return x.heard < y.heard; }));
  }
  known.clocks.push_back(added);
  return known.clocks.back();
}

TimeLine::Clock* TimeLine::continuedClock(Source& known, std::int64_t at,
                                          const Present& present) const {
  // The one heard last first.
  Clock* continued = nullptr;
  for (Clock& candidate : known.clocks) {
    if (continues(candidate, at, present) &&
        (continued == nullptr || candidate.heard > continued->heard)) {
      continued = &candidate;
    }
  }
  return continued;
}

TimeLine::Placed TimeLine::continueHeld(const std::string& source, Source& known, std::int64_t at,
                                        std::int64_t node_clock, std::int64_t now_ns,
                                        const Present& present) {
  const Held held = known.held;
  known.held = Held{};
  if (!held.interrupted) {
    // Its next message continued from the held stamp: its clock really went back.
    Placed placed = start(source, held.first, at, node_clock, Event::kJumpedBack);
    placed.release_held = true;
    placed.held_stamp = fromNanoseconds(held.first);
    return placed;
  }
  // The held clock went on, interleaved with the other one: a second clock of the source.
  Placed placed = on(addClock(known, Clock{newOffset(at, node_clock, present), at, 0, 0, 0, 0}), at,
                     node_clock, now_ns, present);
  placed.event = Event::kSecondClock;
  return placed;
}

TimeLine::Placed TimeLine::place(const std::string& source, const ros::Time& stamp,
                                 const ros::Time& clock, double now) {
  const std::int64_t at = nanoseconds(stamp);  // stamps are at most 2^32 s: no overflow
  const std::int64_t node_clock = clock.isZero() ? 0 : nanoseconds(clock);
  if (!started_) return start(source, at, at, node_clock, Event::kStarted);
  const std::int64_t now_ns = toNanoseconds(now);
  // The line's present is the node's clock (epoch_ is line zero in it): no stamp, however far
  // ahead its source's clock runs, moves it. Without a node's clock that ran since the last
  // placement (none yet, or sim time standing still), the line's last instant.
  Present present{now_ns, false, false, node_clock};
  if (node_clock != 0 && node_clock > last_clock_) {
    present.clock_runs = true;
    present.shared = sharedWith(source, node_clock);
    // Shared, the node's clock; alone, a source that ran ahead of it carried the monitor
    // there, and what comes next is placed no earlier than the line's last instant.
    present.line = present.shared ? node_clock - epoch_ : std::max(node_clock - epoch_, now_ns);
  }
  bool is_new = false;
  Source& known = sourceOf(source, is_new);
  known.heard = ++heard_;
  if (Clock* continued = continuedClock(known, at, present)) {
    Placed placed = on(*continued, at, node_clock, now_ns, present);
    if (known.held.active && !known.held.interrupted) {
      // The stamp held before this one was off the source's clock: its states are dropped.
      known.held.interrupted = true;
      ++known.dropped;
      placed.dropped_held = true;
      placed.held_stamp = fromNanoseconds(known.held.first);
    }
    return placed;
  }

  if (known.held.active && continues(known.held, at, node_clock)) {
    return continueHeld(source, known, at, node_clock, now_ns, present);
  }

  const Clock* last = nullptr;
  for (const Clock& candidate : known.clocks) {
    if (last == nullptr || candidate.heard > last->heard) last = &candidate;
  }
  // Back from a clock it kept for more than one message (or without the node's clock to tell
  // which stamp is odd): held until its next message says which.
  if (last != nullptr && at < last->last_stamp - jump_ns_ &&
      (last->messages >= 2 || node_clock == 0)) {
    known.held = Held{true, false, at, at, node_clock};
    Placed placed;
    placed.event = Event::kHeld;
    placed.held_stamp = stamp;
    return placed;
  }

  // A new source, or a stamp on none of its clocks: a clock of its own.
  Placed placed = on(addClock(known, Clock{newOffset(at, node_clock, present), at, 0, 0, 0, 0}), at,
                     node_clock, now_ns, present);
  if (!is_new) {
    placed.event = Event::kNewClock;
  } else if (placed.clock_offset != 0) {
    placed.event = Event::kOffsetChanged;
  }
  return placed;
}

bool TimeLine::stampOf(double time, std::int64_t clock_offset, ros::Time& stamp) const {
  if (!std::isfinite(time) || std::abs(time) > 1e10) return false;
  // Offsets are at most 2^32 s either way: no overflow.
  const std::int64_t at = epoch_ + toNanoseconds(time) - clock_offset;
  if (at < 0 || at >= (std::int64_t{1} << 32) * 1000000000) return false;
  stamp = fromNanoseconds(at);
  return true;
}

bool TimeLine::lineTimeOf(const ros::Time& stamp, double& time) const {
  if (!started_) return false;
  time = static_cast<double>(nanoseconds(stamp) - epoch_) * 1e-9;
  return true;
}

double TimeLine::offset(const std::string& source) const {
  const auto found = sources_.find(source);
  if (found == sources_.end() || found->second.clocks.empty()) return 0.0;
  const Clock* last = &found->second.clocks.front();
  for (const Clock& clock : found->second.clocks) {
    if (clock.heard > last->heard) last = &clock;
  }
  return static_cast<double>(last->offset) * 1e-9;
}

std::map<std::string, double> TimeLine::offsets() const {
  std::map<std::string, double> result;
  for (const auto& entry : sources_) result[entry.first] = offset(entry.first);
  return result;
}

std::map<std::string, TimeLine::SourceClocks> TimeLine::sources() const {
  std::map<std::string, SourceClocks> result;
  for (const auto& [name, source] : sources_) {
    std::vector<Clock> clocks = source.clocks;
    std::sort(clocks.begin(), clocks.end(),
              [](const Clock& x, const Clock& y) { return x.heard > y.heard; });
    SourceClocks& entry = result[name];
    for (const Clock& clock : clocks)
      entry.offsets.push_back(static_cast<double>(clock.offset) * 1e-9);
    entry.dropped = source.dropped;
  }
  return result;
}

void TimeLine::reset() {
  started_ = false;
  epoch_ = 0;
  last_clock_ = 0;
  first_source_.clear();
  sources_.clear();
}

}  // namespace collision_response
