// What the contact solvers of this room share (contact_forces.cpp, friction_impulses.cpp,
// contact_projection.cpp): a group of bodies and contacts in long double, its response to forces
// or impulses at the contacts, and the minimum-norm solve of linear conditions on that response.
// Internal to src/core/solver/: its callers include contact_forces.h and the others.
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <vector>

#include "solver/contact_forces.h"
#include "solver/impulse_response.h"

namespace collision_response::core::contact_group {

using Real = long double;  // 11 bits more than double: the answer is rounded once, at the end
using V3 = Eigen::Matrix<Real, 3, 1>;
using Matrix = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;
using Vector = Eigen::Matrix<Real, Eigen::Dynamic, 1>;

inline V3 widen(const Eigen::Vector3d& v) { return v.cast<Real>(); }

/// Two unit vectors spanning the plane perpendicular to the unit `normal`.
void tangentBasis(const V3& normal, V3& first, V3& second);

/// What the group does under given contact forces: the bodies' accelerations and, per contact,
/// the gap's and the slip's accelerations. With `free`, gravity and the velocity terms are in.
struct Response {
  std::vector<V3> acceleration, angular_acceleration;
  std::vector<Real> gap_acceleration;
  std::vector<V3> slip_acceleration;
};

/// A group of touching bodies (ForceBody) and its contacts (ForceContact) in long double: each
/// contact's normal, tangent basis and slip, and the bodies' response to forces at the contacts.
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
      const V3 slip_full = relative - turningOf(contact, normal, widen(a.angular_velocity),
                                                widen(b.angular_velocity));
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
    accelerate(source.b, force, -normal_[j], source.lever_b, acceleration[1],
               angular_acceleration[1]);
    accelerate(source.a, -force, normal_[j], source.lever_a, acceleration[0],
               angular_acceleration[0]);
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
            relative - turningOf(contact, normal_[k], local(contact.a, angular_acceleration),
                                 local(contact.b, angular_acceleration));
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
      // b's contact point: -r_b n from its centre (a ball's), a's: +r_a n.
      push(r, contact.b, forces[k], -normal_[k], contact.lever_b);
      push(r, contact.a, -forces[k], normal_[k], contact.lever_a);
    }
    r.gap_acceleration.resize(contacts_.size());
    r.slip_acceleration.resize(contacts_.size());
    for (std::size_t k = 0; k < contacts_.size(); ++k) {
      const ForceContact& contact = contacts_[k];
      const V3 relative = r.acceleration[contact.b] - r.acceleration[contact.a];
      Real gap = normal_[k].dot(relative);
      V3 slip = relative - turningOf(contact, normal_[k], r.angular_acceleration[contact.a],
                                     r.angular_acceleration[contact.b]);
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
  /// The part of the slip at `contact` (normal `normal`) that its bodies' angular velocities
  /// (or accelerations) `w_a` and `w_b` make, subtracted from the relative velocity: w_a x r_a -
  /// w_b x r_b. Two balls: (R_a w_a + R_b w_b) x n, as the ball solvers always have (r_a = R_a
  /// n, r_b = -R_b n); where a side is given by its tensor, from the contact's lever arms.
  V3 turningOf(const ForceContact& contact, const V3& normal, const V3& w_a, const V3& w_b) const {
    const ForceBody& a = bodies_[contact.a];
    const ForceBody& b = bodies_[contact.b];
    if (a.inertia_kind == InverseInertiaKind::kIsotropic &&
        b.inertia_kind == InverseInertiaKind::kIsotropic) {
      return (Real(a.radius) * w_a + Real(b.radius) * w_b).cross(normal);
    }
    const auto side = [&](const ForceBody& body, const V3& w, const Eigen::Vector3d& lever,
                          const V3& outward) -> V3 {
      if (body.inertia_kind == InverseInertiaKind::kIsotropic) {
        return w.cross(Real(body.radius) * outward);
      }
      return w.cross(widen(lever));
    };
    return side(a, w_a, contact.lever_a, normal) - side(b, w_b, contact.lever_b, -normal);
  }

  /// Force `force` on body `i` at its contact point, `arm` from its centre (its lever arm; a
  /// ball's is r `outward`, outward +n for a, -n for b).
  void push(Response& r, std::size_t i, const V3& force, const V3& outward,
            const Eigen::Vector3d& arm) const {
    pushAt(r, i, i, force, outward, arm);
  }
  /// push() into slot `slot` of `r` for body `i`.
  void pushAt(Response& r, std::size_t slot, std::size_t i, const V3& force, const V3& outward,
              const Eigen::Vector3d& arm) const {
    accelerate(i, force, outward, arm, r.acceleration[slot], r.angular_acceleration[slot]);
  }
  /// What `force` at its contact point (`outward`, `arm`: push()) adds to body `i`'s
  /// accelerations: w F, and the moment arm x F over I (turnOf; for a ball r outward x F times
  /// 1/I = w / (k r^2)).
  void accelerate(std::size_t i, const V3& force, const V3& outward, const Eigen::Vector3d& arm,
                  V3& acceleration, V3& angular_acceleration) const {
    const ForceBody& body = bodies_[i];
    if (body.inverse_mass == 0.0) return;
    acceleration += Real(body.inverse_mass) * force;
    if (turns(body)) {
      angular_acceleration += turnOf<Real>(
          body, outward, [&] { return arm; }, force);
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

/// One nonzero entry of a conditions' matrix.
struct Entry {
  Eigen::Index row, column;
  Real value;
};

/// The minimum-norm least-squares solution of A x = target, A of `size` x `size` given by its
/// nonzero entries, block by block: the unknowns fall into connected sets (i and j connected
/// where A(i, j) or A(j, i) is not 0: their contacts share a movable body, directly or through
/// others), and a block-diagonal system's minimum-norm solution is each block's (a complete
/// orthogonal decomposition each). Exact, and independent of the order of the blocks; a group
/// whose contacts barely interact (balls side by side on a floor) is many small solves, not one
/// dense solve of every unknown. With `least_first` (one flag per unknown), where a block has
/// many solutions the marked unknowns' norm is the least first (leastFirst).
Vector solveMinimumNorm(Eigen::Index size, const std::vector<Entry>& entries, const Vector& target,
                        const std::vector<char>& least_first = {});

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
inline Real conditionValue(const Condition& condition, Real gap, const V3& slip) {
  return condition.normal ? gap : condition.direction.dot(slip);
}

/// The conditions' matrix by its nonzero entries: (i, j) is condition i's value under unknown j
/// alone, at unit size. Column by column from each unknown's response (Group::respondToOne), so
/// in O(the nonzeros): a condition changes only where its contact shares a movable body with
/// the unknown's.
std::vector<Entry> assembleConditions(const Group& group, const std::vector<Unknown>& unknowns,
                                      const std::vector<Condition>& conditions);

/// Each contact's force (on b) for the unknowns' sizes `solution`: the sum of its unknowns'
/// patterns times their sizes.
std::vector<V3> forcesOf(std::size_t count, const std::vector<Unknown>& unknowns,
                         const Vector& solution);

}  // namespace collision_response::core::contact_group
