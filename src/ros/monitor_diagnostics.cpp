#include "collision_response/ros/monitor_diagnostics.h"

#include <algorithm>

#include "collision_response/core/validation.h"

namespace collision_response {

void MonitorDiagnostics::stepped(double step_seconds, double step_cpu_seconds,
                                 double latency_seconds, std::size_t impacts_published) {
  ++period_.steps;
  period_.step_seconds += step_seconds;
  period_.step_seconds_max = std::max(period_.step_seconds_max, step_seconds);
  period_.step_cpu_seconds_max = std::max(period_.step_cpu_seconds_max, step_cpu_seconds);
  period_.latency_seconds += latency_seconds;
  period_.latency_seconds_max = std::max(period_.latency_seconds_max, latency_seconds);
  period_.impacts += impacts_published;
  impacts_published_ += impacts_published;
}

MonitorFigures MonitorFigures::of(const MonitorCycle& cycle) {
  MonitorFigures figures;
  const core::Scene& scene = cycle.scene();
  figures.detection = core::toString(scene.detection);
  figures.combine_rule = core::toString(scene.materials.combineRule());
  figures.restitution_threshold = scene.restitution_threshold;
  figures.bodies = cycle.monitor().bodyCount();
  figures.tracked = cycle.monitor().trackedBodies();
  figures.stepped = cycle.steppedBodies();
  figures.obstacle_work = cycle.obstacleWork();
  figures.sources = cycle.timeLine().sources();
  return figures;
}

void MonitorDiagnostics::report(diagnostic_updater::DiagnosticStatusWrapper& status,
                                const MonitorFigures& figures, std::size_t waiting, double running,
                                double slow) {
  const double seconds = std::max((ros::WallTime::now() - period_.start).toSec(), 1e-9);
  std::string dropped;  // in this period, by reason
  for (int i = 0; i < kReasonCount; ++i) {
    const Reason reason = static_cast<Reason>(i);
    const std::uint64_t events = totals_[i] - period_.totals[i];
    if (events == 0 || !isDrop(reason)) continue;
    const std::string name = counterName(reason);
    dropped += (dropped.empty() ? "" : "; ") + name.substr(name.find(": ") + 2) + " (" +
               std::to_string(events) + ")";
  }
  const auto inPeriod = [this](Reason reason) {
    return totals_[static_cast<std::size_t>(reason)] -
           period_.totals[static_cast<std::size_t>(reason)];
  };
  const std::uint64_t outputs_dropped =
      inPeriod(Reason::kImpactNotFinite) + inPeriod(Reason::kContactNotFinite);
  if (running >= slow) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "an update has been running for " + core::formatNumber(running) + " s");
  } else if (!dropped.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   std::string(outputs_dropped > 0 ? "dropped: " : "states dropped: ") + dropped);
  } else if (period_.messages == 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                   "no states received in the last " + core::formatNumber(seconds) + " s");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                   std::to_string(figures.tracked) + " bodies tracked");
  }
  const auto steps = static_cast<double>(period_.steps);
  status.add("detection", figures.detection);
  status.add("restitution threshold (m/s)", figures.restitution_threshold);
  status.add("combine rule", figures.combine_rule);
  status.add("bodies in the scene", figures.bodies);
  status.add("bodies tracked", figures.tracked);
  status.add("bodies in stepped clusters", figures.stepped);
  status.add("update in progress (s)", running);
  status.add("input messages per second", static_cast<double>(period_.messages) / seconds);
  status.add("states per second", static_cast<double>(period_.states) / seconds);
  status.add("impacts per second", static_cast<double>(period_.impacts) / seconds);
  status.add("updates", period_.steps);
  status.add("processing time per update, mean (ms)",
             period_.steps ? 1e3 * period_.step_seconds / steps : 0.0);
  status.add("processing time per update, max (ms)", 1e3 * period_.step_seconds_max);
  status.add("processing CPU per update, max (ms)", 1e3 * period_.step_cpu_seconds_max);
  status.add("arrival to publication, mean (ms)",
             period_.steps ? 1e3 * period_.latency_seconds / steps : 0.0);
  status.add("arrival to publication, max (ms)", 1e3 * period_.latency_seconds_max);
  status.add("messages waiting", waiting);
  status.add("states received (total)", states_received_);
  status.add("states used (total)", states_used_);
  status.add("transforms missing (states dropped, total)", total(Reason::kTransformMissing));
  status.add("obstacle transforms missing (total)", total(Reason::kObstacleTransform));
  status.add("obstacle frames looked up, last update", figures.obstacle_work.lookups);
  status.add("obstacle placements, last update", figures.obstacle_work.placements);
  status.add("obstacles placed again within the last update", figures.obstacle_work.near);
  // By source (at most TimeLine::kMaxSources): the clocks that are not the node's, and the
  // stamps dropped off its clock.
  for (const auto& [source, clocks] : figures.sources) {
    if (!clocks.offsets.empty() && clocks.offsets[0] != 0.0)
      status.add("clock offset of " + source + " (s)", clocks.offsets[0]);
    if (clocks.offsets.size() > 1)
      status.add("clock offset of " + source + ", its other clock (s)", clocks.offsets[1]);
    if (clocks.dropped > 0)
      status.add("stamps off the clock of " + source + ", dropped (total)", clocks.dropped);
  }
  for (int i = 0; i < kReasonCount; ++i) {
    if (totals_[i] > 0)
      status.add(std::string(counterName(static_cast<Reason>(i))) + " (total)", totals_[i]);
  }
  if (!last_beyond_resolution_.empty()) {
    status.add("last state beyond resolution", last_beyond_resolution_);
  }
  if (!last_over_work_budget_.empty()) {
    status.add("last bodies stepped over the exact work budget", last_over_work_budget_);
  }
  status.add("impacts published (total)", impacts_published_);
  period_ = Period{};
  period_.totals = totals_;
}

}  // namespace collision_response
