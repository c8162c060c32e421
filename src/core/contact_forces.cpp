#include "collision_response/core/contact_forces.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <set>

namespace collision_response::core {
namespace {

using Real = long double;  // 11 bits more than double: the answer is rounded once, at the end
using V3 = Eigen::Matrix<Real, 3, 1>;
using Matrix = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;
using Vector = Eigen::Matrix<Real, Eigen::Dynamic, 1>;

V3 widen(const Eigen::Vector3d& v) { return v.cast<Real>(); }

/// Two unit vectors spanning the plane perpendicular to the unit `normal`.
void tangentBasis(const V3& normal, V3& first, V3& second) {
  Eigen::Index axis = 0;
  normal.cwiseAbs().minCoeff(&axis);
  V3 unit = V3::Zero();
  unit[axis] = 1;
  first = normal.cross(unit).normalized();
  second = normal.cross(first);
}

enum class Tangential { kNone, kStick, kSlide };

struct Mode {
  bool pressed = true;
  Tangential tangential = Tangential::kNone;
  V3 slide_direction = V3::Zero();  ///< unit: the slip's direction (friction is against it)
};

/// What the group does under given contact forces: the bodies' accelerations and, per contact,
/// the gap's and the slip's accelerations. With `free`, gravity and the velocity terms are in.
struct Response {
  std::vector<V3> acceleration, angular_acceleration;
  std::vector<Real> gap_acceleration;
  std::vector<V3> slip_acceleration;
};

class Group {
 public:
  Group(const std::vector<ForceBody>& bodies, const std::vector<ForceContact>& contacts)
      : bodies_(bodies), contacts_(contacts) {
    for (const ForceContact& contact : contacts_) {
      const V3 normal = widen(contact.normal);
      V3 first, second;
      tangentBasis(normal, first, second);
      normal_.push_back(normal);
      first_.push_back(first);
      second_.push_back(second);
      const ForceBody& a = bodies_[contact.a];
      const ForceBody& b = bodies_[contact.b];
      const V3 relative = widen(b.velocity) - widen(a.velocity);
      const V3 across = relative - relative.dot(normal) * normal;
      const V3 turning =
          (Real(a.radius) * widen(a.angular_velocity) + Real(b.radius) * widen(b.angular_velocity));
      const V3 slip_full = relative - turning.cross(normal);
      slip_.push_back(slip_full - slip_full.dot(normal) * normal);
      const Real curvature = contact.curvature;
      centripetal_.push_back(curvature * across.squaredNorm());
      // The normal turns at n' = v_perp / d: the slip changes by -(r_a w_a + r_b w_b) x n'.
      turning_term_.push_back(-turning.cross(curvature * across));
    }
  }

  std::size_t contactCount() const { return contacts_.size(); }
  const V3& normal(std::size_t k) const { return normal_[k]; }
  const V3& first(std::size_t k) const { return first_[k]; }
  const V3& second(std::size_t k) const { return second_[k]; }
  const V3& slip(std::size_t k) const { return slip_[k]; }

  /// The group's response to the contact forces `forces` (on each contact's b).
  Response respond(const std::vector<V3>& forces, bool free) const {
    Response r;
    r.acceleration.assign(bodies_.size(), V3::Zero());
    r.angular_acceleration.assign(bodies_.size(), V3::Zero());
    if (free) {
      for (std::size_t i = 0; i < bodies_.size(); ++i) {
        r.acceleration[i] = widen(bodies_[i].acceleration);
        r.angular_acceleration[i] = widen(bodies_[i].angular_acceleration);
      }
    }
    for (std::size_t k = 0; k < contacts_.size(); ++k) {
      const ForceContact& contact = contacts_[k];
      push(r, contact.b, forces[k], -normal_[k]);  // b's contact point: -r_b n from its centre
      push(r, contact.a, -forces[k], normal_[k]);  // a's: +r_a n
    }
    r.gap_acceleration.resize(contacts_.size());
    r.slip_acceleration.resize(contacts_.size());
    for (std::size_t k = 0; k < contacts_.size(); ++k) {
      const ForceContact& contact = contacts_[k];
      const V3 relative = r.acceleration[contact.b] - r.acceleration[contact.a];
      Real gap = normal_[k].dot(relative);
      V3 slip = relative - (Real(bodies_[contact.a].radius) * r.angular_acceleration[contact.a] +
                            Real(bodies_[contact.b].radius) * r.angular_acceleration[contact.b])
                               .cross(normal_[k]);
      if (free) {
        gap += centripetal_[k];
        slip += turning_term_[k];
      }
      r.gap_acceleration[k] = gap;
      r.slip_acceleration[k] = slip - slip.dot(normal_[k]) * normal_[k];
    }
    return r;
  }

 private:
  /// Force `force` on body `i` at its contact point, r `lever` from its centre (lever +n for a,
  /// -n for b).
  void push(Response& r, std::size_t i, const V3& force, const V3& lever) const {
    const ForceBody& body = bodies_[i];
    if (body.inverse_mass == 0.0) return;
    r.acceleration[i] += Real(body.inverse_mass) * force;
    if (body.spin_factor != 0.0 && body.radius > 0.0) {
      // Moment r lever x F about the centre; angular acceleration moment / I, 1/I = w / (k r^2).
      r.angular_acceleration[i] +=
          (Real(body.inverse_mass) * Real(body.spin_factor) / Real(body.radius)) *
          lever.cross(force);
    }
  }

  const std::vector<ForceBody>& bodies_;
  const std::vector<ForceContact>& contacts_;
  std::vector<V3> normal_, first_, second_, slip_, turning_term_;
  std::vector<Real> centripetal_;
};

/// The force pattern of one unknown: the force on each contact's b per unit of the unknown.
struct Unknown {
  std::size_t contact = 0;
  V3 pattern = V3::Zero();
};

/// The forces for an assignment of modes: the linear conditions solved jointly.
struct Trial {
  std::vector<V3> forces;            // per contact, on b
  std::vector<Real> normal_force;    // per contact
  std::vector<V3> tangential_force;  // per contact
  Response response;
};

Trial solveModes(const Group& group, const std::vector<Mode>& modes,
                 const std::vector<Real>& friction) {
  const std::size_t count = group.contactCount();
  std::vector<Unknown> unknowns;
  // Rows: one condition per unknown (gap acceleration 0 for a pressed contact's normal force,
  // slip acceleration 0 along each tangent of a sticking one).
  struct Row {
    std::size_t contact;
    int kind;  // 0 gap, 1 first tangent, 2 second tangent
  };
  std::vector<Row> rows;
  for (std::size_t k = 0; k < count; ++k) {
    if (!modes[k].pressed) continue;
    V3 pattern = group.normal(k);
    if (modes[k].tangential == Tangential::kSlide) {
      pattern -= friction[k] * modes[k].slide_direction;
    }
    unknowns.push_back(Unknown{k, pattern});
    rows.push_back(Row{k, 0});
    if (modes[k].tangential == Tangential::kStick) {
      unknowns.push_back(Unknown{k, group.first(k)});
      rows.push_back(Row{k, 1});
      unknowns.push_back(Unknown{k, group.second(k)});
      rows.push_back(Row{k, 2});
    }
  }
  const auto condition = [&](const Response& response, const Row& row) -> Real {
    if (row.kind == 0) return response.gap_acceleration[row.contact];
    const V3& tangent = row.kind == 1 ? group.first(row.contact) : group.second(row.contact);
    return tangent.dot(response.slip_acceleration[row.contact]);
  };
  const std::vector<V3> no_forces(count, V3::Zero());
  const Response free = group.respond(no_forces, true);
  const auto size = static_cast<Eigen::Index>(unknowns.size());
  Vector solution = Vector::Zero(size);
  if (size > 0) {
    Matrix system(size, size);
    Vector target(size);
    for (Eigen::Index j = 0; j < size; ++j) {
      std::vector<V3> forces = no_forces;
      forces[unknowns[j].contact] = unknowns[j].pattern;
      const Response column = group.respond(forces, false);
      for (Eigen::Index i = 0; i < size; ++i) system(i, j) = condition(column, rows[i]);
    }
    for (Eigen::Index i = 0; i < size; ++i) target[i] = -condition(free, rows[i]);
    // Minimum-norm least squares: also right where contacts are redundant (a ball in a corner
    // of three planes that a pair of them already holds).
    solution = system.completeOrthogonalDecomposition().solve(target);
  }
  Trial trial;
  trial.forces.assign(count, V3::Zero());
  trial.normal_force.assign(count, 0);
  trial.tangential_force.assign(count, V3::Zero());
  for (Eigen::Index j = 0; j < size; ++j) {
    const Unknown& unknown = unknowns[j];
    trial.forces[unknown.contact] += solution[j] * unknown.pattern;
    if (rows[j].kind == 0) trial.normal_force[unknown.contact] = solution[j];
  }
  for (std::size_t k = 0; k < count; ++k) {
    trial.tangential_force[k] =
        trial.forces[k] - trial.forces[k].dot(group.normal(k)) * group.normal(k);
  }
  trial.response = group.respond(trial.forces, true);
  return trial;
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

}  // namespace

void closeContactVelocities(std::vector<ForceBody>& bodies,
                            const std::vector<ForceContact>& contacts,
                            const std::vector<bool>& sticking) {
  // Impulses map to velocity changes as forces map to accelerations: the same response, with
  // no free terms. One condition per unknown: the normal relative velocity, and the slip along
  // each tangent of a sticking contact.
  const Group group(bodies, contacts);
  const std::size_t count = contacts.size();
  struct Condition {
    std::size_t contact;
    V3 direction;
    bool normal;
  };
  std::vector<Condition> conditions;
  std::vector<Real> targets;
  for (std::size_t k = 0; k < count; ++k) {
    const ForceContact& contact = contacts[k];
    const V3 relative = widen(bodies[contact.b].velocity) - widen(bodies[contact.a].velocity);
    conditions.push_back(Condition{k, group.normal(k), true});
    targets.push_back(-group.normal(k).dot(relative));
    if (sticking[k]) {
      for (const V3& tangent : {group.first(k), group.second(k)}) {
        conditions.push_back(Condition{k, tangent, false});
        targets.push_back(-tangent.dot(group.slip(k)));
      }
    }
  }
  const auto size = static_cast<Eigen::Index>(conditions.size());
  if (size == 0) return;
  const auto measure = [&](const Response& response, const Condition& condition) -> Real {
    return condition.normal
               ? response.gap_acceleration[condition.contact]
               : condition.direction.dot(response.slip_acceleration[condition.contact]);
  };
  const std::vector<V3> no_impulses(count, V3::Zero());
  Matrix system(size, size);
  for (Eigen::Index j = 0; j < size; ++j) {
    std::vector<V3> impulses = no_impulses;
    impulses[conditions[j].contact] = conditions[j].direction;
    const Response column = group.respond(impulses, false);
    for (Eigen::Index i = 0; i < size; ++i) system(i, j) = measure(column, conditions[i]);
  }
  Vector target(size);
  for (Eigen::Index i = 0; i < size; ++i) target[i] = targets[i];
  const Vector solution = system.completeOrthogonalDecomposition().solve(target);
  std::vector<V3> impulses = no_impulses;
  for (Eigen::Index j = 0; j < size; ++j) {
    impulses[conditions[j].contact] += solution[j] * conditions[j].direction;
  }
  const Response change = group.respond(impulses, false);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].inverse_mass == 0.0) continue;
    bodies[i].velocity = (widen(bodies[i].velocity) + change.acceleration[i]).cast<double>();
    bodies[i].angular_velocity =
        (widen(bodies[i].angular_velocity) + change.angular_acceleration[i]).cast<double>();
  }
}

void closeContactGaps(std::vector<Eigen::Vector3d>& positions, const std::vector<ForceBody>& bodies,
                      const std::vector<ForceContact>& contacts, const std::vector<double>& gaps) {
  // Displacements d = w sum_k s_k mu_k n_k change gap_l by sum_k A_lk mu_k, as impulses change the
  // normal relative velocities: the same linear map.
  const Group group(bodies, contacts);
  const auto size = static_cast<Eigen::Index>(contacts.size());
  if (size == 0) return;
  const std::vector<V3> none(contacts.size(), V3::Zero());
  Matrix system(size, size);
  for (Eigen::Index j = 0; j < size; ++j) {
    std::vector<V3> pushes = none;
    pushes[j] = group.normal(j);
    const Response column = group.respond(pushes, false);
    for (Eigen::Index i = 0; i < size; ++i) system(i, j) = column.gap_acceleration[i];
  }
  Vector target(size);
  for (Eigen::Index i = 0; i < size; ++i) target[i] = -Real(gaps[i]);
  const Vector solution = system.completeOrthogonalDecomposition().solve(target);
  std::vector<V3> pushes = none;
  for (Eigen::Index j = 0; j < size; ++j) pushes[j] = solution[j] * group.normal(j);
  const Response change = group.respond(pushes, false);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].inverse_mass == 0.0) continue;
    positions[i] = (widen(positions[i]) + change.acceleration[i]).cast<double>();
  }
}

ContactForceSolution solveContactForces(const std::vector<ForceBody>& bodies,
                                        const std::vector<ForceContact>& contacts,
                                        const ContactForceSettings& settings) {
  const Group group(bodies, contacts);
  const std::size_t count = contacts.size();
  std::vector<Real> friction(count);
  for (std::size_t k = 0; k < count; ++k) friction[k] = contacts[k].friction;

  const Scales scales = scalesOf(bodies, settings);
  const Real acceleration_scale = scales.acceleration;
  const Real tolerance = kTolerance;
  const Real slip_tolerance = scales.slip_tolerance;

  std::vector<Mode> modes(count);
  for (std::size_t k = 0; k < count; ++k) {
    if (friction[k] > 0) {
      const V3& slip = group.slip(k);
      if (slip.norm() > slip_tolerance) {
        modes[k].tangential = Tangential::kSlide;
        modes[k].slide_direction = slip.normalized();
      } else {
        modes[k].tangential = Tangential::kStick;
      }
    }
  }

  ContactForceSolution result;
  Trial trial;
  std::set<std::vector<int>> seen;
  bool one_at_a_time = false;
  bool settled = false;
  for (int iteration = 0; iteration < settings.max_iterations; ++iteration) {
    trial = solveModes(group, modes, friction);
    Real force_scale = 0;
    for (std::size_t k = 0; k < count; ++k) {
      force_scale = std::max(force_scale, std::abs(trial.normal_force[k]));
    }
    // Each failing condition with its size (in units of its scale), to change the worst first
    // when changing all at once cycles.
    struct Change {
      std::size_t contact;
      Real size;
      Mode mode;
    };
    std::vector<Change> changes;
    for (std::size_t k = 0; k < count; ++k) {
      const Mode& mode = modes[k];
      Mode next = mode;
      Real size = 0;
      if (mode.pressed) {
        const Real normal = trial.normal_force[k];
        if (normal < -tolerance * force_scale) {  // it would pull: let it go
          next.pressed = false;
          size = -normal / std::max(force_scale, Real(1e-300));
        } else if (mode.tangential == Tangential::kStick) {
          const Real needed = trial.tangential_force[k].norm();
          const Real bound = friction[k] * std::max(normal, Real(0));
          if (needed > bound * (1 + tolerance) + tolerance * force_scale * friction[k]) {
            // Static friction cannot hold it: it starts to slide, the friction against the
            // direction the sticking force pointed away from.
            next.tangential = Tangential::kSlide;
            next.slide_direction = -trial.tangential_force[k] / needed;
            size = (needed - bound) / std::max(force_scale, Real(1e-300));
          }
        } else if (mode.tangential == Tangential::kSlide &&
                   group.slip(k).norm() <= slip_tolerance) {
          // Starting to slide: the slip must grow along the direction taken.
          const V3& rate = trial.response.slip_acceleration[k];
          const Real along = rate.dot(mode.slide_direction);
          if (along < -tolerance * acceleration_scale) {
            next.tangential = Tangential::kStick;
            size = -along / std::max(acceleration_scale, Real(1e-300));
          } else if (rate.norm() > tolerance * acceleration_scale &&
                     (rate.normalized() - mode.slide_direction).norm() > 1e-12L) {
            next.slide_direction = rate.normalized();  // follow the slip it starts
            size = (rate.normalized() - mode.slide_direction).norm();
          }
        }
      } else {
        const Real gap = trial.response.gap_acceleration[k];
        if (gap < -tolerance * std::max(acceleration_scale, Real(1e-300))) {  // it would close
          next.pressed = true;
          size = -gap / std::max(acceleration_scale, Real(1e-300));
        }
      }
      if (size > 0) changes.push_back(Change{k, size, next});
    }
    if (changes.empty()) {
      settled = true;
      break;
    }
    std::vector<int> signature;
    for (const Mode& mode : modes) {
      signature.push_back(mode.pressed * 4 + static_cast<int>(mode.tangential));
    }
    if (!seen.insert(signature).second) one_at_a_time = true;  // all at once cycled
    if (one_at_a_time) {
      // The largest failure; among equal ones (mirror images) all of them.
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
    for (std::size_t k = 0; k < count; ++k) {
      if (modes[k].pressed && modes[k].tangential == Tangential::kNone && friction[k] > 0) {
        // A contact pressed again takes up friction by its slip.
        const V3& slip = group.slip(k);
        if (slip.norm() > slip_tolerance) {
          modes[k].tangential = Tangential::kSlide;
          modes[k].slide_direction = slip.normalized();
        } else {
          modes[k].tangential = Tangential::kStick;
        }
      }
    }
  }

  result.converged = settled;
  if (!settled) {
    // Keep the last forces, clamped: no contact pulls, no friction beyond mu N.
    for (std::size_t k = 0; k < count; ++k) {
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
  // A pressed contact left with no force only touches (a neighbour on the floor): it carries
  // nothing and lasts no more than any touching pair.
  Real force_scale = 0;
  for (std::size_t k = 0; k < count; ++k) {
    force_scale = std::max(force_scale, std::abs(trial.normal_force[k]));
  }
  for (std::size_t k = 0; k < count; ++k) {
    if (modes[k].pressed && trial.normal_force[k] <= tolerance * force_scale) {
      modes[k].pressed = false;
    }
  }
  package(group, trial, modes, scales, true, result);
  return result;
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
    } else if (group.slip(k).norm() > 0) {
      modes[k].tangential = Tangential::kSlide;  // along the slip it has now
      modes[k].slide_direction = group.slip(k).normalized();
    }
  }
  const Trial trial = solveModes(group, modes, friction);
  ContactForceSolution result;
  package(group, trial, modes, scales, false, result);
  return result;
}

}  // namespace collision_response::core
