#include "geometry/air_flight.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <exception>
#include <limits>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/mass_properties.h"

namespace collision_response::core {
namespace {

using State = std::array<double, 6>;  // position, velocity
using Stepper = boost::numeric::odeint::runge_kutta_dopri5<State>;
using Dense = boost::numeric::odeint::result_of::make_dense_output<Stepper>::type;
using Vector6 = Eigen::Matrix<double, 6, 1>;

constexpr double kPi = 3.14159265358979323846;
/// The steps one flight may take (each kept, about 1 kB): far more than a flight between two
/// updates or within a prediction's 60 s horizon takes (a 1 s serve takes 30 steps at
/// tolerance 1e-9, 107 at 1e-12); past it the flight holds its last state rather than
/// integrating without end.
constexpr std::size_t kMaxSteps = 1u << 14;

}  // namespace

AirFactors airFactors(double density, double radius, double inverse_mass, double drag_coefficient,
                      double lift_coefficient) {
  const double per_coefficient = 0.5 * density * kPi * radius * radius * inverse_mass;
  return AirFactors{per_coefficient * drag_coefficient, per_coefficient * lift_coefficient};
}

AirFactors airFactorsOfSection(double density, double section, double inverse_mass,
                               double drag_coefficient, double lift_coefficient) {
  const double per_coefficient = 0.5 * density * section * inverse_mass;
  return AirFactors{per_coefficient * drag_coefficient, per_coefficient * lift_coefficient};
}

AirFactors bodyAirFactors(const BodySpec& body, double density, bool drag, bool magnus) {
  const double drag_coefficient = drag ? body.drag_coefficient : 0.0;
  const double lift_coefficient = magnus ? body.lift_coefficient : 0.0;
  if (!isShapedBody(body)) {
    return airFactors(density, body.radius, inverseMass(body.mass), drag_coefficient,
                      lift_coefficient);
  }
  return airFactorsOfSection(density, meanCrossSection(shapeOf(body)), inverseMass(body.mass),
                             drag_coefficient, lift_coefficient);
}

Eigen::Vector3d airAcceleration(const Eigen::Vector3d& gravity, const AirFactors& air,
                                const Eigen::Vector3d& velocity,
                                const Eigen::Vector3d& angular_velocity) {
  const double speed = velocity.norm();
  Eigen::Vector3d acceleration = gravity - (air.drag * speed) * velocity;
  if (air.lift != 0.0) {
    const double spin = angular_velocity.norm();
    if (spin > 0.0) acceleration += (air.lift * speed / spin) * angular_velocity.cross(velocity);
  }
  return acceleration;
}

struct AirFlight::Integration {
  Eigen::Vector3d gravity;
  AirFactors air;
  Eigen::Vector3d spin;
  std::function<Eigen::Vector3d(double)> spin_at;  ///< empty: `spin` throughout
  Dense dense;
  /// The stepper after each step taken: its dense output covers that step.
  std::vector<Dense> steps;
  Vector6 initial;
  double queried_time = std::numeric_limits<double>::quiet_NaN();
  bool stalled = false;  ///< no further step: the last one reached is held
  Vector6 queried = Vector6::Zero();

  Integration(double tolerance)
      : dense(boost::numeric::odeint::make_dense_output(tolerance, tolerance, Stepper())) {}

  void derivative(const State& x, State& rate, double time) const {
    const Eigen::Vector3d velocity(x[3], x[4], x[5]);
    const Eigen::Vector3d acceleration =
        airAcceleration(gravity, air, velocity, spin_at ? spin_at(time) : spin);
    for (int i = 0; i < 3; ++i) {
      rate[static_cast<std::size_t>(i)] = x[static_cast<std::size_t>(i) + 3];
      rate[static_cast<std::size_t>(i) + 3] = acceleration[i];
    }
  }
};

AirFlight::AirFlight(double start, const Eigen::Vector3d& position, const Eigen::Vector3d& velocity,
                     const Eigen::Vector3d& angular_velocity, const Eigen::Vector3d& gravity,
                     const AirFactors& air, double tolerance)
    : start_(start),
      spin_(angular_velocity),
      integration_(std::make_unique<Integration>(tolerance)) {
  Integration& integration = *integration_;
  integration.gravity = gravity;
  integration.air = air;
  integration.spin = angular_velocity;
  integration.initial << position, velocity;
  State initial;
  for (std::size_t i = 0; i < 6; ++i)
    initial[i] = integration.initial[static_cast<Eigen::Index>(i)];
  // A first step of a millisecond: the error control shortens it where the air bends the path
  // faster.
  integration.dense.initialize(initial, start, 1e-3);
}

AirFlight::AirFlight(double start, const Eigen::Vector3d& position, const Eigen::Vector3d& velocity,
                     std::function<Eigen::Vector3d(double)> spin_at, const Eigen::Vector3d& gravity,
                     const AirFactors& air, double tolerance)
    : AirFlight(start, position, velocity, spin_at(start), gravity, air, tolerance) {
  integration_->spin_at = std::move(spin_at);
}

AirFlight::~AirFlight() = default;

Eigen::Vector3d AirFlight::angularVelocity(std::size_t, double time) const {
  return integration_->spin_at ? integration_->spin_at(time) : spin_;
}

const Vector6& AirFlight::stateAt(double time) const {
  Integration& integration = *integration_;
  if (!(time > start_)) return integration.initial;
  if (time == integration.queried_time) return integration.queried;
  const auto system = [&integration](const State& x, State& rate, double t) {
    integration.derivative(x, rate, t);
  };
  while (!integration.stalled &&
         (integration.steps.empty() || integration.steps.back().current_time() < time)) {
    // Past the steps a flight may take, or where the integrator fails (a speed so large that
    // drag's acceleration overflows, the error control shrinking the step for ever), the flight
    // stalls: it holds its last finite state (doc/model.md, "Effects in detail").
    if (integration.steps.size() >= kMaxSteps) {
      integration.stalled = true;
      break;
    }
    try {
      integration.dense.do_step(system);
    } catch (const std::exception&) {
      integration.stalled = true;
      break;
    }
    const State& reached = integration.dense.current_state();
    if (!std::all_of(reached.begin(), reached.end(), [](double x) { return std::isfinite(x); })) {
      integration.stalled = true;
      break;
    }
    integration.steps.push_back(integration.dense);
  }
  if (integration.steps.empty()) return integration.initial;
  const auto covering =
      std::lower_bound(integration.steps.begin(), integration.steps.end(), time,
                       [](const Dense& step, double t) { return step.current_time() < t; });
  const Dense& step = covering == integration.steps.end() ? integration.steps.back() : *covering;
  State x;
  step.calc_state(std::clamp(time, step.previous_time(), step.current_time()), x);
  for (std::size_t i = 0; i < 6; ++i) integration.queried[static_cast<Eigen::Index>(i)] = x[i];
  integration.queried_time = time;
  return integration.queried;
}

Eigen::Vector3d AirFlight::position(std::size_t, double time) const {
  return stateAt(time).head<3>();
}

Eigen::Vector3d AirFlight::velocity(std::size_t, double time) const {
  return stateAt(time).tail<3>();
}

double AirFlight::end() const { return std::numeric_limits<double>::infinity(); }

double AirFlight::accelerationBound(std::size_t, double gravity, double from, double to) const {
  return gravity + airAccelerationBound(gravity, from, to);
}

double AirFlight::airAccelerationBound(double gravity, double from, double to) const {
  const AirFactors& air = integration_->air;
  const double speed = velocity(0, from).norm();
  const double fastest =
      air.drag > 0 ? std::max(speed, std::sqrt(gravity / air.drag)) : speed + gravity * (to - from);
  // 1 % over: the integrated speed is the true one only to the integrator's tolerance.
  const double bound = 1.01 * fastest;
  return (air.drag + air.lift) * bound * bound;
}

std::size_t AirFlight::steps() const { return integration_->steps.size(); }

double AirFlight::stalledAt() const {
  const Integration& integration = *integration_;
  if (!integration.stalled) return std::numeric_limits<double>::infinity();
  return integration.steps.empty() ? start_ : integration.steps.back().current_time();
}

}  // namespace collision_response::core
