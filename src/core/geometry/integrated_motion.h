// A body's motion where it has no closed form and is integrated: curved lasting contact
// (ConstrainedStep) and flight through air (AirFlight). The monitor's tracks follow one when
// they have it, a parabola otherwise (motion_model.h).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <limits>

namespace collision_response::core {

class IntegratedMotion {
 public:
  IntegratedMotion() = default;
  IntegratedMotion(const IntegratedMotion&) = delete;
  IntegratedMotion& operator=(const IntegratedMotion&) = delete;
  virtual ~IntegratedMotion() = default;

  /// Body `slot`'s state at `time`, an instant from the motion's start to end().
  virtual Eigen::Vector3d position(std::size_t slot, double time) const = 0;
  virtual Eigen::Vector3d velocity(std::size_t slot, double time) const = 0;
  virtual Eigen::Vector3d angularVelocity(std::size_t slot, double time) const = 0;
  /// The last instant the motion holds to (infinity: integrated as far as it is asked).
  virtual double end() const = 0;
  /// A bound on body `slot`'s acceleration over [from, to] (`gravity`: |g|).
  virtual double accelerationBound(std::size_t slot, double gravity, double from,
                                   double to) const = 0;
  /// A flight (no lasting contact): the body is free until it meets something.
  virtual bool free() const { return false; }
  /// The instant from which the motion could not be integrated further and holds its last state
  /// (a flight through air that stalled), as far as it has been asked; infinity: none.
  virtual double stalledAt() const { return std::numeric_limits<double>::infinity(); }
};

}  // namespace collision_response::core
