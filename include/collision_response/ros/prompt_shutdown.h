// SIGINT ends the process within a grace period, even while a callback is still running (an
// update of the monitor, or of the scene player's played motion, that takes longer): roscpp's own
// handler only asks for a shutdown, which waits for the callback to return.
#pragma once

#include <atomic>
#include <thread>

namespace collision_response {

/// For a node's main(), from ros::init (with ros::init_options::NoSigintHandler) to the end of
/// ros::spin(): SIGINT (and SIGTERM) ask roscpp to shut down, as its own handler does; if the
/// process is still running `grace` seconds later, it logs that it ends mid-callback and exits
/// (status 0) without waiting for the callback.
class PromptShutdown {
 public:
  explicit PromptShutdown(double grace = 0.5);
  ~PromptShutdown();
  PromptShutdown(const PromptShutdown&) = delete;
  PromptShutdown& operator=(const PromptShutdown&) = delete;

 private:
  std::atomic<bool> done_{false};
  std::thread watchdog_;
};

}  // namespace collision_response
