// Lasting contact that curves (a ball on a sphere, on another ball whose line of centres turns)
// has no closed form: its motion is integrated, one error-controlled step at a time, with the
// contacts' modes held over the step and the instant a mode stops holding found by bisection.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <memory>
#include <vector>

#include "collision_response/core/shape.h"
#include "geometry/integrated_motion.h"
#include "geometry/narrow_phase.h"
#include "solver/contact_forces.h"

namespace collision_response::core::monitor {

/// A contact of a group being integrated: between participants a and b (indices into the
/// step's participants); against a plane b, the plane's outward normal (the contact's normal is
/// its opposite), otherwise two spheres whose line of centres is the normal.
struct ConstrainedContact {
  std::size_t a = 0;
  std::size_t b = 0;
  bool plane = false;
  Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitZ();
  /// Against a finite shape (a box, cylinder or capsule; b): the shape where it is placed, moving
  /// straight on; the normal is to its nearest feature (narrow_phase.h), whichever that is as
  /// the ball moves from a face over an edge.
  std::shared_ptr<const PlacedShape> shape;
  double friction = 0.0;
  ContactMode mode = ContactMode::kSticking;  ///< held over the step
  /// Sliding: the direction of the slip it starts with (ContactForce::slide_direction).
  Eigen::Vector3d slide_direction = Eigen::Vector3d::Zero();
};

/// The narrow phase's geometry of a contact (narrow_phase.h) into the force solver's: its
/// normal, point, lever arms and how its normal turns (curvature, turning axis, axial share).
/// The bodies, friction and slide direction are the caller's.
inline void setContactGeometry(const ContactGeometry& g, ForceContact& contact) {
  contact.normal = g.normal;
  contact.point = g.point;
  contact.lever_a = g.lever_a;
  contact.lever_b = g.lever_b;
  contact.curvature = g.curvature;
  contact.turning_axis = g.turning_axis;
  contact.axial_share = g.axial_share;
}

/// One step of a group's motion: from `start` to `until`, as Dormand-Prince 5(4) with error
/// control (Boost.Odeint) gives it, or to the first instant within it where a mode stops
/// holding (a pressed contact would pull, a sticking one needs more than mu N, a sliding one's
/// slip stops), found by bisection on the step's dense output. The state of every movable
/// participant (position, velocity, angular velocity) is known at any instant of the step.
///
/// Integrated as far as it is looked at: at first a 4096th of the way to `until`; a query past
/// end() integrates on to it, and extend() reaches three times as far from the start. The steps
/// are those one integration to `until` would take (the same calls of the same stepper), so the
/// motion does not depend on how it was asked for; only the work does. An impact on one of its
/// bodies replaces the step long before `until` (a settling pile: about 100 instants an update),
/// and what was integrated past it was lost.
class ConstrainedStep final : public IntegratedMotion {
 public:
  /// `bodies` at `start` (the movable ones first, `movable` of them; the others move at constant
  /// velocity), their `positions` then; the motion is integrated from `start` to `until` (or
  /// the first mode change). `tolerance`: the integrator's error per step, absolute (m, m/s,
  /// rad/s) and relative; `slip_tolerance`: slower slips are none (m/s, as the force solver's);
  /// `step`: the size to try first.
  ConstrainedStep(const std::vector<ForceBody>& bodies,
                  const std::vector<Eigen::Vector3d>& positions, std::size_t movable,
                  const std::vector<ConstrainedContact>& contacts, double start, double until,
                  double tolerance, double slip_tolerance, double step);
  ~ConstrainedStep() override;

  double start() const { return start_; }
  /// How far it is integrated: where its mode changed, `until`, or (not complete()) the
  /// frontier so far, past which it is integrated on demand.
  double end() const override { return end_; }
  /// The motion ended before `until`: where a mode stopped holding, or after the most steps one
  /// motion takes (the group must be solved again there).
  bool modeChanged() const { return mode_changed_; }
  /// Integrated to its end: `until`, or where its mode changed.
  bool complete() const { return mode_changed_ || !(end_ < until_); }
  /// Integrates on to three times as far from the start as end() (at most to `until`).
  void extend() const { advanceTo(end_ + 2 * (end_ - start_)); }
  /// The size the integrator would take next.
  double nextStep() const { return next_step_; }
  /// How many times its contact forces were solved so far (each stage of each step, each
  /// margin and bisection): the work it cost.
  std::size_t solves() const { return solves_; }

  Eigen::Vector3d position(std::size_t body, double time) const override;
  Eigen::Vector3d velocity(std::size_t body, double time) const override;
  Eigen::Vector3d angularVelocity(std::size_t body, double time) const override;
  /// Gravity and the step's initial acceleration, each twice: the contact forces change over the
  /// step, by less than they are.
  double accelerationBound(std::size_t body, double gravity, double, double) const override {
    return 2 * (gravity + initial_acceleration_[body].norm());
  }
  /// The acceleration at the step's start (for bounds).
  const Eigen::Vector3d& initialAcceleration(std::size_t body) const {
    return initial_acceleration_[body];
  }

 private:
  using State = std::vector<double>;
  struct Integration;  // Boost.Odeint's dense-output stepper, kept out of this header

  /// Integrates on until end() >= `time`, the motion's end, or its mode changes.
  void advanceTo(double time) const;
  void derivative(const State& state, State& rate, double time) const;
  ContactForceSolution forces(const State& state, double time) const;
  /// The least margin of the modes at a state: < 0 where one stops holding.
  double margin(const State& state, double time) const;
  State stateAt(double time) const;
  /// stateAt for the public queries, which come a body and a quantity at a time (a pair's
  /// positions, then its velocities) at one instant: the last instant's state is kept.
  const State& queriedStateAt(double time) const;
  const Integration& stepAt(double time) const;

  std::vector<ForceBody> bodies_;
  std::vector<Eigen::Vector3d> positions_;  // at start_
  std::size_t movable_;
  std::vector<ConstrainedContact> contacts_;
  std::vector<Eigen::Vector3d> slip_direction_;  // sliding contacts: the slip's at the start
  std::vector<Eigen::Vector3d> initial_acceleration_;
  double start_, until_;
  // Integrated on demand (advanceTo) from queries on a const step: mutable.
  mutable double end_;
  mutable double next_step_ = 0.0;
  mutable bool mode_changed_ = false;
  mutable int taken_ = 0;                             // steps taken
  mutable std::unique_ptr<Integration> integration_;  // the stepper, where it has got to
  double force_scale_ = 0.0;
  ContactForceSettings settings_;
  mutable std::vector<std::unique_ptr<Integration>> steps_;  // each step's dense output, in order
  mutable double queried_time_ = NAN;                        // queriedStateAt's last instant
  mutable State queried_state_;
  mutable std::size_t solves_ = 0;
};

}  // namespace collision_response::core::monitor
