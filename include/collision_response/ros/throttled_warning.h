// Warnings throttled by reason: at most one a period for each (topic, reason), so that one noisy
// input does not hide a different problem on another, and the ones held back are counted into
// the next. The key never holds what a publisher chose (an id, a frame): its space is the node's
// topics times the reasons, and a hard cap bounds it even so.
#pragma once

#include <ros/console.h>
#include <ros/time.h>

#include <cstddef>
#include <map>
#include <string>
#include <tuple>

#include "collision_response/ros/state_intake.h"

namespace collision_response {

class ThrottledWarning {
 public:
  explicit ThrottledWarning(double period = 1.0) : period_(period) {}

  /// At most this many keys are kept; past it, keys idle for a period are forgotten, and if
  /// none is, the new key shares one overflow key per reason.
  static constexpr std::size_t kMaxKeys = 1024;
  /// Characters of a warning's text, at most.
  static constexpr std::size_t kMaxLength = 512;

  /// Logs "`topic`: `text`" (a warning; an error for kInternalError) unless this topic and
  /// reason logged less than a period ago (wall time); `count` events are held back then, and
  /// the next line that goes out says how many were.
  void warn(const std::string& topic, Reason reason, const std::string& text, std::size_t count = 1,
            int variant = 0);

  std::size_t keys() const { return last_.size(); }

 private:
  struct Entry {
    ros::WallTime last;
    std::size_t held_back = 0;
  };
  double period_;
  std::map<std::tuple<std::string, Reason, int>, Entry> last_;
};

}  // namespace collision_response
