#include <algorithm>
#include <cmath>
#include <limits>

#include "harness.h"

namespace collision_response::bench {
namespace {

/// Kinetic energy, plus the potential energy in gravity when the scene has it.
double energy(const core::Scene& scene, const std::vector<V>& positions,
              const std::vector<V>& velocities) {
  const V g = scene.effects.gravity ? scene.gravity : V::Zero();
  double total = 0;
  for (std::size_t i = 0; i < velocities.size(); ++i) {
    total += 0.5 * scene.bodies[i].mass * velocities[i].squaredNorm() -
             scene.bodies[i].mass * g.dot(positions[i]);
  }
  return total;
}

V momentum(const core::Scene& scene, const std::vector<V>& velocities) {
  V total = V::Zero();
  for (std::size_t i = 0; i < velocities.size(); ++i) total += scene.bodies[i].mass * velocities[i];
  return total;
}

/// The apex of flight `flight` (1: after the first bounce) of body `body`, from three samples
/// around its highest one: the parabola through them is the flight's, exactly when the samples
/// lie on it. NaN when the flight has fewer than three samples.
double apexHeight(const Run& run, std::size_t body, int flight) {
  // Flight n: the samples after the n-th bounce (a sample falling, the next rising) up to the
  // next bounce.
  int bounces = 0;
  std::vector<std::size_t> samples;
  for (std::size_t k = 1; k < run.times.size(); ++k) {
    if (run.velocities[k - 1][body].z() < 0 && run.velocities[k][body].z() > 0) ++bounces;
    if (bounces > flight) break;
    if (bounces == flight) samples.push_back(k);
  }
  if (samples.size() < 3) return NAN;
  std::size_t top = 1;
  for (std::size_t j = 1; j + 1 < samples.size(); ++j) {
    if (run.positions[samples[j]][body].z() > run.positions[samples[top]][body].z()) top = j;
  }
  const std::size_t k0 = samples[top - 1], k1 = samples[top], k2 = samples[top + 1];
  const double t0 = run.times[k0], t1 = run.times[k1], t2 = run.times[k2];
  const double z0 = run.positions[k0][body].z(), z1 = run.positions[k1][body].z(),
               z2 = run.positions[k2][body].z();
  // The parabola through the three points (divided differences): its top.
  const double d01 = (z1 - z0) / (t1 - t0), d12 = (z2 - z1) / (t2 - t1);
  const double a = (d12 - d01) / (t2 - t0);
  if (!(a < 0)) return std::max({z0, z1, z2});
  const double t_top = 0.5 * (t0 + t1) - d01 / (2 * a);
  return z0 + (t_top - t0) * (d01 + a * (t_top - t1));
}

/// The first update at which `changed` holds for body `body`; its time, or NaN.
template <typename Predicate>
double firstTime(const Run& run, std::size_t body, Predicate changed) {
  for (std::size_t k = 0; k < run.times.size(); ++k) {
    if (changed(run.velocities[k][body])) return run.times[k];
  }
  return NAN;
}

/// The larger, NaN (not measurable) winning: a worst case is not better for a missing value.
double worst(double current, double value) {
  if (std::isnan(current) || std::isnan(value)) return NAN;
  return std::max(current, value);
}

double firstImpact(const Run& run) {
  return run.impact_times.empty()
             ? NAN
             : *std::min_element(run.impact_times.begin(), run.impact_times.end());
}

}  // namespace

Errors measure(const BenchScene& bench, const core::Scene& scene, const Run& run,
               const Run* reference) {
  Errors errors;
  const std::vector<V>& v0 = run.velocities.front();
  const std::vector<V>& v1 = run.velocities.back();
  const std::vector<V>& p0 = run.positions.front();
  const std::vector<V>& p1 = run.positions.back();
  if (bench.name == "drop_test") {
    // Every ball dropped from h = 1 m: the first impact at sqrt(2 h / g), the first bounce up
    // to e^2 h, the third to e^6 h.
    const double g = 9.81, h = 1.0, first = std::sqrt(2 * h / g);
    double instant = 0, restitution = 0, apex = 0;
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const double e = core::seedTable()[i].restitution;
      const double found = run.impact_times.empty()
                               ? firstTime(run, i, [](const V& v) { return v.z() > 0; })
                               : firstImpact(run);
      instant = worst(instant, std::abs(found - first));
      const double r = scene.bodies[i].radius;
      restitution =
          worst(restitution, std::abs(std::sqrt((apexHeight(run, i, 1) - r) / h) - e) / e);
      const double third = std::pow(e, 6) * h;
      apex = worst(apex, std::abs((apexHeight(run, i, 3) - r) - third) / third);
    }
    errors.instant = instant;
    errors.restitution = restitution;
    errors.apex = apex;
  } else if (bench.name == "cradle") {
    const double exact = 0.02;  // 0.02 m at 1 m/s
    errors.instant = std::abs((run.impact_times.empty()
                                   ? firstTime(run, 0, [](const V& v) { return v.x() < 1 - 1e-9; })
                                   : firstImpact(run)) -
                              exact);
    double worst = 0;
    for (std::size_t i = 0; i < v1.size(); ++i) {
      worst = std::max(worst, (v1[i] - V(i + 1 == v1.size() ? 1.0 : 0.0, 0, 0)).norm());
    }
    errors.velocity = worst;
    errors.momentum_drift =
        (momentum(scene, v1) - momentum(scene, v0)).norm() / momentum(scene, v0).norm();
    errors.energy_drift =
        std::abs(energy(scene, p1, v1) - energy(scene, p0, v0)) / energy(scene, p0, v0);
  } else if (bench.name == "billiards_break") {
    const double r = 0.028575, exact = (1.905 - 0.635 - 2 * r) / 6.0;
    errors.instant = std::abs((run.impact_times.empty()
                                   ? firstTime(run, 0, [](const V& v) { return v.x() < 6 - 1e-9; })
                                   : firstImpact(run)) -
                              exact);
    if (reference != nullptr) {
      double sum = 0;
      const std::vector<V>& ref = reference->velocities.back();
      for (std::size_t i = 0; i < v1.size(); ++i) sum += (v1[i] - ref[i]).squaredNorm();
      errors.velocity = std::sqrt(sum / static_cast<double>(v1.size()));
    }
  } else if (bench.name == "tunnelling") {
    const double exact = (1.0 - 0.03) / 50.0;
    const bool passed = run.positions.back()[0].x() > 1.0;
    errors.missed = passed ? 1 : 0;
    if (!passed) {
      errors.instant =
          std::abs((run.impact_times.empty()
                        ? firstTime(run, 0, [](const V& v) { return v.x() < 50 - 1e-9; })
                        : firstImpact(run)) -
                   exact);
      errors.velocity = (v1[0] - V(-0.8 * 50, 0, 0)).norm();
    }
  } else if (bench.name == "sphere_gas") {
    errors.energy_drift =
        std::abs(energy(scene, p1, v1) - energy(scene, p0, v0)) / std::abs(energy(scene, p0, v0));
  }
  return errors;
}

}  // namespace collision_response::bench
