// The monitor's status for /diagnostics: what it received, did and dropped, by reason, since the
// last report and in total. Counters are keyed by Reason (a fixed set), never by what a
// publisher sent.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/time.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>

#include "collision_response/ros/monitor_cycle.h"
#include "collision_response/ros/state_intake.h"

namespace collision_response {

/// What the report shows of the monitor itself, copied from it after every update (and after
/// live tuning) on the monitor's thread, so that /diagnostics can be published from a thread of
/// its own while an update runs.
struct MonitorFigures {
  std::string detection, combine_rule;
  double restitution_threshold = 0.0;
  std::size_t bodies = 0, tracked = 0, stepped = 0;
  MonitorCycle::ObstacleWork obstacle_work;  ///< the last update's (tf-attached obstacles)
  std::map<std::string, TimeLine::SourceClocks> sources;
  static MonitorFigures of(const MonitorCycle& cycle);
};

class MonitorDiagnostics {
 public:
  void received(std::size_t states) {
    ++period_.messages;
    period_.states += states;
    states_received_ += states;
  }
  /// States of a processed input that the monitor took (those dropped are counted by reason).
  void used(std::size_t states) { states_used_ += states; }
  void count(Reason reason, std::size_t events = 1) {
    totals_[static_cast<std::size_t>(reason)] += events;
  }
  /// The warning of the last state dropped as beyond resolution: it names the body and the
  /// field, and /diagnostics shows it (one entry, whatever the publisher sends).
  void noteBeyondResolution(const std::string& text) { last_beyond_resolution_ = text; }
  /// The warning of the last update whose exact work ran over the scene's budget: it names the
  /// bodies stepped from there (a few, and how many more), and /diagnostics shows it.
  void noteOverWorkBudget(const std::string& text) { last_over_work_budget_ = text; }
  /// A processed input: the step's processing time (wall, and the CPU of the monitor's thread:
  /// what the update cost, whatever else shares the cores) and the arrival-to-publication
  /// latency (s).
  void stepped(double step_seconds, double step_cpu_seconds, double latency_seconds,
               std::size_t impacts_published);

  std::uint64_t total(Reason reason) const { return totals_[static_cast<std::size_t>(reason)]; }
  std::uint64_t impactsPublished() const { return impacts_published_; }

  /// Fills `status` (the summary: WARN while states or impacts are dropped, with the reasons
  /// and counts of the period; OK otherwise) and starts a new period.
  /// `waiting`: the inputs queued for the monitor (for the update in progress, or for their
  /// transforms). `running`: how long the update in progress has run (s; 0: none), shown as "update
  /// in progress (s)", and in the summary (WARN) from `slow` s on.
  void report(diagnostic_updater::DiagnosticStatusWrapper& status, const MonitorFigures& figures,
              std::size_t waiting, double running = 0.0, double slow = INFINITY);
  void report(diagnostic_updater::DiagnosticStatusWrapper& status, const MonitorCycle& cycle,
              std::size_t waiting) {
    report(status, MonitorFigures::of(cycle), waiting);
  }

 private:
  struct Period {
    ros::WallTime start = ros::WallTime::now();
    std::uint64_t messages = 0, states = 0, steps = 0, impacts = 0;
    double step_seconds = 0.0, step_seconds_max = 0.0, step_cpu_seconds_max = 0.0;
    double latency_seconds = 0.0, latency_seconds_max = 0.0;  ///< arrival to publication
    std::array<std::uint64_t, kReasonCount> totals{};         ///< totals_ at its start
  };
  Period period_;
  std::array<std::uint64_t, kReasonCount> totals_{};
  std::uint64_t impacts_published_ = 0;
  /// In total: every state received is used, dropped (counted by reason) or waiting.
  std::uint64_t states_received_ = 0, states_used_ = 0;
  std::string last_beyond_resolution_;
  std::string last_over_work_budget_;
};

}  // namespace collision_response
