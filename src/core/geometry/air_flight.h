// Flight through air (the drag and magnus effects): gravity, quadratic drag and the Magnus force
// have no closed form together, so the flight is integrated (Dormand-Prince 5(4) with error
// control and dense output, Boost.Odeint) as far as it is asked for.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <vector>

#include "collision_response/core/scene.h"
#include "geometry/integrated_motion.h"

namespace collision_response::core {

/// What the air does to one body, per unit mass: drag = rho C_d A / (2 m) and lift =
/// rho C_L A / (2 m) (1/m), A = pi r^2 its cross-section; 0 where the effect is off.
struct AirFactors {
  double drag = 0.0;
  double lift = 0.0;
};

/// The factors of a sphere of `radius` and inverse mass `inverse_mass` in air of `density`.
AirFactors airFactors(double density, double radius, double inverse_mass, double drag_coefficient,
                      double lift_coefficient);
/// The factors of a body of cross-section `section` (m^2) and inverse mass `inverse_mass`: the same
/// rho C A / (2 m) with A given (a shaped body's mean cross-section, meanCrossSection).
AirFactors airFactorsOfSection(double density, double section, double inverse_mass,
                               double drag_coefficient, double lift_coefficient);

/// The factors of a scene's body in air of `density`, drag's where `drag`, lift's where `magnus`
/// (0 otherwise): a ball's by its radius (airFactors), a shaped body's (a box, cylinder, capsule,
/// mesh, or a sphere given a tensor) by its mean cross-section (meanCrossSection: the drag of a
/// body tumbling through every orientation alike).
AirFactors bodyAirFactors(const BodySpec& body, double density, bool drag, bool magnus);

/// The acceleration of a body moving at `velocity` and spinning at `angular_velocity` in air:
/// g - drag |v| v + lift |v| (w/|w| x v). Quadratic drag, F = -1/2 rho C_d A |v| v, and the
/// Magnus force F = 1/2 rho C_L A |v|^2 along w/|w| x v/|v| (A. M. Nathan, "The effect of spin
/// on the flight of a baseball", Am. J. Phys. 76, 119 (2008)), C_d and C_L taken
/// as constants. No spin, or no speed: no Magnus force.
Eigen::Vector3d airAcceleration(const Eigen::Vector3d& gravity, const AirFactors& air,
                                const Eigen::Vector3d& velocity,
                                const Eigen::Vector3d& angular_velocity);

/// One body's flight from its state at `start`: its centre and velocity integrated, its spin
/// constant (no torque of the air), or, for a body whose turning is its own torque-free
/// rotation (a tumbling shaped body), the angular velocity `spin_at(t)` that rotation gives.
/// Integrated on demand, as far as it is looked at; a query between the steps taken reads the
/// stepper's dense output (its 4th-order interpolant, to the step's error). The steps are those one
/// integration would take, however it is asked.
class AirFlight final : public IntegratedMotion {
 public:
  AirFlight(double start, const Eigen::Vector3d& position, const Eigen::Vector3d& velocity,
            const Eigen::Vector3d& angular_velocity, const Eigen::Vector3d& gravity,
            const AirFactors& air, double tolerance);
  AirFlight(double start, const Eigen::Vector3d& position, const Eigen::Vector3d& velocity,
            std::function<Eigen::Vector3d(double)> spin_at, const Eigen::Vector3d& gravity,
            const AirFactors& air, double tolerance);
  ~AirFlight() override;

  Eigen::Vector3d position(std::size_t slot, double time) const override;
  Eigen::Vector3d velocity(std::size_t slot, double time) const override;
  /// Its spin at `time`: constant, or the torque-free rotation's `spin_at(time)`.
  Eigen::Vector3d angularVelocity(std::size_t, double time) const override;
  double end() const override;
  /// Drag and Magnus grow with the speed squared; the speed is bounded by its start and the
  /// terminal speed sqrt(|g| / drag) (drag never lets it grow past both; Magnus does no work), or
  /// without drag by its start plus |g| (to - from).
  double accelerationBound(std::size_t slot, double gravity, double from, double to) const override;
  /// m/s^2: the air's part of that bound (drag's and lift's), |g| aside.
  double airAccelerationBound(double gravity, double from, double to) const;
  bool free() const override { return true; }
  /// Where the integrator could not go on (a step it could not take, a state past the doubles,
  /// or kMaxSteps taken), the flight holds its last state reached from then on.
  double stalledAt() const override;
  /// The integrator's steps taken so far (the work it cost).
  std::size_t steps() const;

 private:
  struct Integration;
  /// The state (position, velocity) at `time`, integrating on as far as needed.
  const Eigen::Matrix<double, 6, 1>& stateAt(double time) const;

  double start_;
  Eigen::Vector3d spin_;
  std::unique_ptr<Integration> integration_;
};

}  // namespace collision_response::core
