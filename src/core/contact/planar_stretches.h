// A planar motion on a face's edge (shaped_edge_tip.h: a body's face turning over it;
// shaped_edge_roll.h: a side rolling over it): a state of two coordinates and their rates,
// integrated stretch by stretch, each stretch one grip of the edge (holding, or sliding one way),
// by the Dormand-Prince 5(4) pair with dense output (Boost.Odeint), its events found on the dense
// output by bisection.
#pragma once

#include <algorithm>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <cstddef>
#include <exception>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/validation.h"

namespace collision_response::core::planar {

using State = std::array<double, 4>;  // two coordinates, then their rates
using Stepper = boost::numeric::odeint::runge_kutta_dopri5<State>;
using Dense = boost::numeric::odeint::result_of::make_dense_output<Stepper>::type;

/// Steps one motion may take before it is asked again from where it is ("stops").
constexpr std::size_t kMaxSteps = 1u << 14;
/// Bisection of an event on the dense output: to this part of the instant (or of 1 s).
constexpr double kEventResolution = 1e-13;

/// How the edge holds the body's point on it: still (sticking, or rolling), or sliding (the
/// friction against the slip's sign sigma).
enum class Grip { kSliding, kHolding };

/// One integrated stretch in one grip, up to `to`.
struct Stretch {
  Dense dense;
  double to = 0.0;
  Grip grip = Grip::kSliding;
  double sigma = 1.0;
};

/// The motion's stretches from its start.
struct Stretches {
  double start = 0.0;
  State initial{};
  Grip initial_grip = Grip::kSliding;
  double initial_sigma = 1.0;
  std::vector<Stretch> list;

  /// The state, grip and slip's sign at `time` (at or after the start, within what was
  /// integrated: the stretch covering it, or the last one's end).
  std::tuple<State, Grip, double> at(double time) const {
    if (list.empty() || !(time > start)) return {initial, initial_grip, initial_sigma};
    const auto covering =
        std::lower_bound(list.begin(), list.end(), time,
                         [](const Stretch& stretch, double t) { return stretch.to < t; });
    const Stretch& stretch = covering == list.end() ? list.back() : *covering;
    State y;
    stretch.dense.calc_state(std::clamp(time, stretch.dense.previous_time(), stretch.to), y);
    return {y, stretch.grip, stretch.sigma};
  }
};

/// Integrates one grip from `y` at `t` to its first event (its instant and index among the
/// `events`; `y` the state there, `t` its instant), or to `until` or the step budget (`taken`)
/// with none, each step kept in `path`. `rate(x)` is the state's derivative in this grip,
/// `value(x, e)` event e's function, > 0 while the grip lasts. `motion` names the motion in the
/// error where the integrator fails ("the tipping over the face's edge").
template <class Rate, class Value>
Expected<std::optional<std::pair<double, std::size_t>>> integrateGrip(
    Stretches& path, State& y, double& t, double until, Grip grip, double sigma, double tolerance,
    std::size_t& taken, std::size_t events, const Rate& rate, const Value& value,
    const std::string& motion) {
  const auto system = [&rate](const State& x, State& derivative, double) { derivative = rate(x); };
  Dense dense = boost::numeric::odeint::make_dense_output(tolerance, tolerance, Stepper());
  dense.initialize(y, t, 1e-4);
  std::optional<std::pair<double, std::size_t>> event;
  while (++taken <= kMaxSteps) {
    try {
      dense.do_step(system);
    } catch (const std::exception&) {
      return Error{"contact", motion + " could not be integrated past +" +
                                  formatNumber(t - path.start) + " s"};
    }
    const double t0 = dense.previous_time(), t1 = std::min(dense.current_time(), until);
    const auto at = [&](double time, std::size_t e) {
      State x;
      dense.calc_state(time, x);
      return value(x, e);
    };
    for (std::size_t e = 0; e < events; ++e) {
      if (at(t1, e) > 0) continue;
      double lo = t0, hi = at(t0, e) <= 0 ? t0 : t1;
      while (hi - lo > kEventResolution * std::max(1.0, std::abs(hi))) {
        const double mid = 0.5 * (lo + hi);
        (at(mid, e) > 0 ? lo : hi) = mid;
      }
      if (!event || hi < event->first) event = std::make_pair(hi, e);
    }
    path.list.push_back({dense, event ? event->first : t1, grip, sigma});
    t = path.list.back().to;
    if (event || t >= until) break;
  }
  dense.calc_state(t, y);
  return event;
}

}  // namespace collision_response::core::planar
