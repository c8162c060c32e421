#include "collision_response/ros/throttled_warning.h"

namespace collision_response {

void ThrottledWarning::warn(const std::string& topic, Reason reason, const std::string& text,
                            std::size_t count, int variant) {
  const ros::WallTime now = ros::WallTime::now();
  auto key = std::make_tuple(topic, reason, variant);
  if (last_.count(key) == 0 && last_.size() >= kMaxKeys) {
    for (auto it = last_.begin(); it != last_.end();) {
      const bool idle = (now - it->second.last).toSec() >= period_ && it->second.held_back == 0;
      it = idle ? last_.erase(it) : std::next(it);
    }
    if (last_.size() >= kMaxKeys) key = std::make_tuple("(other topics)", reason, 0);
  }
  auto [entry, inserted] = last_.try_emplace(key);
  if (!inserted && (now - entry->second.last).toSec() < period_) {
    entry->second.held_back += count;
    return;
  }
  // A warning's text quotes what a publisher sent (tf2's reason repeats a frame id whole): a
  // line is at most kMaxLength characters.
  std::string line =
      topic + ": " + (text.size() > kMaxLength ? text.substr(0, kMaxLength) + "..." : text);
  if (entry->second.held_back > 0) {
    line += " (and " + std::to_string(entry->second.held_back) + " more like it in the last " +
            std::to_string((now - entry->second.last).toSec()).substr(0, 4) + " s)";
  }
  entry->second = Entry{now, 0};
  if (reason == Reason::kInternalError) {
    ROS_ERROR_STREAM(line);
  } else {
    ROS_WARN_STREAM(line);
  }
}

}  // namespace collision_response
