// Warnings throttled per reason: one a second for each distinct key (a topic and a field, say),
// so that one noisy input does not hide a different problem on another.
#pragma once

#include <ros/console.h>
#include <ros/time.h>

#include <map>
#include <string>

namespace collision_response {

class ThrottledWarning {
 public:
  explicit ThrottledWarning(double period = 1.0) : period_(period) {}

  /// Logs `text` as a warning unless `key` was logged less than the period ago (wall time).
  void warn(const std::string& key, const std::string& text) {
    const ros::WallTime now = ros::WallTime::now();
    const auto last = last_.find(key);
    if (last != last_.end() && (now - last->second).toSec() < period_) return;
    last_[key] = now;
    ROS_WARN_STREAM(text);
  }

 private:
  double period_;
  std::map<std::string, ros::WallTime> last_;
};

}  // namespace collision_response
