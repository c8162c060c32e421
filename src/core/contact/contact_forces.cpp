#include "contact/contact_forces.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>
#include <utility>

#include "impact/order_free.h"

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
      if (contact.turning_axis.isZero()) {
        centripetal_.push_back(curvature * across.squaredNorm());
        // The normal turns at n' = v_perp / d: the slip changes by -(r_a w_a + r_b w_b) x n'.
        turning_term_.push_back(-turning.cross(curvature * across));
      } else {
        // Along the turning axis at its share of the rate: n' = (v_perp - (1 - share)(a.v) a) / d.
        const V3 axis = widen(contact.turning_axis);
        const V3 turn =
            curvature * (across - (1 - Real(contact.axial_share)) * axis.dot(across) * axis);
        centripetal_.push_back(across.dot(turn));
        turning_term_.push_back(-turning.cross(turn));
      }
    }
    incident_.resize(bodies_.size());
    for (std::size_t k = 0; k < contacts_.size(); ++k) {
      incident_[contacts_[k].a].push_back(k);
      incident_[contacts_[k].b].push_back(k);
    }
  }

  std::size_t contactCount() const { return contacts_.size(); }

  /// What a force `force` on contact j's b (and -force on its a) alone does, without the free
  /// terms: visit(k, gap acceleration, slip acceleration) for each contact k that shares a
  /// movable body with j, the only ones it changes; the values are respond()'s to the bit (the
  /// other forces' zeros add nothing). A column of the conditions' matrix in O(its nonzeros).
  template <class Visit>
  void respondToOne(std::size_t j, const V3& force, Visit visit) const {
    const ForceContact& source = contacts_[j];
    // The two bodies' accelerations in fixed slots, not a Response: a column costs no
    // allocation (this runs for every unknown of every solve, and the integrator of curved
    // contact solves at every stage of every step).
    V3 acceleration[2] = {V3::Zero(), V3::Zero()};
    V3 angular_acceleration[2] = {V3::Zero(), V3::Zero()};
    const std::size_t moved[2] = {source.a, source.b};
    accelerate(source.b, force, -normal_[j], acceleration[1], angular_acceleration[1]);
    accelerate(source.a, -force, normal_[j], acceleration[0], angular_acceleration[0]);
    const auto local = [&](std::size_t body, const V3* values) -> V3 {
      if (body == moved[0]) return values[0];
      if (body == moved[1]) return values[1];
      return V3::Zero();
    };
    for (int side = 0; side < 2; ++side) {
      const std::size_t body = moved[side];
      if (bodies_[body].inverse_mass == 0.0) continue;
      for (const std::size_t k : incident_[body]) {
        const ForceContact& contact = contacts_[k];
        if (side == 1 && (contact.a == moved[0] || contact.b == moved[0]) &&
            bodies_[moved[0]].inverse_mass != 0.0) {
          continue;  // visited from a's side
        }
        const V3 relative = local(contact.b, acceleration) - local(contact.a, acceleration);
        const Real gap = normal_[k].dot(relative);
        const V3 slip =
            relative - (Real(bodies_[contact.a].radius) * local(contact.a, angular_acceleration) +
                        Real(bodies_[contact.b].radius) * local(contact.b, angular_acceleration))
                           .cross(normal_[k]);
        visit(k, gap, V3(slip - slip.dot(normal_[k]) * normal_[k]));
      }
    }
  }
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
    pushAt(r, i, i, force, lever);
  }
  /// push() into slot `slot` of `r` for body `i`.
  void pushAt(Response& r, std::size_t slot, std::size_t i, const V3& force,
              const V3& lever) const {
    accelerate(i, force, lever, r.acceleration[slot], r.angular_acceleration[slot]);
  }
  /// What `force` at `lever` adds to body `i`'s accelerations.
  void accelerate(std::size_t i, const V3& force, const V3& lever, V3& acceleration,
                  V3& angular_acceleration) const {
    const ForceBody& body = bodies_[i];
    if (body.inverse_mass == 0.0) return;
    acceleration += Real(body.inverse_mass) * force;
    if (body.spin_factor != 0.0 && body.radius > 0.0) {
      // Moment r lever x F about the centre; angular acceleration moment / I, 1/I = w / (k r^2).
      angular_acceleration +=
          (Real(body.inverse_mass) * Real(body.spin_factor) / Real(body.radius)) *
          lever.cross(force);
    }
  }

  const std::vector<ForceBody>& bodies_;
  const std::vector<ForceContact>& contacts_;
  std::vector<V3> normal_, first_, second_, slip_, turning_term_;
  std::vector<Real> centripetal_;
  std::vector<std::vector<std::size_t>> incident_;  // per body: the contacts it is in
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

/// One nonzero entry of a conditions' matrix.
struct Entry {
  Eigen::Index row, column;
  Real value;
};

/// Among the least-squares solutions of a x = b, given the one of minimum norm `x` from a's
/// complete orthogonal decomposition a P = Q [T 0; 0 0] Z (rank r): the one whose unknowns
/// marked in `least_first` have the least norm, and among those the least norm of all. The
/// solutions are x + K y, K = P Z^T's last n - r columns an orthonormal basis of a's kernel,
/// and x is orthogonal to it, so |x + K y|^2 = |x|^2 + |y|^2: the minimum-norm y of
/// (S K) y = -S x (S the marked rows) is both.
Vector leastFirst(const Eigen::CompleteOrthogonalDecomposition<Matrix>& decomposition,
                  const Vector& x, const std::vector<char>& least_first) {
  const Eigen::Index n = decomposition.cols(), rank = decomposition.rank();
  std::vector<Eigen::Index> marked;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (least_first[static_cast<std::size_t>(i)]) marked.push_back(i);
  }
  if (rank == n || marked.empty()) return x;
  const Matrix kernel =
      decomposition.colsPermutation() * decomposition.matrixZ().bottomRows(n - rank).transpose();
  const auto m = static_cast<Eigen::Index>(marked.size());
  Matrix selected(m, n - rank);
  Vector shift(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    selected.row(r) = kernel.row(marked[static_cast<std::size_t>(r)]);
    shift[r] = -x[marked[static_cast<std::size_t>(r)]];
  }
  return x + kernel * selected.completeOrthogonalDecomposition().solve(shift);
}

/// The minimum-norm least-squares solution of A x = target, A of `size` x `size` given by its
/// nonzero entries, block by block: the unknowns fall into connected sets (i and j connected
/// where A(i, j) or A(j, i) is not 0: their contacts share a movable body, directly or through
/// others), and a block-diagonal system's minimum-norm solution is each block's (a complete
/// orthogonal decomposition each). Exact, and independent of the order of the blocks; a group
/// whose contacts barely interact (balls side by side on a floor) is many small solves, not one
/// dense solve of every unknown. With `least_first` (one flag per unknown), where a block has
/// many solutions the marked unknowns' norm is the least first (leastFirst).
Vector solveMinimumNorm(Eigen::Index size, const std::vector<Entry>& entries, const Vector& target,
                        const std::vector<char>& least_first = {}) {
  const auto unknown = [](Eigen::Index i) { return static_cast<std::size_t>(i); };
  ConnectedSets connected(unknown(size));
  for (const Entry& entry : entries) {
    if (entry.value != 0) connected.link(unknown(entry.row), unknown(entry.column));
  }
  const std::vector<std::vector<std::size_t>> blocks = connected.sets();
  // Each unknown's block and its place in it.
  std::vector<std::size_t> block_of(unknown(size)), place(unknown(size));
  std::vector<Matrix> parts(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (std::size_t i = 0; i < blocks[b].size(); ++i) {
      block_of[blocks[b][i]] = b;
      place[blocks[b][i]] = i;
    }
    const auto n = static_cast<Eigen::Index>(blocks[b].size());
    parts[b] = Matrix::Zero(n, n);
  }
  for (const Entry& entry : entries) {
    if (entry.value == 0) continue;
    parts[block_of[unknown(entry.row)]](static_cast<Eigen::Index>(place[unknown(entry.row)]),
                                        static_cast<Eigen::Index>(place[unknown(entry.column)])) =
        entry.value;
  }
  Vector solution = Vector::Zero(size);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const std::vector<std::size_t>& block = blocks[b];
    const auto n = static_cast<Eigen::Index>(block.size());
    Vector right(n);
    for (Eigen::Index i = 0; i < n; ++i)
      right[i] = target[static_cast<Eigen::Index>(block[unknown(i)])];
    const Eigen::CompleteOrthogonalDecomposition<Matrix> decomposition(parts[b]);
    Vector x = decomposition.solve(right);
    if (!least_first.empty() && decomposition.rank() < n) {
      std::vector<char> marked(block.size());
      for (std::size_t i = 0; i < block.size(); ++i) marked[i] = least_first[block[i]];
      x = leastFirst(decomposition, x, marked);
    }
    for (Eigen::Index i = 0; i < n; ++i)
      solution[static_cast<Eigen::Index>(block[unknown(i)])] = x[i];
  }
  return solution;
}

/// One linear condition on the group's response at contact `contact`, to be 0: its gap's
/// acceleration (`normal`) or its slip's acceleration along the tangent `direction`. With
/// impulses for forces the same conditions hold the velocities (closeContactVelocities), with
/// displacements the gaps (closeContactGaps).
struct Condition {
  std::size_t contact = 0;
  V3 direction = V3::Zero();
  bool normal = true;
};

/// The condition's value where the contact's gap accelerates by `gap` and its slip by `slip`.
Real conditionValue(const Condition& condition, Real gap, const V3& slip) {
  return condition.normal ? gap : condition.direction.dot(slip);
}

/// The conditions' matrix by its nonzero entries: (i, j) is condition i's value under unknown j
/// alone, at unit size. Column by column from each unknown's response (Group::respondToOne), so
/// in O(the nonzeros): a condition changes only where its contact shares a movable body with
/// the unknown's.
std::vector<Entry> assembleConditions(const Group& group, const std::vector<Unknown>& unknowns,
                                      const std::vector<Condition>& conditions) {
  std::vector<std::vector<Eigen::Index>> conditions_of(group.contactCount());
  for (std::size_t i = 0; i < conditions.size(); ++i) {
    conditions_of[conditions[i].contact].push_back(static_cast<Eigen::Index>(i));
  }
  std::vector<Entry> entries;
  for (std::size_t u = 0; u < unknowns.size(); ++u) {
    const auto j = static_cast<Eigen::Index>(u);
    group.respondToOne(unknowns[u].contact, unknowns[u].pattern,
                       [&](std::size_t k, Real gap, const V3& slip) {
                         for (const Eigen::Index i : conditions_of[k]) {
                           const Condition& condition = conditions[static_cast<std::size_t>(i)];
                           entries.push_back(Entry{i, j, conditionValue(condition, gap, slip)});
                         }
                       });
  }
  return entries;
}

/// Each contact's force (on b) for the unknowns' sizes `solution`: the sum of its unknowns'
/// patterns times their sizes.
std::vector<V3> forcesOf(std::size_t count, const std::vector<Unknown>& unknowns,
                         const Vector& solution) {
  std::vector<V3> forces(count, V3::Zero());
  for (Eigen::Index j = 0; j < solution.size(); ++j) {
    const Unknown& unknown = unknowns[static_cast<std::size_t>(j)];
    forces[unknown.contact] += solution[j] * unknown.pattern;
  }
  return forces;
}

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

}  // namespace

void closeContactVelocities(std::vector<ForceBody>& bodies,
                            const std::vector<ForceContact>& contacts,
                            const std::vector<bool>& sticking) {
  // Impulses map to velocity changes as forces map to accelerations: the same response, with
  // no free terms. One condition per unknown: the normal relative velocity, and the slip along
  // each tangent of a sticking contact.
  const Group group(bodies, contacts);
  const std::size_t count = contacts.size();
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
  // Relative velocities within the rounding of the velocities need no closing.
  Real speed = 0, widest = 0;
  for (const ForceBody& body : bodies) {
    speed = std::max(speed, Real(body.velocity.lpNorm<Eigen::Infinity>() +
                                 body.radius * body.angular_velocity.lpNorm<Eigen::Infinity>()));
  }
  for (const Real target : targets) widest = std::max(widest, std::abs(target));
  if (widest <= std::numeric_limits<double>::epsilon() * speed) return;
  std::vector<Unknown> unknowns;  // an impulse along each condition's direction
  for (const Condition& condition : conditions) {
    unknowns.push_back(Unknown{condition.contact, condition.direction});
  }
  const std::vector<Entry> entries = assembleConditions(group, unknowns, conditions);
  Vector target(size);
  for (Eigen::Index i = 0; i < size; ++i) target[i] = targets[static_cast<std::size_t>(i)];
  const Vector solution = solveMinimumNorm(size, entries, target);
  const std::vector<V3> impulses = forcesOf(count, unknowns, solution);
  const Response change = group.respond(impulses, false);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].inverse_mass == 0.0) continue;
    bodies[i].velocity = (widen(bodies[i].velocity) + change.acceleration[i]).cast<double>();
    bodies[i].angular_velocity =
        (widen(bodies[i].angular_velocity) + change.angular_acceleration[i]).cast<double>();
  }
}

namespace {

/// A block's friction problem, dense: the minimum of E(x) = x'A x / 2 + s'x over the discs
/// |x_k| <= b_k (`coupling` A, `slip` s, `bound` b; x_k = x[2 k], x[2 k + 1] in contact k's
/// tangent basis).
struct DiscProblem {
  const Matrix& coupling;
  const Vector& slip;
  const std::vector<Real>& bound;

  Eigen::Index size() const { return slip.size(); }
  Eigen::Index discs() const { return slip.size() / 2; }
  Real b(Eigen::Index k) const { return bound[static_cast<std::size_t>(k)]; }
  Real energy(const Vector& x) const { return 0.5L * x.dot(coupling * x) + slip.dot(x); }
  /// b_k^2 - |x_k|^2: > 0 inside disc k.
  Real room(const Vector& x, Eigen::Index k) const {
    return b(k) * b(k) - x.segment<2>(2 * k).squaredNorm();
  }
};

/// The scale of the energies: what stopping every slip alone would remove.
Real energyScale(const DiscProblem& problem) {
  Real scale = 0;
  for (Eigen::Index i = 0; i < problem.size(); ++i) {
    scale = std::max(scale, std::abs(problem.slip[i]) * problem.b(i / 2));
  }
  return scale;
}

/// The contacts at their disc's edge take the bound exactly, against the slip A x + s they
/// leave.
void pressEdgesToBound(const DiscProblem& problem, const std::vector<char>& edge, Vector& x) {
  const Vector residual = problem.coupling * x + problem.slip;  // the slips left
  for (Eigen::Index k = 0; k < problem.discs(); ++k) {
    if (!edge[static_cast<std::size_t>(k)]) continue;
    const Eigen::Matrix<Real, 2, 1> left = residual.segment<2>(2 * k);
    const Real b = problem.b(k);
    if (left.norm() > 0) {
      x.segment<2>(2 * k) = -b * left.normalized();
    } else if (x.segment<2>(2 * k).norm() > b) {
      x.segment<2>(2 * k) *= b / x.segment<2>(2 * k).norm();
    }
  }
}

/// The contacts inside their discs stop their slip exactly, the edge ones' impulses given: the
/// rows of A x + s = 0 of the inner unknowns, solved for them (least squares, minimum norm).
void stopInnerSlips(const DiscProblem& problem, const std::vector<char>& edge, Vector& x) {
  std::vector<Eigen::Index> inner;
  for (Eigen::Index i = 0; i < problem.size(); ++i) {
    if (!edge[static_cast<std::size_t>(i / 2)]) inner.push_back(i);
  }
  if (inner.empty()) return;
  const auto n = static_cast<Eigen::Index>(inner.size());
  Matrix system(n, n);
  Vector target(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    target[r] = -problem.slip[inner[r]];
    for (Eigen::Index j = 0; j < problem.size(); ++j) {
      if (edge[static_cast<std::size_t>(j / 2)]) {
        target[r] -= problem.coupling(inner[r], j) * x[j];
      }
    }
    for (Eigen::Index c = 0; c < n; ++c) system(r, c) = problem.coupling(inner[r], inner[c]);
  }
  const Vector solved = system.completeOrthogonalDecomposition().solve(target);
  for (Eigen::Index r = 0; r < n; ++r) x[inner[r]] = solved[r];
}

/// Whether Coulomb's conditions hold at x: an edge contact's impulse against the slip left
/// (not reversing it), an inner one within its bound with its slip stopped; and whether an edge
/// impulse has yet to settle along the slip left (to within rounding).
struct CoulombVerdict {
  bool holds = true;
  bool moved = false;
};

CoulombVerdict coulombVerdict(const DiscProblem& problem, const std::vector<char>& edge,
                              const Vector& x) {
  const Vector left = problem.coupling * x + problem.slip;
  CoulombVerdict verdict;
  for (Eigen::Index k = 0; k < problem.discs() && verdict.holds; ++k) {
    const Real b = problem.b(k);
    const Eigen::Matrix<Real, 2, 1> xk = x.segment<2>(2 * k), lk = left.segment<2>(2 * k);
    if (edge[static_cast<std::size_t>(k)]) {
      if (lk.norm() == 0) continue;
      verdict.holds = xk.dot(lk) <= 0;
      if ((xk / b + lk.normalized()).norm() > 1e-15L) verdict.moved = true;
    } else {
      verdict.holds = xk.norm() <= b && lk.norm() <= 1e-15L * (problem.slip.norm() + 1);
    }
  }
  return verdict;
}

/// Where a condition fails, the contact changes sides (all at once): an inner one beyond its
/// bound goes to the edge, an edge one whose impulse would reverse the slip goes inside.
void switchSides(const DiscProblem& problem, const Vector& x, std::vector<char>& edge) {
  const Vector left = problem.coupling * x + problem.slip;
  for (Eigen::Index k = 0; k < problem.discs(); ++k) {
    const Real b = problem.b(k);
    const Eigen::Matrix<Real, 2, 1> xk = x.segment<2>(2 * k), lk = left.segment<2>(2 * k);
    char& on_edge = edge[static_cast<std::size_t>(k)];
    if (!on_edge && xk.norm() > b) {
      on_edge = 1;
    } else if (on_edge && xk.dot(lk) > 0) {
      on_edge = 0;
    }
  }
}

/// The dense solve's steps (a factorisation of the block's matrix: the sticking solve, a round of
/// polishing, a Newton step) that a bound on the impact's work leaves it (WorkBound), and how
/// many it took.
struct DenseSteps {
  std::size_t left = std::numeric_limits<std::size_t>::max();
  std::size_t taken = 0;
  bool cut = false;  ///< a step was wanted with none left
  /// One more step: false (and cut) where none is left.
  bool take() {
    if (taken >= left) {
      cut = true;
      return false;
    }
    ++taken;
    return true;
  }
};

/// Coulomb's conditions for a given set of contacts at their disc's edge: those take the bound
/// exactly, against the slip they leave; the others stop their slip exactly (a linear solve);
/// repeated while the edge directions move. True (and `x` set) when they then hold; else `x` is
/// the last attempt and `edge` switched where a condition failed.
bool polishCoulomb(const DiscProblem& problem, Vector& x, std::vector<char>& edge,
                   DenseSteps& steps) {
  Vector polished = x;
  for (int round = 0; round < 8; ++round) {
    if (!steps.take()) return false;
    pressEdgesToBound(problem, edge, polished);
    stopInnerSlips(problem, edge, polished);
    const CoulombVerdict verdict = coulombVerdict(problem, edge, polished);
    if (verdict.holds && !verdict.moved) {
      x = polished;
      return true;
    }
    if (!verdict.holds) break;
  }
  switchSides(problem, polished, edge);
  x = polished;
  return false;
}

/// The barrier objective t E(y) - sum_k log(b_k^2 - |y_k|^2).
Real barrierObjective(const DiscProblem& problem, Real t, const Vector& y) {
  Real value = t * problem.energy(y);
  for (Eigen::Index k = 0; k < problem.discs(); ++k) value -= std::log(problem.room(y, k));
  return value;
}

/// One damped Newton step on the barrier objective at x for weight t: false where it no longer
/// decreases (the decrement below 1e-20, or no step length that stays inside every disc and
/// decreases it by a quarter of the decrement times the length: Armijo backtracking).
bool newtonStep(const DiscProblem& problem, Real t, Vector& x) {
  Vector gradient = t * (problem.coupling * x + problem.slip);
  Matrix hessian = t * problem.coupling;
  for (Eigen::Index k = 0; k < problem.discs(); ++k) {
    // -log g, g = b^2 - |x_k|^2: gradient 2 x_k / g, Hessian 2 I / g + 4 x_k x_k' / g^2.
    const Real g = problem.room(x, k);
    const Eigen::Matrix<Real, 2, 1> xk = x.segment<2>(2 * k);
    gradient.segment<2>(2 * k) += (2 / g) * xk;
    hessian.block<2, 2>(2 * k, 2 * k) +=
        (2 / g) * Eigen::Matrix<Real, 2, 2>::Identity() + (4 / (g * g)) * xk * xk.transpose();
  }
  const Vector step = -hessian.ldlt().solve(gradient);
  const Real decrement = -gradient.dot(step);
  if (!(decrement > 1e-20L)) return false;
  const Real here = barrierObjective(problem, t, x);
  Real length = 1;
  for (int halving = 0; halving < 60; ++halving, length *= 0.5L) {
    const Vector y = x + length * step;
    bool inside = true;
    for (Eigen::Index k = 0; k < problem.discs() && inside; ++k) inside = problem.room(y, k) > 0;
    if (inside && barrierObjective(problem, t, y) <= here - 0.25L * length * decrement) {
      x = y;
      return true;
    }
  }
  return false;
}

/// The primal barrier method (Boyd and Vandenberghe, "Convex Optimization", 2004, section
/// 11.3): from x = 0, Newton's method on t E(x) - sum log(b^2 - |x_k|^2) for t growing tenfold,
/// until the duality gap discs / t is below 1e-14 of the energies (nearer the discs' edges
/// b^2 - |x|^2 loses its digits). Where A is singular the barrier tends to the centre of the
/// optimal set, so the answer depends on no order.
///
/// Stopped short (no `steps` left), x is still inside every disc and E(x) <= 0: each Newton step
/// lowers t E - sum log(b^2 - |x|^2), whose log part is least at x = 0, so t E(x) stays below
/// what the log part gained, and a larger t keeps it so.
Vector barrierMinimum(const DiscProblem& problem, DenseSteps& steps) {
  const Real scale = energyScale(problem);
  Vector x = Vector::Zero(problem.size());
  Real t = 1 / std::max(scale, Real(1e-300));
  const Real gap_wanted = 1e-14L * std::max(scale, Real(1e-300));
  for (int outer = 0; outer < 40; ++outer) {
    for (int newton = 0; newton < 50; ++newton) {
      if (!steps.take()) return x;
      if (!newtonStep(problem, t, x)) break;
    }
    if (Real(problem.discs()) / t < gap_wanted) break;
    t *= 10;
  }
  return x;
}

/// The friction impulses x (each contact's, in its tangent basis: x[2 k], x[2 k + 1]) of a block
/// small enough for dense algebra: the minimum of E(x) = x'A x / 2 + s'x over the discs
/// |x_k| <= b_k (`coupling` A, `slip` s, `bound` b). First Coulomb's conditions solved exactly
/// from the sticking answer (fast, and usually right at once); where they do not settle, a
/// primal barrier method (barrierMinimum, in long double), then the same exact conditions from
/// its answer.
///
/// `steps`: what a bound on the impact's work leaves (DenseSteps). Stopped short before the
/// barrier method, no friction (x = 0); within it, its last iterate, inside every disc, where
/// its energy is at most E(0) = 0 (else x = 0); in the last polish, the barrier's answer;
/// `steps.cut` says so.
Vector frictionByBarrier(const Matrix& coupling, const Vector& slip, const std::vector<Real>& bound,
                         DenseSteps& steps) {
  const DiscProblem problem{coupling, slip, bound};
  const Eigen::Index disc = problem.discs();
  if (!steps.take()) return Vector::Zero(slip.size());
  Vector x = coupling.completeOrthogonalDecomposition().solve(-slip);  // sticking everywhere
  std::vector<char> edge(static_cast<std::size_t>(disc), 0);
  for (Eigen::Index k = 0; k < disc; ++k) {
    edge[static_cast<std::size_t>(k)] = x.segment<2>(2 * k).norm() > problem.b(k);
  }
  bool settled = false;
  for (int attempt = 0; attempt < 8 && !settled && !steps.cut; ++attempt) {
    settled = polishCoulomb(problem, x, edge, steps);
  }
  if (settled) return x;
  if (steps.cut) return Vector::Zero(slip.size());
  x = barrierMinimum(problem, steps);
  if (steps.cut) return problem.energy(x) <= 0 ? x : Vector::Zero(slip.size());
  for (Eigen::Index k = 0; k < disc; ++k) {
    edge[static_cast<std::size_t>(k)] = x.segment<2>(2 * k).norm() >= problem.b(k) * (1 - 1e-8L);
  }
  Vector polished = x;
  if (polishCoulomb(problem, polished, edge, steps)) x = polished;
  return x;
}

/// A block's tangential coupling row by row: for each unknown (a contact's first or second
/// tangent: 2 k and 2 k + 1 in the block's numbering), its nonzero (column, A_ij).
using CouplingRows = std::vector<std::vector<std::pair<Eigen::Index, Real>>>;

/// Relative to the largest slip, the projected-gradient residual at which the iterative friction
/// solve stops (doc/model.md, "Work per message, and threads").
constexpr Real kFrictionResidual = 1e-12L;
/// The iterative friction solve's iterations at most.
constexpr int kFrictionIterations = 10000;

/// The friction impulses of a block too large for dense algebra (more than kDenseBlockContacts
/// contacts): the minimum of E(x) = x'A x / 2 + s'x over the discs |x_k| <= b_k by an
/// accelerated projected gradient (Beck and Teboulle, "A fast iterative shrinkage-thresholding
/// algorithm for linear inverse problems", SIAM J. Imaging Sci. 2009), its momentum restarted
/// wherever it points against the step taken (O'Donoghue and Candes, "Adaptive restart for
/// accelerated gradient schemes", Found. Comput. Math. 2015). The step is 1/L with
/// L = max_i sum_j |A_ij|, at least A's largest eigenvalue (Gershgorin). A x is built row by row
/// from A's nonzeros: an iteration costs O(the block's nonzeros).
///
/// Every iterate is a projection onto the discs, so whatever the iteration reaches, |x_k| <= b_k
/// (to the rounding of one scaling). It stops where the projected-gradient residual
/// L |x - P(x - (A x + s) / L)| (per contact; 0 exactly where x is the minimum: Coulomb's law,
/// the slip stopped inside the disc, at the bound against the slip left on its edge) is at most
/// kFrictionResidual of the largest slip, returning true; else at a fixed point of the rounded
/// step or after `max_iterations` (kFrictionIterations, or fewer where the impact's work is
/// bounded: WorkBound), returning false; `iterations` says how many it took. The last iterate is
/// returned where its energy is at most E(0) = 0 (friction adds no energy), else the iterate of the
/// lowest energy (x = 0 at worst), returning false. Every sum (rows of A x, the energy, dot
/// products, the bound) is order-free and sign-symmetric (orderFreeSum), so renaming the bodies or
/// mirroring the cluster changes no bit. A block's friction problem by A's nonzeros (CouplingRows),
/// every sum order-free.
class SparseDiscProblem {
 public:
  SparseDiscProblem(const CouplingRows& rows, const Vector& slip, const std::vector<Real>& bound)
      : rows_(rows), slip_(slip), bound_(bound) {}

  Eigen::Index size() const { return slip_.size(); }
  Eigen::Index discs() const { return slip_.size() / 2; }

  /// A v, row by row.
  Vector apply(const Vector& v) {
    Vector out(size());
    for (Eigen::Index i = 0; i < size(); ++i) {
      terms_.clear();
      for (const auto& [j, value] : rows_[static_cast<std::size_t>(i)]) {
        terms_.push_back(value * v[j]);
      }
      out[i] = orderFreeSum(terms_);
    }
    return out;
  }
  /// E(v), A v given.
  Real energy(const Vector& v, const Vector& coupled) {
    terms_.clear();
    for (Eigen::Index i = 0; i < size(); ++i) {
      terms_.push_back(v[i] * (0.5L * coupled[i] + slip_[i]));
    }
    return orderFreeSum(terms_);
  }
  Real dot(const Vector& u, const Vector& v) {
    terms_.clear();
    for (Eigen::Index i = 0; i < size(); ++i) terms_.push_back(u[i] * v[i]);
    return orderFreeSum(terms_);
  }
  /// L = max_i sum_j |A_ij|: at least A's largest eigenvalue (Gershgorin).
  Real lipschitz() {
    Real bound = 0;
    for (Eigen::Index i = 0; i < size(); ++i) {
      terms_.clear();
      for (const auto& entry : rows_[static_cast<std::size_t>(i)]) {
        terms_.push_back(std::abs(entry.second));
      }
      bound = std::max(bound, orderFreeSum(terms_));
    }
    return bound;
  }
  Real largestSlip() const {
    Real largest = 0;
    for (Eigen::Index k = 0; k < discs(); ++k) {
      largest = std::max(largest, slip_.segment<2>(2 * k).norm());
    }
    return largest;
  }
  /// P(v - (A v + s) / L), A v given: a gradient step of length 1/L projected onto the discs.
  Vector projectedStep(const Vector& v, const Vector& coupled, Real lipschitz) const {
    Vector step = v - (coupled + slip_) / lipschitz;
    for (Eigen::Index k = 0; k < discs(); ++k) {
      const Real length = step.segment<2>(2 * k).norm(), b = bound_[static_cast<std::size_t>(k)];
      if (length > b) step.segment<2>(2 * k) *= b / length;
    }
    return step;
  }
  /// The projected-gradient residual L |v - P(v - (A v + s) / L)|, its largest per contact.
  Real residual(const Vector& v, const Vector& coupled, Real lipschitz) const {
    const Vector step = projectedStep(v, coupled, lipschitz);
    Real worst = 0;
    for (Eigen::Index k = 0; k < discs(); ++k) {
      worst = std::max(worst, lipschitz * (v.segment<2>(2 * k) - step.segment<2>(2 * k)).norm());
    }
    return worst;
  }

 private:
  const CouplingRows& rows_;
  const Vector& slip_;
  const std::vector<Real>& bound_;
  std::vector<Real> terms_;  // the sums' terms (orderFreeSum orders them in place)
};

/// The accelerated iteration's state: the last iterate x, where the next step starts (x plus
/// momentum) y, each with its A times it, and the momentum's weight.
struct AcceleratedIterate {
  Vector x, coupled_x, y, coupled_y;
  Real momentum = 1;
};

/// The iteration moves on to z (A z given): its momentum restarted where it points against the
/// step taken (O'Donoghue and Candes), else carried by Beck and Teboulle's weights
/// m' = (1 + sqrt(1 + 4 m^2)) / 2, y = z + (m - 1) / m' (z - x).
void advance(SparseDiscProblem& problem, Vector z, const Vector& coupled_z,
             AcceleratedIterate& it) {
  if (problem.dot(it.y - z, z - it.x) > 0) {
    it.y = z;
    it.coupled_y = coupled_z;
    it.momentum = 1;
  } else {
    const Real next = (1 + std::sqrt(1 + 4 * it.momentum * it.momentum)) / 2;
    const Real carried = (it.momentum - 1) / next;
    it.y = z + carried * (z - it.x);
    it.coupled_y = coupled_z + carried * (coupled_z - it.coupled_x);  // A y, by linearity
    it.momentum = next;
  }
  it.x = std::move(z);
  it.coupled_x = coupled_z;
}

bool frictionByProjectedGradient(const CouplingRows& rows, const Vector& slip,
                                 const std::vector<Real>& bound, int max_iterations,
                                 Vector& solution, int& iterations) {
  SparseDiscProblem problem(rows, slip, bound);
  const Eigen::Index size = problem.size();
  const Real lipschitz = problem.lipschitz();
  const Real largest_slip = problem.largestSlip();
  solution = Vector::Zero(size);
  if (!(lipschitz > 0)) return false;  // no contact moves a body: no impulse does anything
  const Real tolerance = kFrictionResidual * largest_slip;
  AcceleratedIterate it{Vector::Zero(size), Vector::Zero(size), Vector::Zero(size),
                        Vector::Zero(size)};
  Vector lowest = it.x;  // the iterate of the lowest energy so far
  Real lowest_energy = 0, energy_x = 0;
  bool settled = false;
  iterations = 0;
  for (int iteration = 0; iteration < max_iterations && !settled; ++iteration) {
    Vector z = problem.projectedStep(it.y, it.coupled_y, lipschitz);
    const Vector coupled_z = problem.apply(z);
    energy_x = problem.energy(z, coupled_z);
    if (energy_x <= lowest_energy) {
      lowest = z;
      lowest_energy = energy_x;
    }
    // Or a fixed point of the rounding.
    settled = problem.residual(z, coupled_z, lipschitz) <= tolerance || z == it.x;
    advance(problem, std::move(z), coupled_z, it);
    ++iterations;
  }
  if (energy_x <= 0) {
    solution = it.x;
    return problem.residual(it.x, it.coupled_x, lipschitz) <= tolerance;
  }
  solution = lowest;
  return false;
}

/// The contacts of an impact that can take friction: a bound mu J > 0 and a slip.
struct FrictionContacts {
  std::vector<std::size_t> active;  // their indices
  std::vector<Real> bound;          // per active contact: mu J
  std::vector<long> slot;           // per contact: its place in `active`, -1 if not there
};

FrictionContacts frictionContacts(const Group& group, const std::vector<ForceContact>& contacts,
                                  const std::vector<double>& normal_impulses) {
  FrictionContacts friction;
  friction.slot.assign(contacts.size(), -1);
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const Real b = Real(contacts[k].friction) * Real(normal_impulses[k]);
    if (b > 0 && group.slip(k).norm() > 0) {
      friction.slot[k] = static_cast<long>(friction.active.size());
      friction.active.push_back(k);
      friction.bound.push_back(b);
    }
  }
  return friction;
}

/// Contact k's tangent t (0: first, 1: second).
const V3& tangentOf(const Group& group, std::size_t k, Eigen::Index t) {
  return t == 0 ? group.first(k) : group.second(k);
}

/// The tangential coupling of the active contacts: per active contact l, what a unit impulse
/// along each of its tangents does to the slips of the active contacts m it shares a movable
/// body with, C(m, l) (row: m's tangents; column: l's), sorted by m; and the blocks of contacts
/// so connected. Built column by column from each unknown's response (Group::respondToOne), in
/// O(its nonzeros).
class TangentialCoupling {
 public:
  using Block = Eigen::Matrix<Real, 2, 2>;
  using Column = std::vector<std::pair<std::size_t, Block>>;

  TangentialCoupling(const Group& group, const FrictionContacts& friction)
      : columns_(friction.active.size()), connected_(friction.active.size()) {
    for (std::size_t l = 0; l < friction.active.size(); ++l) {
      for (Eigen::Index t = 0; t < 2; ++t) {
        std::size_t visited = 0;  // respondToOne visits in the same order for either force
        group.respondToOne(friction.active[l], tangentOf(group, friction.active[l], t),
                           [&](std::size_t k, Real, const V3& slip_change) {
                             if (friction.slot[k] < 0) return;
                             const auto m = static_cast<std::size_t>(friction.slot[k]);
                             if (t == 0) {
                               columns_[l].emplace_back(m, Block::Zero());
                               connected_.link(l, m);
                             }
                             Block& entry = columns_[l][visited++].second;
                             entry(0, t) = group.first(k).dot(slip_change);
                             entry(1, t) = group.second(k).dot(slip_change);
                           });
      }
      std::sort(columns_[l].begin(), columns_[l].end(),
                [](const auto& p, const auto& q) { return p.first < q.first; });
    }
  }

  /// The blocks: sets of active contacts connected through shared movable bodies.
  std::vector<std::vector<std::size_t>> blocks() { return connected_.sets(); }
  /// The active contacts m whose slips contact l's impulses change (m, C(m, l)), by m.
  const Column& column(std::size_t l) const { return columns_[l]; }

  /// The symmetric coupling A(m, l) = (C(m, l) + C(l, m)') / 2 (C is symmetric up to rounding),
  /// row r of m's tangents, column c of l's.
  Real operator()(std::size_t m, std::size_t l, Eigen::Index r, Eigen::Index c) const {
    const Column& column = columns_[l];
    const Column& row = columns_[m];
    const auto at = [](const Column& list, std::size_t key) {
      return std::lower_bound(list.begin(), list.end(), key,
                              [](const auto& p, std::size_t value) { return p.first < value; });
    };
    const auto forward = at(column, m);
    const auto backward = at(row, l);
    const Real there = forward != column.end() && forward->first == m ? forward->second(r, c) : 0;
    const Real back = backward != row.end() && backward->first == l ? backward->second(c, r) : 0;
    return 0.5L * (there + back);
  }

 private:
  std::vector<Column> columns_;
  ConnectedSets connected_;
};

/// Visits every coupling entry of a block, visit(row, column, A_ij), in the block's numbering
/// (contact p of the block: unknowns 2 p and 2 p + 1; `place`: each active contact's p).
template <class Visit>
void forEachCouplingEntry(const TangentialCoupling& coupling, const std::vector<std::size_t>& block,
                          const std::vector<Eigen::Index>& place, Visit visit) {
  for (std::size_t q = 0; q < block.size(); ++q) {
    const std::size_t l = block[q];
    const auto column = static_cast<Eigen::Index>(2 * q);
    for (const auto& entry : coupling.column(l)) {
      for (Eigen::Index r = 0; r < 2; ++r) {
        for (Eigen::Index c = 0; c < 2; ++c) {
          visit(2 * place[entry.first] + r, column + c, coupling(entry.first, l, r, c));
        }
      }
    }
  }
}

/// A block's friction problem in its numbering (contact p of the block: unknowns 2 p, 2 p + 1):
/// the slips s in the contacts' tangent bases and the bounds b.
struct BlockProblem {
  Vector slip;
  std::vector<Real> bound;
};

/// The block's problem; `place` takes each of its contacts' p.
BlockProblem setUpBlock(const Group& group, const FrictionContacts& friction,
                        const std::vector<std::size_t>& block, std::vector<Eigen::Index>& place) {
  const auto n = static_cast<Eigen::Index>(block.size());
  BlockProblem problem{Vector(2 * n), std::vector<Real>(block.size())};
  for (Eigen::Index p = 0; p < n; ++p) {
    const std::size_t l = block[static_cast<std::size_t>(p)];
    place[l] = p;
    problem.bound[static_cast<std::size_t>(p)] = friction.bound[l];
    for (Eigen::Index t = 0; t < 2; ++t) {
      problem.slip[2 * p + t] =
          tangentOf(group, friction.active[l], t).dot(group.slip(friction.active[l]));
    }
  }
  return problem;
}

/// The block's impulses x (in its numbering) onto each contact's tangents: its impulse on b.
void addBlockImpulses(const Group& group, const FrictionContacts& friction,
                      const std::vector<std::size_t>& block, const Vector& x,
                      std::vector<V3>& impulses) {
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const std::size_t k = friction.active[block[static_cast<std::size_t>(j / 2)]];
    impulses[k] += x[j] * tangentOf(group, k, j % 2);
  }
}

/// A block's friction impulses x (in its numbering), by dense algebra up to kDenseBlockContacts
/// contacts (frictionByBarrier), above by the accelerated projected gradient
/// (frictionByProjectedGradient; false where it stops short of its residual).
///
/// `work` (optional): what the block may spend and spent (solveFrictionImpulses; WorkBound's
/// units: an iteration of the projected gradient costs the block's contacts, a step of the dense
/// solve, frictionByBarrier's factorisation and its line search, WorkBound::denseStep). A block
/// reached with too little left for a step gets no friction (x = 0); one that runs out stops
/// where its solve got to.
bool frictionOfBlock(const TangentialCoupling& coupling, const std::vector<std::size_t>& block,
                     const std::vector<Eigen::Index>& place, const Vector& slip,
                     const std::vector<Real>& bound, WorkBound* work, Vector& x) {
  const std::size_t left = work == nullptr ? std::numeric_limits<std::size_t>::max() : work->left();
  if (block.size() <= kDenseBlockContacts) {
    const std::size_t step_cost = WorkBound::denseStep(block.size());
    DenseSteps steps;
    if (left != std::numeric_limits<std::size_t>::max()) steps.left = left / step_cost;
    Matrix dense = Matrix::Zero(slip.size(), slip.size());
    forEachCouplingEntry(coupling, block, place,
                         [&](Eigen::Index i, Eigen::Index j, Real value) { dense(i, j) = value; });
    x = frictionByBarrier(dense, slip, bound, steps);
    if (work != nullptr) {
      work->spent += steps.taken * step_cost;
      work->cut = work->cut || steps.cut;
    }
    return !steps.cut;
  }
  const int allowed = static_cast<int>(
      std::min<std::size_t>(left / block.size(), static_cast<std::size_t>(kFrictionIterations)));
  if (allowed == 0) {
    work->cut = true;
    x = Vector::Zero(slip.size());
    return false;
  }
  CouplingRows rows(static_cast<std::size_t>(slip.size()));
  forEachCouplingEntry(coupling, block, place, [&](Eigen::Index i, Eigen::Index j, Real value) {
    if (value != 0) rows[static_cast<std::size_t>(i)].emplace_back(j, value);
  });
  int iterations = 0;
  const bool converged = frictionByProjectedGradient(rows, slip, bound, allowed, x, iterations);
  if (work != nullptr) {
    work->spent += static_cast<std::size_t>(iterations) * block.size();
    if (!converged && allowed < kFrictionIterations && iterations == allowed) work->cut = true;
  }
  return converged;
}

/// The answer in doubles: each contact's impulse (in `tangential`), slip, slip change and mode
/// (sticking where the impulse stays within its bound), each body's change of velocity (in
/// `acceleration`) and of angular velocity (in `angular_acceleration`).
ContactForceSolution storeFrictionImpulses(const Group& group, const FrictionContacts& friction,
                                           const std::vector<V3>& impulses, std::size_t body_count,
                                           bool converged) {
  const Response change = group.respond(impulses, false);
  ContactForceSolution result;
  result.converged = converged;
  result.contacts.resize(impulses.size());
  for (std::size_t k = 0; k < impulses.size(); ++k) {
    ContactForce& out = result.contacts[k];
    out.tangential = impulses[k].cast<double>();
    out.slip = group.slip(k).cast<double>();
    out.slip_acceleration = change.slip_acceleration[k].cast<double>();
    if (friction.slot[k] < 0) {
      out.mode = ContactMode::kSeparating;
    } else {
      const Real b = friction.bound[static_cast<std::size_t>(friction.slot[k])];
      out.mode =
          impulses[k].norm() < b * (1 - 1e-9L) ? ContactMode::kSticking : ContactMode::kSliding;
    }
  }
  result.acceleration.resize(body_count);
  result.angular_acceleration.resize(body_count);
  for (std::size_t i = 0; i < body_count; ++i) {
    result.acceleration[i] = change.acceleration[i].cast<double>();
    result.angular_acceleration[i] = change.angular_acceleration[i].cast<double>();
  }
  return result;
}

}  // namespace

ContactForceSolution solveFrictionImpulses(const std::vector<ForceBody>& bodies,
                                           const std::vector<ForceContact>& contacts,
                                           const std::vector<double>& normal_impulses,
                                           WorkBound* work) {
  // Maximal dissipation: the tangential impulses x (on each contact's b, in its tangent basis)
  // minimise the kinetic energy they leave, E(x) = x'A x / 2 + s'x (A the tangential coupling,
  // s the slips; E is exactly the change of kinetic energy), over the discs |x_k| <= mu_k J_k.
  // Its minimum is Coulomb's law: where the disc's inside holds it the slip stops (A x + s = 0),
  // elsewhere the impulse is at the bound against the slip left. E(x) <= E(0) = 0: friction
  // never adds energy. A_kl = 0 unless contacts k and l share a movable body, so E is a sum over
  // the blocks of contacts connected through shared movable bodies, each minimised on its own
  // (exact): by dense algebra up to kDenseBlockContacts contacts (frictionByBarrier), above by
  // an accelerated projected gradient to a documented residual (frictionByProjectedGradient).
  // A is built column by column from each unknown's response (Group::respondToOne), in
  // O(its nonzeros).
  const Group group(bodies, contacts);
  const FrictionContacts friction = frictionContacts(group, contacts, normal_impulses);
  TangentialCoupling coupling(group, friction);
  std::vector<V3> impulses(contacts.size(), V3::Zero());
  bool converged = true;
  std::vector<Eigen::Index> place(friction.active.size(), -1);  // each one's place in its block
  for (const std::vector<std::size_t>& block : coupling.blocks()) {
    const BlockProblem problem = setUpBlock(group, friction, block, place);
    Vector x;
    converged =
        frictionOfBlock(coupling, block, place, problem.slip, problem.bound, work, x) && converged;
    addBlockImpulses(group, friction, block, x, impulses);
  }
  return storeFrictionImpulses(group, friction, impulses, bodies.size(), converged);
}

void closeContactGaps(std::vector<Eigen::Vector3d>& positions, const std::vector<ForceBody>& bodies,
                      const std::vector<ForceContact>& contacts, const std::vector<double>& gaps) {
  // Displacements d = w sum_k s_k mu_k n_k change gap_l by sum_k A_lk mu_k, as impulses change the
  // normal relative velocities: the same linear map.
  const auto size = static_cast<Eigen::Index>(contacts.size());
  if (size == 0) return;
  // Gaps within the rounding of the positions need no closing: the displacements would be
  // below an ulp of the positions they are added to.
  double reach = 0.0, widest = 0.0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    reach = std::max(reach, positions[i].lpNorm<Eigen::Infinity>() + bodies[i].radius);
  }
  for (const double gap : gaps) widest = std::max(widest, std::abs(gap));
  if (widest <= std::numeric_limits<double>::epsilon() * reach) return;
  const Group group(bodies, contacts);
  std::vector<Unknown> unknowns;      // a displacement along each normal
  std::vector<Condition> conditions;  // each gap
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    unknowns.push_back(Unknown{k, group.normal(k)});
    conditions.push_back(Condition{k, group.normal(k), true});
  }
  const std::vector<Entry> entries = assembleConditions(group, unknowns, conditions);
  Vector target(size);
  for (Eigen::Index i = 0; i < size; ++i) target[i] = -Real(gaps[static_cast<std::size_t>(i)]);
  const Vector solution = solveMinimumNorm(size, entries, target);
  const std::vector<V3> pushes = forcesOf(contacts.size(), unknowns, solution);
  const Response change = group.respond(pushes, false);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].inverse_mass == 0.0) continue;
    positions[i] = (widen(positions[i]) + change.acceleration[i]).cast<double>();
  }
}

namespace {

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
