#include "model/constrained_motion.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <boost/numeric/odeint.hpp>
#include <cmath>

namespace collision_response::core::monitor {
namespace {

constexpr std::size_t kPerBody = 9;  // position, velocity, angular velocity

Eigen::Vector3d slice(const std::vector<double>& state, std::size_t body, std::size_t part) {
  const std::size_t at = kPerBody * body + 3 * part;
  return Eigen::Vector3d(state[at], state[at + 1], state[at + 2]);
}

void put(std::vector<double>& state, std::size_t body, std::size_t part,
         const Eigen::Vector3d& value) {
  const std::size_t at = kPerBody * body + 3 * part;
  for (int c = 0; c < 3; ++c) state[at + c] = value[c];
}

}  // namespace

struct ConstrainedStep::Integration {
  using Stepper = boost::numeric::odeint::runge_kutta_dopri5<State>;
  using Dense = boost::numeric::odeint::result_of::make_dense_output<Stepper>::type;
  explicit Integration(double tolerance)
      : dense(boost::numeric::odeint::make_dense_output(tolerance, tolerance, Stepper())) {}
  Integration(const Integration&) = default;
  Dense dense;
};

ConstrainedStep::~ConstrainedStep() = default;

ConstrainedStep::ConstrainedStep(const std::vector<ForceBody>& bodies,
                                 const std::vector<Eigen::Vector3d>& positions, std::size_t movable,
                                 const std::vector<ConstrainedContact>& contacts, double start,
                                 double until, double tolerance, double slip_tolerance, double step)
    : bodies_(bodies),
      positions_(positions),
      movable_(movable),
      contacts_(contacts),
      start_(start),
      until_(until),
      end_(start) {
  settings_.slip_tolerance = slip_tolerance;
  State initial(kPerBody * movable_);
  for (std::size_t i = 0; i < movable_; ++i) {
    put(initial, i, 0, positions_[i]);
    put(initial, i, 1, bodies_[i].velocity);
    put(initial, i, 2, bodies_[i].angular_velocity);
  }
  const ContactForceSolution at_start = forces(initial, start_);
  for (std::size_t k = 0; k < contacts_.size(); ++k) {
    force_scale_ = std::max(force_scale_, std::abs(at_start.contacts[k].normal));
    slip_direction_.push_back(at_start.contacts[k].slide_direction);
  }
  initial_acceleration_.assign(at_start.acceleration.begin(),
                               at_start.acceleration.begin() + static_cast<long>(movable_));
  integration_ = std::make_unique<Integration>(tolerance);
  integration_->dense.initialize(initial, start_, std::max(step, 1e-9 * (until_ - start_)));
  advanceTo(start_ + (until_ - start_) / 4096);
}

void ConstrainedStep::advanceTo(double time) const {
  const auto system = [this](const State& x, State& dxdt, double t) { derivative(x, dxdt, t); };
  // A motion takes at most this many steps; a stiffer one ends there and is solved again.
  constexpr int kMostSteps = 256;
  for (; end_ < until_ && end_ < time && !mode_changed_; ++taken_) {
    if (taken_ == kMostSteps) {
      mode_changed_ = true;
      return;
    }
    integration_->dense.do_step(system);
    const double stepped = integration_->dense.current_time();
    next_step_ = integration_->dense.current_time_step();
    steps_.push_back(std::make_unique<Integration>(*integration_));
    end_ = std::min(stepped, until_);
    if (!(margin(stateAt(end_), end_) < 0)) continue;
    // A mode stops holding within the step: the first instant, by bisection (its margin is
    // continuous along the step; to 1e-12 of the step, or of the time line's rounding).
    double holds = steps_.back()->dense.previous_time(), fails = end_;
    const double resolution = 1e-12 * (fails - holds) + 4e-16 * std::abs(fails);
    while (fails - holds > resolution) {
      const double middle = 0.5 * (holds + fails);
      if (margin(stateAt(middle), middle) < 0) {
        fails = middle;
      } else {
        holds = middle;
      }
    }
    end_ = fails;
    mode_changed_ = true;
    integration_.reset();  // the motion ends here: no more steps
    return;
  }
  if (complete()) integration_.reset();
}

ContactForceSolution ConstrainedStep::forces(const State& state, double time) const {
  ++solves_;
  std::vector<ForceBody> bodies = bodies_;
  std::vector<Eigen::Vector3d> positions(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (i < movable_) {
      positions[i] = slice(state, i, 0);
      bodies[i].velocity = slice(state, i, 1);
      bodies[i].angular_velocity = slice(state, i, 2);
    } else {
      positions[i] = positions_[i] + bodies[i].velocity * (time - start_);
    }
  }
  std::vector<ForceContact> contacts(contacts_.size());
  std::vector<ContactMode> modes(contacts_.size());
  for (std::size_t k = 0; k < contacts_.size(); ++k) {
    const ConstrainedContact& c = contacts_[k];
    ForceContact& contact = contacts[k];
    contact.a = c.a;
    contact.b = c.b;
    contact.friction = c.friction;
    contact.slide_direction = c.slide_direction;
    const double radius_a = bodies[c.a].radius;
    if (c.plane) {
      contact.normal = -c.plane_normal;
      contact.lever_a = radius_a * contact.normal;  // the plane's side: immovable, not read
    } else if (c.shape) {
      const ContactGeometry g =
          contactGeometry(positions[c.a], bodies[c.a].radius, shapeAt(*c.shape, time), 0.0,
                          [] { return Eigen::Vector3d(Eigen::Vector3d::Zero()); });
      setContactGeometry(g, contact);
    } else {
      const Eigen::Vector3d centres = positions[c.b] - positions[c.a];
      const double distance = centres.norm();
      contact.normal = centres / distance;
      contact.curvature = 1.0 / distance;
      contact.lever_a = radius_a * contact.normal;
      contact.lever_b = -bodies[c.b].radius * contact.normal;
    }
    modes[k] = c.mode;
  }
  return solveContactForcesWithModes(bodies, contacts, modes, settings_);
}

void ConstrainedStep::derivative(const State& state, State& rate, double time) const {
  const ContactForceSolution solution = forces(state, time);
  rate.resize(state.size());
  for (std::size_t i = 0; i < movable_; ++i) {
    put(rate, i, 0, slice(state, i, 1));
    put(rate, i, 1, solution.acceleration[i]);
    put(rate, i, 2, solution.angular_acceleration[i]);
  }
}

double ConstrainedStep::margin(const State& state, double time) const {
  const ContactForceSolution solution = forces(state, time);
  const double scale = std::max(force_scale_, 1e-300);
  // With the solver's tolerances (solveContactForces), so that a motion starts with every margin
  // >= 0: a force of -1e-12 of the largest does not pull, friction within 1e-12 of mu N holds.
  constexpr double kTolerance = 1e-12;
  double least = INFINITY;
  for (std::size_t k = 0; k < contacts_.size(); ++k) {
    const ContactForce& force = solution.contacts[k];
    const ConstrainedContact& contact = contacts_[k];
    least = std::min(least, force.normal / scale + kTolerance);  // it would pull: it lets go
    if (contact.friction > 0 && contact.mode == ContactMode::kSticking) {
      const double bound = contact.friction * force.normal;
      least = std::min(least, (bound * (1 + kTolerance) + kTolerance * scale * contact.friction -
                               force.tangential.norm()) /
                                  scale);
    }
    if (contact.friction > 0 && contact.mode == ContactMode::kSliding &&
        slip_direction_[k].norm() > 0) {
      // The slip stops (reverses by half the slip tolerance: a contact that starts to slide
      // has a slip of rounding size in no direction of its own).
      least = std::min(least, force.slip.dot(slip_direction_[k]) + 0.5 * settings_.slip_tolerance);
    }
  }
  return least;
}

const ConstrainedStep::Integration& ConstrainedStep::stepAt(double time) const {
  // The first step whose end is at or after `time` (the last one past the motion's end).
  const auto found = std::lower_bound(steps_.begin(), steps_.end(), time,
                                      [](const std::unique_ptr<Integration>& step, double t) {
                                        return step->dense.current_time() < t;
                                      });
  return found == steps_.end() ? *steps_.back() : **found;
}

ConstrainedStep::State ConstrainedStep::stateAt(double time) const {
  State state(kPerBody * movable_);
  if (steps_.empty()) {  // no step taken yet: the start
    for (std::size_t i = 0; i < movable_; ++i) {
      put(state, i, 0, positions_[i]);
      put(state, i, 1, bodies_[i].velocity);
      put(state, i, 2, bodies_[i].angular_velocity);
    }
    return state;
  }
  const Integration& step = stepAt(time);
  step.dense.calc_state(std::clamp(time, step.dense.previous_time(), step.dense.current_time()),
                        state);
  return state;
}

const ConstrainedStep::State& ConstrainedStep::queriedStateAt(double time) const {
  // Past the frontier, integrated on to it first; a state once found for an instant within the
  // steps taken stays right (later steps only add to them).
  if (time > end_ && !complete()) advanceTo(time);
  if (!(time == queried_time_)) {
    queried_state_ = stateAt(time);
    queried_time_ = time;
  }
  return queried_state_;
}

Eigen::Vector3d ConstrainedStep::position(std::size_t body, double time) const {
  return slice(queriedStateAt(time), body, 0);
}

Eigen::Vector3d ConstrainedStep::velocity(std::size_t body, double time) const {
  return slice(queriedStateAt(time), body, 1);
}

Eigen::Vector3d ConstrainedStep::angularVelocity(std::size_t body, double time) const {
  return slice(queriedStateAt(time), body, 2);
}

}  // namespace collision_response::core::monitor
