#include "collision_response/ros/prompt_shutdown.h"

#include <ros/ros.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>

namespace collision_response {
namespace {

// Set by the signal handler (lock-free, so safe there), read by the watchdog thread.
std::atomic<bool> g_signalled{false};

extern "C" void onSignal(int /*signal*/) {
  g_signalled.store(true);
  ros::requestShutdown();  // what roscpp's own SIGINT handler does
}

}  // namespace

PromptShutdown::PromptShutdown(double grace) {
  static_assert(std::atomic<bool>::is_always_lock_free, "the handler needs a lock-free flag");
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  watchdog_ = std::thread([this, grace] {
    using Clock = std::chrono::steady_clock;
    while (!done_.load() && !g_signalled.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (done_.load()) return;
    const auto deadline = Clock::now() + std::chrono::duration<double>(grace);
    while (!done_.load() && Clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (done_.load()) return;
    ROS_WARN(
        "shutting down mid-update: a callback still running %.1f s after the signal is "
        "abandoned",
        grace);
    std::fflush(stdout);
    std::fflush(stderr);
    std::_Exit(0);
  });
}

PromptShutdown::~PromptShutdown() {
  done_.store(true);
  watchdog_.join();
}

}  // namespace collision_response
