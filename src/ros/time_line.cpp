#include "collision_response/ros/time_line.h"

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

}  // namespace

TimeLine::TimeLine(double clock_jump_back) : jump_ns_(toNanoseconds(clock_jump_back)) {}

TimeLine::Placed TimeLine::place(const std::string& source, const ros::Time& stamp, double now) {
  const std::int64_t at = nanoseconds(stamp);  // stamps are at most 2^32 s: no overflow
  Placed placed;
  const auto restart = [&](Event event) {
    reset();
    started_ = true;
    epoch_ = at;
    first_source_ = source;
    sources_[source] = Source{0, at, ++heard_};
    placed.time = 0.0;
    placed.event = event;
    return placed;
  };
  if (!started_) return restart(Event::kStarted);
  auto found = sources_.find(source);
  if (found != sources_.end() && at < found->second.last_stamp - jump_ns_) {
    return restart(Event::kJumpedBack);
  }
  if (found == sources_.end()) {
    if (sources_.size() >= kMaxSources) {
      auto oldest = sources_.begin();
      for (auto it = sources_.begin(); it != sources_.end(); ++it) {
        if (it->second.heard < oldest->second.heard) oldest = it;
      }
      sources_.erase(oldest);
    }
    found = sources_.emplace(source, Source{0, at, 0}).first;
  }
  Source& known = found->second;
  known.heard = ++heard_;
  if (at > known.last_stamp) known.last_stamp = at;
  std::int64_t line = at - epoch_ + known.offset;
  const std::int64_t now_ns = toNanoseconds(now);
  if (line < now_ns - jump_ns_) {
    // Behind the line although its own clock did not go back: another clock. Shifted onto
    // the line's present.
    known.offset += now_ns - line;
    line = now_ns;
    placed.event = Event::kOffsetChanged;
  }
  placed.time = static_cast<double>(line) * 1e-9;
  return placed;
}

bool TimeLine::stampOf(double time, ros::Time& stamp) const {
  if (!std::isfinite(time) || std::abs(time) > 1e10) return false;
  const std::int64_t at = epoch_ + toNanoseconds(time);
  if (at < 0 || at >= (std::int64_t{1} << 32) * 1000000000) return false;
  stamp.sec = static_cast<std::uint32_t>(at / 1000000000);
  stamp.nsec = static_cast<std::uint32_t>(at % 1000000000);
  return true;
}

double TimeLine::offset(const std::string& source) const {
  const auto found = sources_.find(source);
  return found == sources_.end() ? 0.0 : static_cast<double>(found->second.offset) * 1e-9;
}

std::map<std::string, double> TimeLine::offsets() const {
  std::map<std::string, double> result;
  for (const auto& [name, source] : sources_)
    result[name] = static_cast<double>(source.offset) * 1e-9;
  return result;
}

void TimeLine::reset() {
  started_ = false;
  epoch_ = 0;
  first_source_.clear();
  sources_.clear();
}

}  // namespace collision_response
