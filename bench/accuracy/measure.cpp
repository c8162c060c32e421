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

// --- lasting contact ---------------------------------------------------------------------------

/// How deep the bodies went into what they touch at one sampled instant (m, >= 0): the deepest
/// overlap with a plane, with an immovable sphere, and between two bodies.
struct Penetration {
  double planes = 0, spheres = 0, bodies = 0;
  double any() const { return std::max({planes, spheres, bodies}); }
};

Penetration penetrationAt(const core::Scene& scene, const Run& run, std::size_t sample) {
  Penetration deepest;
  for (std::size_t i = 0; i < run.bodies; ++i) {
    const V& p = run.position(sample, i);
    const double r = scene.bodies[i].radius;
    for (const core::ObstacleSpec& obstacle : scene.obstacles) {
      if (obstacle.shape == core::ObstacleShape::kPlane) {
        const V n = obstacle.normal.normalized();
        deepest.planes = std::max(deepest.planes, r - (n.dot(p) - obstacle.offset));
      } else if (obstacle.shape == core::ObstacleShape::kMesh) {
        continue;  // its scene's own metric (ballOnMeshFloor)
      } else if (obstacle.shape == core::ObstacleShape::kBox) {
        // Along the axes (the scenes' boxes): counted with the spheres, as a finite obstacle.
        const V q = (p - obstacle.position).cwiseAbs() - 0.5 * obstacle.size;
        const double outside = q.cwiseMax(0.0).norm(), inside = std::min(0.0, q.maxCoeff());
        deepest.spheres = std::max(deepest.spheres, r - outside - inside);
      } else {
        deepest.spheres =
            std::max(deepest.spheres, r + obstacle.radius - (p - obstacle.position).norm());
      }
    }
    // Every pair (a pile of 1,000 at 300 instants: 1.5e8 distances, a fraction of a second).
    for (std::size_t j = i + 1; j < run.bodies; ++j) {
      const double reach = r + scene.bodies[j].radius;
      const V s = run.position(sample, j) - p;
      if (s.squaredNorm() < reach * reach) {
        deepest.bodies = std::max(deepest.bodies, reach - s.norm());
      }
    }
  }
  return deepest;
}

/// The deepest penetration over every sampled instant.
Penetration deepestPenetration(const core::Scene& scene, const Run& run) {
  Penetration deepest;
  for (std::size_t k = 0; k < run.samples(); ++k) {
    const Penetration now = penetrationAt(scene, run, k);
    deepest.planes = std::max(deepest.planes, now.planes);
    deepest.spheres = std::max(deepest.spheres, now.spheres);
    deepest.bodies = std::max(deepest.bodies, now.bodies);
  }
  return deepest;
}

/// J: how far the energy (kinetic of the centres, plus potential) rose above the start at any
/// sampled instant (0: it never did). Spin's energy is not in the states: with spin this can
/// only miss a gain, not invent one.
double energyGain(const core::Scene& scene, const Run& run) {
  const double e0 = energy(scene, run, 0);
  double gain = 0;
  for (std::size_t k = 1; k < run.samples(); ++k) gain = std::max(gain, energy(scene, run, k) - e0);
  return gain;
}

/// J: the largest rise of the energy (kinetic of the centres, plus potential) from one sampled
/// instant to the next (0: it never rose). A settling pile that still moves at its end but never
/// gains energy is rearranging, not being pumped.
double energyStepRise(const core::Scene& scene, const Run& run) {
  double rise = 0, before = energy(scene, run, 0);
  for (std::size_t k = 1; k < run.samples(); ++k) {
    const double now = energy(scene, run, k);
    rise = std::max(rise, now - before);
    before = now;
  }
  return rise;
}

double kineticEnergy(const core::Scene& scene, const Run& run, std::size_t sample) {
  double total = 0;
  for (std::size_t i = 0; i < run.bodies; ++i) {
    total += 0.5 * scene.bodies[i].mass * run.velocity(sample, i).squaredNorm();
  }
  return total;
}

/// The reference's resting centre of each body (rows "rest BODY x y z").
std::vector<V> restingCentres(const References& refs, const std::string& name) {
  std::vector<V> centres;
  for (const std::vector<double>& row : refs.rows(name, "rest")) centres.push_back(row3(row, 1));
  return centres;
}

// A ball into a corner: penetration into either plane, the final position against the corner's,
// the energy's rise above the start (relative to what the fall releases), the final speed.
Metrics ballCorner(const std::string& name, const core::Scene& scene, const Run& run,
                   const References& refs) {
  const std::size_t last = run.samples() - 1;
  const V rest = restingCentres(refs, name).front();
  const double released = refs.value(name, "energy0") - refs.value(name, "energy_rest");
  return {{"penetration", deepestPenetration(scene, run).any()},
          {"rest_error", (run.position(last, 0) - rest).norm()},
          {"energy_gain", energyGain(scene, run) / released},
          {"final_speed", run.velocity(last, 0).norm()}};
}

/// Where a ball in free flight at sample `k` last touched the sphere `dome`: its ballistic path
/// traced back to the instant it was at the contact distance (exact for any state on the
/// flight, as the apexes are); the cosine of that point's angle from the top. A ball that left
/// with no normal force leaves on a parabola that osculates the sphere (the distance grows as
/// the cube of the time): there the crossing is ill-conditioned (~1e-6 s from the rounding of
/// the distance), and the instant is taken instead from the simple root of the distance's
/// second derivative, when that root lies on the contact distance (within 1 um). NaN: no
/// crossing within 3 s back.
double leavingCosine(const core::Scene& scene, const Run& run, std::size_t k,
                     const core::ObstacleSpec& dome) {
  const V g = scene.gravity, p = run.position(k, 0), v = run.velocity(k, 0);
  const double reach = dome.radius + scene.bodies.front().radius;
  const auto at = [&](double tau) { return V(p + v * tau + 0.5 * g * tau * tau - dome.position); };
  const auto outside = [&](double tau) { return at(tau).norm() - reach; };
  // d^2/dtau^2 |s| = (|s'|^2 + s.s'' - (s.s'/|s|)^2) / |s|, s'' = g.
  const auto curving = [&](double tau) {
    const V s = at(tau), rate = v + g * tau;
    const double radial = s.dot(rate) / s.norm();
    return (rate.squaredNorm() + s.dot(g) - radial * radial) / s.norm();
  };
  const auto bisect = [](const auto& f, double inside, double outside_end) {
    const bool inside_sign = f(inside) <= 0;
    for (int i = 0; i < 200; ++i) {
      const double middle = 0.5 * (inside + outside_end);
      ((f(middle) <= 0) == inside_sign ? inside : outside_end) = middle;
    }
    return 0.5 * (inside + outside_end);
  };
  double late = 0, early = kNaN;
  for (double tau = -1e-4; tau >= -3.0; tau -= 1e-4) {
    if (outside(tau) <= 0) {
      early = tau;
      break;
    }
    late = tau;
  }
  if (std::isnan(early)) return kNaN;
  double leaving = bisect(outside, early, late);
  const double window = 0.02;  // s either side of the crossing
  const double before = leaving - window, after = std::min(leaving + window, 0.0);
  if ((curving(before) <= 0) != (curving(after) <= 0)) {
    const double osculating = bisect(curving, before, after);
    if (std::abs(outside(osculating)) < 1e-6) leaving = osculating;
  }
  const V contact = at(leaving);
  return -g.normalized().dot(contact) / contact.norm();
}

// A ball off a fixed sphere: the angle at which it left (from its first state in flight after
// its last state on the sphere, traced back; an early hop does not count), penetration into the
// sphere and into the floor.
Metrics ballOffSphere(const std::string& name, const core::Scene& scene, const Run& run,
                      const References& refs) {
  const core::ObstacleSpec& dome = scene.obstacles.at(0);
  const double reach = dome.radius + scene.bodies.front().radius;
  // On the sphere: within 10 um of it (the peers' contacts settle within a micrometre).
  std::size_t last_on = 0;
  for (std::size_t k = 0; k < run.samples(); ++k) {
    if ((run.position(k, 0) - dome.position).norm() - reach <= 1e-5) last_on = k;
  }
  const double leaving =
      last_on + 1 < run.samples()
          ? std::acos(std::clamp(leavingCosine(scene, run, last_on + 1, dome), -1.0, 1.0))
          : kNaN;
  const Penetration deepest = deepestPenetration(scene, run);
  return {{"leave_angle", std::abs(leaving - std::acos(refs.value(name, "leave_cos")))},
          {"penetration_sphere", deepest.spheres},
          {"penetration_floor", deepest.planes},
          {"energy_gain", energyGain(scene, run)}};
}

// A ball sliding off a box's edge: its horizontal velocity in flight at the last state, against
// sqrt(g r) cos^(3/2) theta (the leaving angle's closed form); penetration into the box.
Metrics ballOffEdge(const std::string& name, const core::Scene& scene, const Run& run,
                    const References& refs) {
  const double vx = run.samples() > 0 ? run.velocity(run.samples() - 1, 0).x() : kNaN;
  return {{"flight_vx", std::abs(vx - refs.value(name, "flight_vx"))},
          {"penetration_box", deepestPenetration(scene, run).spheres},
          {"energy_gain", energyGain(scene, run)}};
}

// A ball sliding across a tessellated floor: how far its centre left z = r (a ghost bounce lifts
// it, sinking takes it in) and its velocity at the end against the start's, at any state.
Metrics ballOnMeshFloor(const std::string& name, const Run& run, const References& refs) {
  const auto& start = refs.rows(name, "velocity").front();
  const V velocity(start.at(0), start.at(1), start.at(2));
  const double height = refs.value(name, "height");
  double off = 0, sink = 0;
  for (std::size_t k = 0; k < run.samples(); ++k) {
    const double z = run.position(k, 0).z();
    off = std::max(off, std::abs(z - height));
    sink = std::max(sink, height - z);
  }
  const double speed =
      run.samples() > 0 ? (run.velocity(run.samples() - 1, 0) - velocity).norm() : kNaN;
  return {
      {"height_off", off}, {"penetration_floor", std::max(0.0, sink)}, {"velocity_error", speed}};
}

// A ball off a moving paddle: its velocity at the last state against v_p + e (v_p - v); how far
// it went into the paddle (the box at its start plus v t) at any state.
Metrics ballOffMovingPaddle(const BenchScene& bench, const std::string& name,
                            const core::Scene& scene, const Run& run, const References& refs) {
  const core::ObstacleSpec& paddle = scene.obstacles.at(0);
  const V& v = bench.obstacle_velocities.at(0);
  const double r = scene.bodies.front().radius;
  double deepest = 0;
  for (std::size_t k = 0; k < run.samples(); ++k) {
    const V q =
        (run.position(k, 0) - paddle.position - run.times[k] * v).cwiseAbs() - 0.5 * paddle.size;
    const double outside = q.cwiseMax(0.0).norm(), inside = std::min(0.0, q.maxCoeff());
    deepest = std::max(deepest, r - outside - inside);
  }
  const double vx = run.samples() > 0 ? run.velocity(run.samples() - 1, 0).x() : kNaN;
  return {{"velocity_after", std::abs(vx - refs.value(name, "velocity_after"))},
          {"penetration_paddle", deepest}};
}

// A stack at rest: the largest distance of any centre from its resting place at any sampled
// instant, penetration, the energy's rise.
Metrics ballStack(const std::string& name, const core::Scene& scene, const Run& run,
                  const References& refs) {
  const std::vector<V> rest = restingCentres(refs, name);
  double drift = 0;
  for (std::size_t k = 0; k < run.samples(); ++k) {
    for (std::size_t i = 0; i < run.bodies; ++i) {
      drift = std::max(drift, (run.position(k, i) - rest.at(i)).norm());
    }
  }
  return {{"drift", drift},
          {"penetration", deepestPenetration(scene, run).any()},
          {"energy_gain", energyGain(scene, run)}};
}

// A pile settling: penetration (the deepest overlap of any pair or wall at any sampled instant),
// the kinetic energy at the end (rest: 0) and the energy's rise.
Metrics ballPile(const core::Scene& scene, const Run& run) {
  const Penetration deepest = deepestPenetration(scene, run);
  double fastest = 0;
  for (std::size_t i = 0; i < run.bodies; ++i) {
    fastest = std::max(fastest, run.velocity(run.samples() - 1, i).norm());
  }
  return {{"penetration", deepest.any()},
          {"penetration_pairs", deepest.bodies},
          {"penetration_walls", deepest.planes},
          {"kinetic_end", kineticEnergy(scene, run, run.samples() - 1)},
          {"final_speed", fastest},
          {"energy_gain", energyGain(scene, run)},
          {"energy_step_rise", energyStepRise(scene, run)},
          {"stepped_bodies", run.stepped_bodies}};
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
  if (bench.name == "ball_corner") return ballCorner(name, scene, run, references);
  if (bench.name == "ball_off_sphere") return ballOffSphere(name, scene, run, references);
  if (bench.name == "ball_off_edge") return ballOffEdge(name, scene, run, references);
  if (bench.name == "ball_on_mesh_floor") return ballOnMeshFloor(name, run, references);
  if (bench.name == "ball_off_moving_paddle") {
    return ballOffMovingPaddle(bench, name, scene, run, references);
  }
  if (bench.name == "ball_stack") return ballStack(name, scene, run, references);
  if (bench.name.rfind("ball_pile", 0) == 0) return ballPile(scene, run);
  if (bench.name.rfind("bounce_", 0) == 0) return bounces(name, scene, run, references);
  if (bench.name.rfind("chain_", 0) == 0) return chain(name, scene, run, references);
  if (bench.reference == "conservation") return conservation(name, scene, run, references);
  if (bench.name == "cradle") return cradle(name, scene, run, references);
  throw std::runtime_error("no metrics for scene " + bench.name + " (measure.cpp)");
}

}  // namespace collision_response::bench
