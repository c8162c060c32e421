#include "solver/contact_forces.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>
#include <utility>

#include "solver/contact_group.h"

namespace collision_response::core {
namespace {

using namespace contact_group;

enum class Tangential { kNone, kStick, kSlide };

struct Mode {
  bool pressed = true;
  Tangential tangential = Tangential::kNone;
  V3 slide_direction = V3::Zero();  ///< unit: the slip's direction (friction is against it)
};

/// The forces for an assignment of modes: the linear conditions solved jointly.
struct Trial {
  std::vector<V3> forces;            // per contact, on b
  std::vector<Real> normal_force;    // per contact
  std::vector<V3> tangential_force;  // per contact
  Response response;
};

/// The linear system of an assignment of modes, unknown i with condition i: a pressed contact's
/// normal force N (a sliding one's friction -mu N along its slide direction in the same
/// unknown) with its gap's acceleration; a sticking one's friction along each tangent with its
/// slip's acceleration along that tangent.
struct ModeSystem {
  std::vector<Unknown> unknowns;
  std::vector<Condition> conditions;
};

ModeSystem modeSystem(const Group& group, const std::vector<Mode>& modes,
                      const std::vector<Real>& friction) {
  ModeSystem system;
  for (std::size_t k = 0; k < group.contactCount(); ++k) {
    if (!modes[k].pressed) continue;
    V3 pattern = group.normal(k);
    if (modes[k].tangential == Tangential::kSlide) {
      pattern -= friction[k] * modes[k].slide_direction;
    }
    system.unknowns.push_back(Unknown{k, pattern});
    system.conditions.push_back(Condition{k, group.normal(k), true});
    if (modes[k].tangential == Tangential::kStick) {
      for (const V3& tangent : {group.first(k), group.second(k)}) {
        system.unknowns.push_back(Unknown{k, tangent});
        system.conditions.push_back(Condition{k, tangent, false});
      }
    }
  }
  return system;
}

/// The unknowns' sizes that bring every condition of `system` to 0 from its value `free` takes
/// without contact forces (gravity and the velocity terms).
Vector solveModeSystem(const Group& group, const ModeSystem& system, const Response& free) {
  const auto size = static_cast<Eigen::Index>(system.unknowns.size());
  const std::vector<Entry> entries = assembleConditions(group, system.unknowns, system.conditions);
  Vector target(size);
  for (Eigen::Index i = 0; i < size; ++i) {
    const Condition& condition = system.conditions[static_cast<std::size_t>(i)];
    target[i] = -conditionValue(condition, free.gap_acceleration[condition.contact],
                                free.slip_acceleration[condition.contact]);
  }
  // Minimum-norm least squares: also right where contacts are redundant (a ball in a corner
  // of three planes that a pair of them already holds). Where sticking contacts are redundant
  // (a ball held by friction in the corner of an incline and a wall), static friction is
  // indeterminate: every solution gives the same accelerations, but the one of minimum norm
  // may pull at a contact (doc/model.md, "Lasting contact"). The least static friction is taken
  // first: where normal forces alone can hold the group (the frictionless corner's
  // m g / cos t and m g tan t), friction takes nothing and no contact pulls.
  std::vector<char> static_friction(static_cast<std::size_t>(size));
  for (std::size_t i = 0; i < static_friction.size(); ++i) {
    static_friction[i] = !system.conditions[i].normal;
  }
  return solveMinimumNorm(size, entries, target, static_friction);
}

/// The trial of the unknowns' sizes `solution`: each contact's force, its normal and tangential
/// parts, and the group's response.
Trial storeTrial(const Group& group, const ModeSystem& system, const Vector& solution) {
  const std::size_t count = group.contactCount();
  Trial trial;
  trial.forces = forcesOf(count, system.unknowns, solution);
  trial.normal_force.assign(count, 0);
  for (Eigen::Index j = 0; j < solution.size(); ++j) {
    const Condition& condition = system.conditions[static_cast<std::size_t>(j)];
    if (condition.normal) trial.normal_force[condition.contact] = solution[j];
  }
  trial.tangential_force.assign(count, V3::Zero());
  for (std::size_t k = 0; k < count; ++k) {
    trial.tangential_force[k] =
        trial.forces[k] - trial.forces[k].dot(group.normal(k)) * group.normal(k);
  }
  trial.response = group.respond(trial.forces, true);
  return trial;
}

/// The forces for an assignment of modes: its linear conditions solved jointly.
Trial solveModes(const Group& group, const std::vector<Mode>& modes,
                 const std::vector<Real>& friction) {
  const ModeSystem system = modeSystem(group, modes, friction);
  const Response free = group.respond(std::vector<V3>(group.contactCount(), V3::Zero()), true);
  Vector solution = Vector::Zero(static_cast<Eigen::Index>(system.unknowns.size()));
  if (solution.size() > 0) solution = solveModeSystem(group, system, free);
  return storeTrial(group, system, solution);
}

/// The tolerances' scales: the accelerations and speeds the group has.
struct Scales {
  Real acceleration = 0, speed = 0, slip_tolerance = 0;
};
Scales scalesOf(const std::vector<ForceBody>& bodies, const ContactForceSettings& settings) {
  Scales scales;
  for (const ForceBody& body : bodies) {
    scales.acceleration = std::max(scales.acceleration,
                                   widen(body.acceleration).norm() +
                                       Real(body.radius) * widen(body.angular_acceleration).norm());
    scales.speed =
        std::max(scales.speed, widen(body.velocity).norm() +
                                   Real(body.radius) * widen(body.angular_velocity).norm());
  }
  scales.slip_tolerance =
      Real(settings.slip_tolerance) + 64 * std::numeric_limits<double>::epsilon() * scales.speed;
  return scales;
}

constexpr Real kTolerance = 1e-12L;

/// The answer in doubles: each contact's force, mode, slip and rates, each body's accelerations.
/// `clamp`: no negative normal force (the fixed-mode evaluation keeps its sign, to find where a
/// contact lets go).
void package(const Group& group, const Trial& trial, const std::vector<Mode>& modes,
             const Scales& scales, bool clamp, ContactForceSolution& result) {
  const std::size_t count = group.contactCount();
  const Real tolerance = kTolerance;
  const Real acceleration_scale = scales.acceleration;
  const Real slip_tolerance = scales.slip_tolerance;
  const std::size_t body_count = trial.response.acceleration.size();
  result.contacts.resize(count);
  for (std::size_t k = 0; k < count; ++k) {
    ContactForce& out = result.contacts[k];
    out.normal = static_cast<double>(clamp ? std::max(trial.normal_force[k], Real(0))
                                           : trial.normal_force[k]);
    out.tangential = trial.tangential_force[k].cast<double>();
    out.slip = group.slip(k).cast<double>();
    out.slip_acceleration = trial.response.slip_acceleration[k].cast<double>();
    if (modes[k].pressed && modes[k].tangential == Tangential::kSlide) {
      out.slide_direction = modes[k].slide_direction.cast<double>();
    }
    out.gap_acceleration = static_cast<double>(trial.response.gap_acceleration[k]);
    if (!modes[k].pressed) {
      out.mode = ContactMode::kSeparating;
    } else if (modes[k].tangential == Tangential::kSlide) {
      out.mode = ContactMode::kSliding;
    } else if (modes[k].tangential == Tangential::kStick) {
      out.mode = ContactMode::kSticking;
    } else {
      // Frictionless: it slides as soon as it slips or is about to.
      const bool slipping = group.slip(k).norm() > slip_tolerance ||
                            trial.response.slip_acceleration[k].norm() >
                                tolerance * std::max(acceleration_scale, Real(1e-300));
      out.mode = slipping ? ContactMode::kSliding : ContactMode::kSticking;
    }
  }
  result.acceleration.resize(body_count);
  result.angular_acceleration.resize(body_count);
  // What is left of a balanced acceleration is the rounding of the long double solve (1e-19 of
  // the accelerations at most): components below the rounding of the double inputs are 0, so a
  // body held at rest stays exactly where it is.
  const Real negligible = 4 * std::numeric_limits<double>::epsilon() * acceleration_scale;
  const auto snapped = [negligible](const V3& value) {
    Eigen::Vector3d out;
    for (Eigen::Index c = 0; c < 3; ++c) {
      out[c] = std::abs(value[c]) <= negligible ? 0.0 : static_cast<double>(value[c]);
    }
    return out;
  };
  for (std::size_t i = 0; i < body_count; ++i) {
    result.acceleration[i] = snapped(trial.response.acceleration[i]);
    result.angular_acceleration[i] = snapped(trial.response.angular_acceleration[i]);
  }
}

/// A pressed contact with friction takes it up by its slip: sliding, friction against the slip,
/// where it slips faster than the slip tolerance; sticking where it does not.
void takeUpFriction(const Group& group, std::size_t k, Real slip_tolerance, Mode& mode) {
  const V3& slip = group.slip(k);
  if (slip.norm() > slip_tolerance) {
    mode.tangential = Tangential::kSlide;
    mode.slide_direction = slip.normalized();
  } else {
    mode.tangential = Tangential::kStick;
  }
}

/// The first guess: pressed where the gap would close with no contact force at all (the floor
/// under a ball), free where it would not (two balls side by side that fall together); the
/// iteration corrects it. A good guess keeps the first solve small.
std::vector<Mode> guessModes(const Group& group, const std::vector<Real>& friction,
                             const Scales& scales) {
  const std::size_t count = group.contactCount();
  std::vector<Mode> modes(count);
  const Response unpressed = group.respond(std::vector<V3>(count, V3::Zero()), true);
  for (std::size_t k = 0; k < count; ++k) {
    modes[k].pressed =
        unpressed.gap_acceleration[k] < -kTolerance * std::max(scales.acceleration, Real(1e-300));
  }
  for (std::size_t k = 0; k < count; ++k) {
    if (modes[k].pressed && friction[k] > 0) {
      takeUpFriction(group, k, scales.slip_tolerance, modes[k]);
    }
  }
  return modes;
}

/// The largest normal force of a trial: the scale of its forces.
Real largestNormalForce(const Trial& trial) {
  Real force_scale = 0;
  for (const Real normal : trial.normal_force) {
    force_scale = std::max(force_scale, std::abs(normal));
  }
  return force_scale;
}

/// A contact whose mode fails under a trial's forces: by how much (in units of its scale, > 0),
/// to change the worst first when changing all at once cycles, and the mode it changes to.
struct Change {
  std::size_t contact;
  Real size;
  Mode mode;
};

/// Whether a pressed contact k's mode holds under the trial's forces (size 0) or how it fails: a
/// normal force that would pull, static friction beyond mu N, or a contact starting to slide
/// whose slip would not grow along the direction taken.
Change pressedFailure(const Group& group, std::size_t k, const Mode& mode, const Trial& trial,
                      Real friction, Real force_scale, const Scales& scales) {
  const Real tolerance = kTolerance;
  const Real acceleration_scale = scales.acceleration;
  Change change{k, 0, mode};
  const Real normal = trial.normal_force[k];
  if (normal < -tolerance * force_scale) {  // it would pull: let it go
    change.mode.pressed = false;
    change.size = -normal / std::max(force_scale, Real(1e-300));
  } else if (mode.tangential == Tangential::kStick) {
    const Real needed = trial.tangential_force[k].norm();
    const Real bound = friction * std::max(normal, Real(0));
    if (needed > bound * (1 + tolerance) + tolerance * force_scale * friction) {
      // Static friction cannot hold it: it starts to slide, the friction against the direction
      // the sticking force pointed away from.
      change.mode.tangential = Tangential::kSlide;
      change.mode.slide_direction = -trial.tangential_force[k] / needed;
      change.size = (needed - bound) / std::max(force_scale, Real(1e-300));
    }
  } else if (mode.tangential == Tangential::kSlide &&
             group.slip(k).norm() <= scales.slip_tolerance) {
    // Starting to slide: the slip must grow along the direction taken.
    const V3& rate = trial.response.slip_acceleration[k];
    const Real along = rate.dot(mode.slide_direction);
    if (along < -tolerance * acceleration_scale) {
      change.mode.tangential = Tangential::kStick;
      change.size = -along / std::max(acceleration_scale, Real(1e-300));
    } else if (rate.norm() > tolerance * acceleration_scale &&
               (rate.normalized() - mode.slide_direction).norm() > 1e-12L) {
      change.mode.slide_direction = rate.normalized();  // follow the slip it starts
      change.size = (rate.normalized() - mode.slide_direction).norm();
    }
  }
  return change;
}

/// The contacts whose modes fail under the trial's forces: pressed ones (pressedFailure), and
/// free ones whose gap would close.
std::vector<Change> failingModes(const Group& group, const std::vector<Mode>& modes,
                                 const Trial& trial, const std::vector<Real>& friction,
                                 const Scales& scales) {
  const Real force_scale = largestNormalForce(trial);
  const Real acceleration_scale = std::max(scales.acceleration, Real(1e-300));
  std::vector<Change> changes;
  for (std::size_t k = 0; k < group.contactCount(); ++k) {
    Change change{k, 0, modes[k]};
    if (modes[k].pressed) {
      change = pressedFailure(group, k, modes[k], trial, friction[k], force_scale, scales);
    } else {
      const Real gap = trial.response.gap_acceleration[k];
      if (gap < -kTolerance * acceleration_scale) {  // it would close
        change.mode.pressed = true;
        change.size = -gap / acceleration_scale;
      }
    }
    if (change.size > 0) changes.push_back(change);
  }
  return changes;
}

/// The modes as one key, to see an assignment come back.
std::vector<int> modeSignature(const std::vector<Mode>& modes) {
  std::vector<int> signature;
  for (const Mode& mode : modes) {
    signature.push_back(mode.pressed * 4 + static_cast<int>(mode.tangential));
  }
  return signature;
}

/// The failing contacts take their new modes: all at once, or, `one_at_a_time` (all at once
/// cycled), the largest failure; among equal ones (mirror images) all of them. A contact let go
/// drops its friction; one pressed again takes friction up by its slip.
void changeModes(const Group& group, const std::vector<Real>& friction, Real slip_tolerance,
                 const std::vector<Change>& changes, bool one_at_a_time, std::vector<Mode>& modes) {
  if (one_at_a_time) {
    Real largest = 0;
    for (const Change& change : changes) largest = std::max(largest, change.size);
    for (const Change& change : changes) {
      if (change.size >= largest * (1 - 1e-9L)) modes[change.contact] = change.mode;
    }
  } else {
    for (const Change& change : changes) modes[change.contact] = change.mode;
  }
  for (Mode& mode : modes) {
    if (!mode.pressed) mode.tangential = Tangential::kNone;
  }
  for (std::size_t k = 0; k < modes.size(); ++k) {
    if (modes[k].pressed && modes[k].tangential == Tangential::kNone && friction[k] > 0) {
      takeUpFriction(group, k, slip_tolerance, modes[k]);
    }
  }
}

/// The last forces of modes that did not settle, clamped: no contact pulls, no friction beyond
/// mu N; and the group's response to them.
void clampForces(const Group& group, const std::vector<Real>& friction, Trial& trial) {
  for (std::size_t k = 0; k < group.contactCount(); ++k) {
    const Real normal = std::max(trial.normal_force[k], Real(0));
    V3 tangential = trial.tangential_force[k];
    const Real bound = friction[k] * normal;
    if (tangential.norm() > bound) {
      tangential =
          tangential.norm() > 0 ? V3(tangential * (bound / tangential.norm())) : V3(V3::Zero());
    }
    trial.normal_force[k] = normal;
    trial.tangential_force[k] = tangential;
    trial.forces[k] = normal * group.normal(k) + tangential;
  }
  trial.response = group.respond(trial.forces, true);
}

/// A pressed contact left with no force only touches (a neighbour on the floor): it carries
/// nothing and lasts no more than any touching pair.
void releaseUnloaded(const Trial& trial, std::vector<Mode>& modes) {
  const Real force_scale = largestNormalForce(trial);
  for (std::size_t k = 0; k < modes.size(); ++k) {
    if (modes[k].pressed && trial.normal_force[k] <= kTolerance * force_scale) {
      modes[k].pressed = false;
    }
  }
}

/// Baraff's and Coulomb's conditions (header) by their modes: from a first guess, the forces of
/// the modes (solveModes), and where a mode fails the contact changes it, all failing contacts
/// at once (the worst first where that cycles), until none fails or the iterations run out.
ContactForceSolution solveContactModes(const std::vector<ForceBody>& bodies,
                                       const std::vector<ForceContact>& contacts,
                                       const ContactForceSettings& settings) {
  const Group group(bodies, contacts);
  std::vector<Real> friction(contacts.size());
  for (std::size_t k = 0; k < contacts.size(); ++k) friction[k] = contacts[k].friction;
  const Scales scales = scalesOf(bodies, settings);
  std::vector<Mode> modes = guessModes(group, friction, scales);
  Trial trial;
  std::set<std::vector<int>> seen;
  bool one_at_a_time = false;
  bool settled = false;
  for (int iteration = 0; iteration < settings.max_iterations; ++iteration) {
    trial = solveModes(group, modes, friction);
    const std::vector<Change> changes = failingModes(group, modes, trial, friction, scales);
    if (changes.empty()) {
      settled = true;
      break;
    }
    if (!seen.insert(modeSignature(modes)).second) one_at_a_time = true;  // all at once cycled
    changeModes(group, friction, scales.slip_tolerance, changes, one_at_a_time, modes);
  }
  ContactForceSolution result;
  result.converged = settled;
  if (!settled) clampForces(group, friction, trial);
  releaseUnloaded(trial, modes);
  package(group, trial, modes, scales, true, result);
  return result;
}

}  // namespace

ContactForceSolution solveContactForces(const std::vector<ForceBody>& bodies,
                                        const std::vector<ForceContact>& contacts,
                                        const ContactForceSettings& settings) {
  ContactForceSolution solution = solveContactModes(bodies, contacts, settings);
  const bool with_friction = std::any_of(contacts.begin(), contacts.end(),
                                         [](const ForceContact& c) { return c.friction > 0; });
  if (solution.converged || !with_friction) return solution;
  // The clamped forces of modes that did not settle may let a gap close (header): without
  // friction, the normal forces alone.
  std::vector<ForceContact> frictionless = contacts;
  for (ForceContact& contact : frictionless) contact.friction = 0.0;
  ContactForceSolution normal_only = solveContactModes(bodies, frictionless, settings);
  if (!normal_only.converged) return solution;
  normal_only.converged = false;
  normal_only.friction_dropped = true;
  return normal_only;
}

ContactForceSolution solveContactForcesWithModes(const std::vector<ForceBody>& bodies,
                                                 const std::vector<ForceContact>& contacts,
                                                 const std::vector<ContactMode>& fixed,
                                                 const ContactForceSettings& settings) {
  const Group group(bodies, contacts);
  const std::size_t count = contacts.size();
  const Scales scales = scalesOf(bodies, settings);
  std::vector<Real> friction(count);
  std::vector<Mode> modes(count);
  for (std::size_t k = 0; k < count; ++k) {
    friction[k] = contacts[k].friction;
    modes[k].pressed = fixed[k] != ContactMode::kSeparating;
    if (!modes[k].pressed || !(friction[k] > 0)) continue;
    if (fixed[k] == ContactMode::kSticking) {
      modes[k].tangential = Tangential::kStick;
    } else if (group.slip(k).norm() > scales.slip_tolerance ||
               (group.slip(k).norm() > 0 && contacts[k].slide_direction.isZero())) {
      modes[k].tangential = Tangential::kSlide;  // along the slip it has now
      modes[k].slide_direction = group.slip(k).normalized();
    } else if (!contacts[k].slide_direction.isZero()) {
      // It starts to slide: a slip below the tolerance has no direction of its own (rounding).
      modes[k].tangential = Tangential::kSlide;
      modes[k].slide_direction = contacts[k].slide_direction.normalized().cast<Real>();
    }
  }
  const Trial trial = solveModes(group, modes, friction);
  ContactForceSolution result;
  package(group, trial, modes, scales, false, result);
  return result;
}

}  // namespace collision_response::core
