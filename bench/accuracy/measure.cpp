// The metrics: what each scene measures of a run, against reference/references.txt (answers
// computed outside the code under test, by reference/make_references.py). One function per kind
// of scene; measure() picks it by name.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "harness.h"

namespace collision_response::bench {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Kinetic energy, plus the potential energy in gravity when the scene has it.
double energy(const core::Scene& scene, const Run& run, std::size_t sample) {
  const V g = scene.effects.gravity ? scene.gravity : V::Zero();
  double total = 0;
  for (std::size_t i = 0; i < run.bodies; ++i) {
    const double m = scene.bodies[i].mass;
    total += 0.5 * m * run.velocity(sample, i).squaredNorm() - m * g.dot(run.position(sample, i));
  }
  return total;
}

V momentum(const core::Scene& scene, const Run& run, std::size_t sample) {
  V total = V::Zero();
  for (std::size_t i = 0; i < run.bodies; ++i)
    total += scene.bodies[i].mass * run.velocity(sample, i);
  return total;
}

V row3(const std::vector<double>& row, std::size_t from) {
  return V(row.at(from), row.at(from + 1), row.at(from + 2));
}

/// The reference's state of body `body` at the scene's end: position and velocity.
std::pair<V, V> finalState(const References& refs, const std::string& scene, std::size_t body) {
  for (const std::vector<double>& row : refs.rows(scene, "final")) {
    if (static_cast<std::size_t>(row.at(0)) == body) return {row3(row, 1), row3(row, 4)};
  }
  throw std::runtime_error("reference " + scene + " final: no body " + std::to_string(body));
}

/// The first instant at which an impact changed body `body`'s motion: the engine's own report
/// (ours), or the first update whose velocity differs from the free motion of the update before
/// (the others: the first update after the impact).
double firstImpact(const core::Scene& scene, const Run& run, std::size_t body) {
  if (run.reports_impacts) {
    double first = kNaN;
    for (const ReportedImpact& impact : run.impacts) {
      const bool involved =
          impact.body == body || (!impact.other_is_obstacle && impact.other == body);
      if (involved && !(impact.time >= first)) first = impact.time;
    }
    return first;
  }
  const V g = scene.effects.gravity ? scene.gravity : V::Zero();
  for (std::size_t k = 1; k < run.samples(); ++k) {
    const double dt = run.times[k] - run.times[k - 1];
    const V expected = run.velocity(k - 1, body) + g * dt;
    if ((run.velocity(k, body) - expected).norm() > 1e-5 * expected.norm() + 1e-6) {
      return run.times[k];
    }
  }
  return kNaN;
}

/// The apex of each flight of body `body` against gravity (centre height, m), flight 1 after the
/// first impact: what the engine's output implies. Ours reports every impact: the apex follows
/// from the post-impact velocity at the contact, h + u^2 / 2g (the parabola the source then
/// plays). The others report states: at the top of each flight (the last update before the
/// upward speed turns negative) h + u^2 / 2g of that state, exact for any state on a ballistic
/// flight. A flight shorter than an update (no state in it rising, then falling) is missing.
std::vector<double> apexes(const core::Scene& scene, const Run& run, std::size_t body) {
  const double g = scene.gravity.norm();
  const V up = -scene.gravity / g;
  std::vector<double> tops;
  if (run.reports_impacts) {
    double last_time = kNaN;
    bool last_pushed = false;
    for (const ReportedImpact& impact : run.impacts) {
      const bool first = impact.body == body;
      if (!first && (impact.other_is_obstacle || impact.other != body)) continue;
      const V& position = first ? impact.position : impact.other_position;
      const double rise = up.dot(first ? impact.velocity_after : impact.other_velocity_after);
      // Several impacts at one instant (a cluster's rounds): the last one's velocity stays.
      if (impact.time == last_time && last_pushed) tops.pop_back();
      last_time = impact.time;
      // An impact after which the body does not rise (it comes to rest) starts no flight.
      last_pushed = rise > 0;
      if (last_pushed) tops.push_back(up.dot(position) + rise * rise / (2 * g));
    }
    return tops;
  }
  bool rising = false;
  for (std::size_t k = 1; k < run.samples(); ++k) {
    const double before = up.dot(run.velocity(k - 1, body)), now = up.dot(run.velocity(k, body));
    if (before <= 0 && now > 0) rising = true;  // a bounce
    if (rising && before > 0 && now <= 0) {     // the top: state k - 1 is the last rising one
      tops.push_back(up.dot(run.position(k - 1, body)) + before * before / (2 * g));
      rising = false;
    }
  }
  return tops;
}

/// Body `body`'s first impact against the reference's.
double instantError(const std::string& name, const core::Scene& scene, const Run& run,
                    const References& refs, std::size_t body) {
  for (const std::vector<double>& row : refs.rows(name, "first_impact_of")) {
    if (static_cast<std::size_t>(row.at(0)) == body) {
      return std::abs(firstImpact(scene, run, body) - row.at(1));
    }
  }
  return kNaN;
}

/// The larger, NaN (not measurable) winning: a worst case is not better for a missing value.
double worst(double current, double value) {
  if (std::isnan(current) || std::isnan(value)) return kNaN;
  return std::max(current, value);
}

// The seed's drop test: e from each ball's first apex, the apex after three bounces, the instant
// of the first impact; worst ball.
Metrics dropTest(const std::string& name, const core::Scene& scene, const Run& run,
                 const References& refs) {
  double instant = 0, restitution = 0, apex = 0;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const double r = scene.bodies[i].radius;
    double reference_rise[4] = {kNaN, kNaN, kNaN, kNaN};
    for (const std::vector<double>& row : refs.rows(name, "apex")) {
      const auto flight = static_cast<std::size_t>(row.at(1));
      if (static_cast<std::size_t>(row.at(0)) == i && flight <= 3) {
        reference_rise[flight] = row.at(2) - r;
      }
    }
    instant = worst(instant, instantError(name, scene, run, refs, i));
    // No flight: the ball did not bounce (e measured 0, an error of 100 %).
    const std::vector<double> tops = apexes(scene, run, i);
    const double rise1 = tops.size() >= 1 ? tops[0] - r : 0.0;
    const double rise3 = tops.size() >= 3 ? tops[2] - r : 0.0;
    // e = sqrt(h'/h): the measured e against the exact one is sqrt(rise / exact rise).
    restitution = worst(restitution, std::abs(std::sqrt(rise1 / reference_rise[1]) - 1));
    apex = worst(apex, std::abs(rise3 - reference_rise[3]) / reference_rise[3]);
  }
  return {{"instant", instant}, {"restitution", restitution}, {"apex", apex}};
}

/// The final velocities against the reference's: RMS over the bodies, or the worst body (m/s);
/// the positions' RMS (m).
Metrics finalVelocities(const std::string& name, const Run& run, const References& refs, bool rms) {
  const std::size_t last = run.samples() - 1;
  double worst_velocity = 0, sum_velocity = 0, sum_position = 0;
  for (std::size_t i = 0; i < run.bodies; ++i) {
    const auto [p, v] = finalState(refs, name, i);
    const double dv = (run.velocity(last, i) - v).norm();
    worst_velocity = std::max(worst_velocity, dv);
    sum_velocity += dv * dv;
    sum_position += (run.position(last, i) - p).squaredNorm();
  }
  const double n = static_cast<double>(run.bodies);
  Metrics metrics = {{"velocity", rms ? std::sqrt(sum_velocity / n) : worst_velocity},
                     {"position", std::sqrt(sum_position / n)}};
  if (run.reports_impacts) metrics["impacts"] = static_cast<double>(run.impacts.size());
  return metrics;
}

double energyDrift(const std::string& name, const core::Scene& scene, const Run& run,
                   const References& refs) {
  const double e0 = refs.value(name, "energy0");
  return std::abs(energy(scene, run, run.samples() - 1) - e0) / std::abs(e0);
}

// The cradle (e = 1, no obstacle): final velocities (worst ball), energy and momentum against
// the start, the striker's first impact.
Metrics cradle(const std::string& name, const core::Scene& scene, const Run& run,
               const References& refs) {
  Metrics metrics = finalVelocities(name, run, refs, false);
  const V p0 = row3(refs.rows(name, "momentum0").front(), 0);
  metrics["energy_drift"] = energyDrift(name, scene, run, refs);
  metrics["momentum_drift"] = (momentum(scene, run, run.samples() - 1) - p0).norm() / p0.norm();
  metrics["instant"] = instantError(name, scene, run, refs, 0);
  return metrics;
}

// The break: velocities and positions after 1 s (RMS over the balls), the cue's first impact.
Metrics billiardsBreak(const std::string& name, const core::Scene& scene, const Run& run,
                       const References& refs) {
  Metrics metrics = finalVelocities(name, run, refs, true);
  metrics["instant"] = instantError(name, scene, run, refs, 0);
  metrics["reference_impacts"] = refs.value(name, "impacts");
  return metrics;
}

// The fast ball against the post: missed or not; its velocity after and the instant.
Metrics tunnelling(const std::string& name, const core::Scene& scene, const Run& run,
                   const References& refs) {
  const std::size_t last = run.samples() - 1;
  const bool passed = run.position(last, 0).x() > scene.obstacles.front().position.x();
  const auto [p, v] = finalState(refs, name, 0);
  (void)p;
  return {{"missed", passed ? 1.0 : 0.0},
          {"velocity", (run.velocity(last, 0) - v).norm()},
          {"instant", passed ? kNaN : instantError(name, scene, run, refs, 0)}};
}

// Energy against the start (the gas: its reference is the conservation law).
Metrics conservation(const std::string& name, const core::Scene& scene, const Run& run,
                     const References& refs) {
  const double e0 = refs.value(name, "energy0");
  Metrics metrics = {
      {"energy_drift", std::abs(energy(scene, run, run.samples() - 1) - e0) / std::abs(e0)}};
  if (run.reports_impacts) metrics["impacts"] = static_cast<double>(run.impacts.size());
  return metrics;
}

// 1,000 bounces: every bounce's apex against h e^(2k), as long as the exact bounce rises 1 nm.
Metrics bounces(const std::string& name, const core::Scene& scene, const Run& run,
                const References& refs) {
  const double r = scene.bodies.front().radius;
  std::vector<double> exact;  // exact[k - 1]: bounce k's rise above the contact
  for (const std::vector<double>& row : refs.rows(name, "bounce")) exact.push_back(row.at(1));
  const std::vector<double> tops = apexes(scene, run, 0);
  const std::size_t count = exact.size();
  const auto error = [&](std::size_t k) {  // bounce k (1-based); a missing one is off by 100 %
    return k <= tops.size() ? std::abs((tops[k - 1] - r) - exact[k - 1]) / exact[k - 1] : 1.0;
  };
  std::size_t faithful = 0;
  while (faithful < count && error(faithful + 1) <= 0.01) ++faithful;
  double first_ten = 0;
  for (std::size_t k = 1; k <= std::min<std::size_t>(10, count); ++k)
    first_ten = std::max(first_ten, error(k));
  return {{"bounces", static_cast<double>(std::min<std::size_t>(tops.size(), 1000))},
          {"exact_bounces", static_cast<double>(count)},
          {"faithful", static_cast<double>(faithful)},
          {"apex_error_10", first_ten},
          {"apex_error_last", error(count)}};
}

// The two-ball chain: the final velocities against the exact ones (m/s), energy, order kept.
Metrics chain(const std::string& name, const core::Scene& scene, const Run& run,
              const References& refs) {
  Metrics metrics = finalVelocities(name, run, refs, false);
  metrics["energy_drift"] = energyDrift(name, scene, run, refs);
  const std::size_t last = run.samples() - 1;
  const double light = run.position(last, 0).x(), heavy = run.position(last, 1).x();
  const double r_light = scene.bodies[0].radius, r_heavy = scene.bodies[1].radius;
  // Out of order: the light ball through the wall or through the heavy one (by more than its
  // radius: an overlap still being resolved is not a pass).
  const bool passed =
      light < 0 || heavy < light || heavy - r_heavy < 0 || light - r_light < -r_light;
  metrics["passed"] = passed ? 1.0 : 0.0;
  metrics["reference_impacts"] = refs.value(name, "impacts");
  return metrics;
}

}  // namespace

Metrics measure(const BenchScene& bench, const std::string& effects, const Run& run,
                const References& references) {
  const core::Scene scene = withEffects(bench, effects);
  const std::string name = referenceName(bench, effects);
  if (!references.has(name, "energy0")) {
    // No reference for these effects (friction and spin): only what needs none.
    return {{"impacts", run.reports_impacts ? static_cast<double>(run.impacts.size()) : kNaN}};
  }
  if (bench.name == "drop_test") return dropTest(name, scene, run, references);
  if (bench.name == "billiards_break") return billiardsBreak(name, scene, run, references);
  if (bench.name == "tunnelling") return tunnelling(name, scene, run, references);
  if (bench.name.rfind("bounce_", 0) == 0) return bounces(name, scene, run, references);
  if (bench.name.rfind("chain_", 0) == 0) return chain(name, scene, run, references);
  if (bench.reference == "conservation") return conservation(name, scene, run, references);
  if (bench.name == "cradle") return cradle(name, scene, run, references);
  throw std::runtime_error("no metrics for scene " + bench.name + " (measure.cpp)");
}

}  // namespace collision_response::bench
