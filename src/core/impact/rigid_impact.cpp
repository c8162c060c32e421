#include "collision_response/core/rigid_impact.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <tuple>
#include <utility>

#include "collision_response/core/friction.h"
#include "collision_response/core/impact.h"
#include "collision_response/core/validation.h"
#include "solver/effective_mass.h"
#include "solver/impulse_response.h"
#include "solver/order_free.h"

namespace collision_response::core {
namespace {

using RealL = long double;
using Vector3L = Eigen::Matrix<RealL, 3, 1>;
using Matrix3L = Eigen::Matrix<RealL, 3, 3>;

/// |n| = 1 to this: a normal that is a unit vector to the rounding of its computation.
constexpr double kUnitTolerance = 1e-9;

Status checkBodyForImpact(const SolverBody& body, const std::string& field) {
  if (!std::isfinite(body.inverse_mass) || body.inverse_mass < 0.0) {
    return Error{field + ".inverse_mass", "must be a finite number >= 0 (0: immovable), got " +
                                              formatNumber(body.inverse_mass)};
  }
  if (auto status = checkFinite(body.velocity, field + ".velocity"); !status) return status;
  if (auto status = checkFinite(body.angular_velocity, field + ".angular_velocity"); !status) {
    return status;
  }
  if (body.inertia_kind == InverseInertiaKind::kIsotropic) {
    if (!std::isfinite(body.spin_factor) || body.spin_factor < 0.0) {
      return Error{field + ".spin_factor",
                   "must be a finite number >= 0 (1/k of I = k m r^2; 0: does not turn), got " +
                       formatNumber(body.spin_factor)};
    }
    if (!std::isfinite(body.radius) || body.radius < 0.0) {
      return Error{field + ".radius",
                   "must be a finite number >= 0 m, got " + formatNumber(body.radius)};
    }
    return Ok{};
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double entry = body.inverse_inertia(i, j);
      if (!std::isfinite(entry) || (i == j && entry < 0.0)) {
        return Error{
            field + ".inverse_inertia(" + std::to_string(i) + ", " + std::to_string(j) + ")",
            i == j ? "a diagonal entry of I^-1 must be a finite number >= 0, got " +
                         formatNumber(entry)
                   : "must be a finite number, got " + formatNumber(entry)};
      }
    }
  }
  return Ok{};
}

/// The normal and lever arms of a contact, named `field` + "normal", ...
Status checkContactGeometry(const ContactPoint& contact, const std::string& field) {
  if (auto status = checkFinite(contact.normal, field + "normal"); !status) return status;
  if (!(std::abs(contact.normal.norm() - 1.0) <= kUnitTolerance)) {
    return Error{field + "normal", "must be a unit vector (to 1e-9), got " +
                                       formatVector(contact.normal) + " of length " +
                                       formatNumber(contact.normal.norm())};
  }
  if (auto status = checkFinite(contact.lever_a, field + "lever_a"); !status) return status;
  return checkFinite(contact.lever_b, field + "lever_b");
}

Status checkPair(const SolverBody& a, const SolverBody& b, const std::string& field_a,
                 const std::string& field_b) {
  if (auto status = checkBodyForImpact(a, field_a); !status) return status;
  if (auto status = checkBodyForImpact(b, field_b); !status) return status;
  if (a.inverse_mass == 0.0 && b.inverse_mass == 0.0) {
    return Error{field_b + ".inverse_mass",
                 "both sides of the contact are immovable (inverse mass 0): nothing can move"};
  }
  return Ok{};
}

/// I^-1 of a side as the law sees it: a ball's from its spin factor, 0 where it does not turn.
Matrix3L inverseInertiaOf(const SolverBody& body) {
  if (!turns(body)) return Matrix3L::Zero();
  if (body.inertia_kind == InverseInertiaKind::kIsotropic) {
    return sphereInverseInertia(body.inverse_mass, body.spin_factor, body.radius).cast<RealL>();
  }
  return body.inverse_inertia.cast<RealL>();
}

/// The velocity of `body`'s material point at lever arm `lever`: v + w x r.
Vector3L pointVelocity(const SolverBody& body, const Eigen::Vector3d& lever) {
  return body.velocity.cast<RealL>() +
         body.angular_velocity.cast<RealL>().cross(lever.cast<RealL>());
}

/// `impulse` (long double) on `body` at `lever`: v += w P, w += I^-1 (r x P), each rounded once.
void applyImpulse(SolverBody& body, const Eigen::Vector3d& lever, const Vector3L& impulse) {
  if (body.inverse_mass == 0.0) return;
  body.velocity = (body.velocity.cast<RealL>() + RealL(body.inverse_mass) * impulse).cast<double>();
  if (!turns(body)) return;
  body.angular_velocity = (body.angular_velocity.cast<RealL>() +
                           inverseInertiaOf(body) * lever.cast<RealL>().cross(impulse))
                              .cast<double>();
}

/// Today's single contact of two balls (cluster_solver.cpp, solveContact with the spin effect).
RigidImpactOutcome resolveBalls(SolverBody& a, SolverBody& b, const ContactPoint& contact,
                                double restitution, double friction) {
  RigidImpactOutcome outcome;
  const ImpactResponse<double> response = resolveImpact(a.inverse_mass, a.velocity, b.inverse_mass,
                                                        b.velocity, contact.normal, restitution);
  outcome.approach_speed = response.approach_speed;
  if (!response.approaching) return outcome;
  a.velocity = response.velocity_a;
  b.velocity = response.velocity_b;
  outcome.normal_impulse = response.normal_impulse;
  outcome.energy_lost = response.energy_lost;
  const Eigen::Vector3d slip = slipAt<true>(a, b, contact);
  outcome.sticking = !(slip.norm() > 0);
  if (friction > 0) {
    const FrictionOutcome sliding =
        applyFriction<true>(a, b, contact, friction, response.normal_impulse);
    outcome.sticking = outcome.sticking || sliding.sticking;
    if (sliding.impulse > 0) outcome.tangential_impulse = -sliding.impulse * (slip / slip.norm());
    outcome.energy_lost += sliding.energy_lost;
  }
  outcome.impulse = outcome.normal_impulse * contact.normal + outcome.tangential_impulse;
  return outcome;
}

}  // namespace

RigidImpactOutcome resolveRigidImpactByLaw(SolverBody& a, SolverBody& b,
                                           const ContactPoint& contact, double restitution,
                                           double friction, double tangential_restitution) {
  RigidImpactOutcome outcome;
  const Vector3L n = contact.normal.cast<RealL>();
  const Vector3L u0 = pointVelocity(b, contact.lever_b) - pointVelocity(a, contact.lever_a);
  const RealL normal_velocity = u0.dot(n);  // u_n
  outcome.approach_speed = static_cast<double>(-normal_velocity);
  if (!(normal_velocity < 0)) return outcome;

  const ContactSide side_a = contactSideOf(a, contact.lever_a);
  const ContactSide side_b = contactSideOf(b, contact.lever_b);
  const Matrix3L k = inverseEffectiveMass(side_a, side_b).cast<RealL>();
  // K n and n.K.n from each side's own terms, w n + (I^-1 (r x n)) x r, not from the matrix:
  // where a lever arm lies along n (a sphere) its rotational entries, ~r^2 / I, cancel along n
  // and would leave their rounding, which for I far below m r^2 swamps w (a negative impulse).
  const auto turnAlong = [&](const ContactSide& side) -> Vector3L {
    const Eigen::Vector3d arm = side.lever_arm.cross(contact.normal);
    return (side.inverse_inertia * arm).cross(side.lever_arm).cast<RealL>();
  };
  const Vector3L kn =
      RealL(side_a.inverse_mass + side_b.inverse_mass) * n + turnAlong(side_a) + turnAlong(side_b);
  const RealL nkn = inverseEffectiveMassAlong(side_a, side_b, contact.normal);
  const RealL plastic_normal = -normal_velocity / nkn;  // |P_I|, > 0
  // D = P_II - P_I = K^-1 (-u0 - K P_I): the sticking impulse's part that K holds orthogonal to n.
  const Vector3L d = k.ldlt().solve(-u0 - plastic_normal * kn);
  const RealL d_normal = d.dot(n);
  const RealL d_tangential = (d - d_normal * n).norm();

  const RealL e = restitution;
  const RealL one_plus_et = RealL(1) + RealL(tangential_restitution);
  const RealL mu = friction;
  const RealL frictionless_normal = (RealL(1) + e) * plastic_normal;  // (1 + e) |P_I|
  RealL kappa = one_plus_et;
  outcome.sticking =
      one_plus_et * d_tangential <= mu * (frictionless_normal + one_plus_et * d_normal);
  if (!outcome.sticking) {
    // On the cone: kappa |D_t| = mu ((1 + e) |P_I| + kappa D.n), whose denominator is > 0
    // where P^ lies outside (1 + e_t > 0 there); held in [0, 1 + e_t] against rounding.
    const RealL denominator = d_tangential - mu * d_normal;
    kappa = denominator > 0
                ? std::clamp(mu * frictionless_normal / denominator, RealL(0), one_plus_et)
                : RealL(0);
  }
  const Vector3L impulse = frictionless_normal * n + kappa * d;
  const RealL lost =
      RealL(0.5) * (RealL(1) - e) * (RealL(1) + e) * plastic_normal * (-normal_velocity) +
      RealL(0.5) * kappa * (RealL(2) - kappa) * d.dot(k * d);

  applyImpulse(a, contact.lever_a, -impulse);
  applyImpulse(b, contact.lever_b, impulse);
  outcome.impulse = impulse.cast<double>();
  // Its parts along n and across, from the law's own: P_I lies along n, D = D.n n + D_t (so
  // that a frictionless impact has no tangential part at all, whatever |n|'s rounding).
  outcome.normal_impulse = static_cast<double>(frictionless_normal + kappa * d_normal);
  outcome.tangential_impulse = (kappa * (d - d_normal * n)).cast<double>();
  outcome.energy_lost = static_cast<double>(lost);
  return outcome;
}

Expected<RigidImpactOutcome> resolveRigidImpact(SolverBody& a, SolverBody& b,
                                                const ContactPoint& contact, double restitution,
                                                double friction, double tangential_restitution) {
  if (auto status = checkContactGeometry(contact, "contact."); !status) return status.error();
  if (auto status = checkRestitution(restitution, "restitution"); !status) return status.error();
  if (auto status = checkFriction(friction, "friction"); !status) return status.error();
  if (!(tangential_restitution >= -1.0 && tangential_restitution <= 1.0)) {
    return Error{"tangential_restitution", "must be in [-1, 1] (0: the default), got " +
                                               formatNumber(tangential_restitution)};
  }
  if (auto status = checkPair(a, b, "a", "b"); !status) return status.error();
  SolverBody after_a = a, after_b = b;
  const RigidImpactOutcome outcome =
      a.inertia_kind == InverseInertiaKind::kIsotropic &&
              b.inertia_kind == InverseInertiaKind::kIsotropic && tangential_restitution == 0.0
          ? resolveBalls(after_a, after_b, contact, restitution, friction)
          : resolveRigidImpactByLaw(after_a, after_b, contact, restitution, friction,
                                    tangential_restitution);
  if (auto status = checkRepresentable({namedResult("a.velocity", after_a.velocity),
                                        namedResult("a.angular_velocity", after_a.angular_velocity),
                                        namedResult("b.velocity", after_b.velocity),
                                        namedResult("b.angular_velocity", after_b.angular_velocity),
                                        namedResult("impulse", outcome.impulse),
                                        namedResult("energy_lost", outcome.energy_lost)});
      !status) {
    return status.error();
  }
  a = after_a;
  b = after_b;
  return outcome;
}

namespace {

using MatrixL = Eigen::Matrix<RealL, Eigen::Dynamic, Eigen::Dynamic>;
using VectorL = Eigen::Matrix<RealL, Eigen::Dynamic, 1>;

/// Contacts whose rows of the Delassus matrix are dependent to this relative size are redundant
/// (jointImpulses): far above the rounding of lever arms given as doubles (~1e-16), far below any
/// contact geometry a body's shape gives on purpose.
constexpr RealL kRedundantContacts = 1e-12L;

/// The canonical order of the contacts: by point, normal, lever arms, bodies and e, each
/// compared lexicographically, so that any listing of the same contacts is solved alike.
std::vector<std::size_t> canonicalOrder(const std::vector<ClusterContact>& contacts) {
  const auto key = [&](std::size_t k) {
    const ClusterContact& c = contacts[k];
    return std::make_tuple(c.point.x(), c.point.y(), c.point.z(), c.normal.x(), c.normal.y(),
                           c.normal.z(), c.lever_a.x(), c.lever_a.y(), c.lever_a.z(), c.lever_b.x(),
                           c.lever_b.y(), c.lever_b.z(), c.a, c.b, c.restitution);
  };
  std::vector<std::size_t> order(contacts.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t k, std::size_t l) { return key(k) < key(l); });
  return order;
}

/// The impulses of Newton's joint rule for contacts already in canonical order: A J = target,
/// the least-norm solution by a complete orthogonal decomposition in long double, a contact
/// that would pull dropped (the most negative first) and the rest solved again.
std::vector<double> jointImpulses(const MatrixL& delassus, const VectorL& target) {
  const auto count = delassus.rows();
  std::vector<bool> active(static_cast<std::size_t>(count), true);
  std::vector<double> impulses(static_cast<std::size_t>(count), 0.0);
  for (Eigen::Index round = 0; round < count; ++round) {
    std::vector<Eigen::Index> kept;
    for (Eigen::Index k = 0; k < count; ++k) {
      if (active[static_cast<std::size_t>(k)]) kept.push_back(k);
    }
    const auto size = static_cast<Eigen::Index>(kept.size());
    MatrixL system(size, size);
    VectorL right(size);
    for (Eigen::Index i = 0; i < size; ++i) {
      right[i] = target[kept[static_cast<std::size_t>(i)]];
      for (Eigen::Index j = 0; j < size; ++j) {
        system(i, j) =
            delassus(kept[static_cast<std::size_t>(i)], kept[static_cast<std::size_t>(j)]);
      }
    }
    // A's rank as its doubles give it: a pivot below kRedundantContacts of the largest is 0
    // (four corners coplanar but for the rounding of their lever arms to doubles, which leaves
    // A's smallest singular value ~1e-16 of its largest: long double's own default, 4e-19 n,
    // would call that full rank and give impulses of any size along A's near-null direction).
    // Rounded once to doubles: contacts that are mirror images of each other receive the same
    // impulse to the bit, and their turns cancel exactly.
    Eigen::CompleteOrthogonalDecomposition<MatrixL> decomposition(system.rows(), system.cols());
    decomposition.setThreshold(kRedundantContacts);
    const Eigen::VectorXd solution = decomposition.compute(system).solve(right).cast<double>();
    std::fill(impulses.begin(), impulses.end(), 0.0);
    Eigen::Index most_negative = -1;
    for (Eigen::Index i = 0; i < size; ++i) {
      impulses[static_cast<std::size_t>(kept[static_cast<std::size_t>(i)])] = solution[i];
      if (solution[i] < 0 && (most_negative < 0 || solution[i] < solution[most_negative])) {
        most_negative = i;
      }
    }
    if (most_negative < 0) break;
    active[static_cast<std::size_t>(kept[static_cast<std::size_t>(most_negative)])] = false;
    if (size == 1) {
      std::fill(impulses.begin(), impulses.end(), 0.0);
      break;
    }
  }
  for (double& impulse : impulses) impulse = std::max(impulse, 0.0);
  return impulses;
}

}  // namespace

namespace {

/// Each contact's side on a body: the body, its sign s (b: +1, a: -1), its lever arm.
struct ContactSideL {
  std::size_t body;
  RealL sign;
  Vector3L lever;
};
std::array<ContactSideL, 2> sidesOf(const ClusterContact& c) {
  return {ContactSideL{c.a, RealL(-1), c.lever_a.cast<RealL>()},
          ContactSideL{c.b, RealL(1), c.lever_b.cast<RealL>()}};
}

/// Every body and contact of a simultaneous impact checked, each refusal naming its field.
Status checkSimultaneous(const std::vector<SolverBody>& bodies,
                         const std::vector<ClusterContact>& contacts) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (auto status = checkBodyForImpact(bodies[i], "bodies[" + std::to_string(i) + "]"); !status) {
      return status;
    }
  }
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const ClusterContact& contact = contacts[k];
    const std::string field = "contacts[" + std::to_string(k) + "].";
    if (contact.a >= bodies.size() || contact.b >= bodies.size() || contact.a == contact.b) {
      return Error{field + "b", "the bodies must be two different ones of the " +
                                    std::to_string(bodies.size()) +
                                    ", got a = " + std::to_string(contact.a) +
                                    ", b = " + std::to_string(contact.b)};
    }
    if (auto status = checkContactGeometry(contact, field); !status) return status;
    if (auto status = checkRestitution(contact.restitution, field + "restitution"); !status) {
      return status;
    }
    if (bodies[contact.a].inverse_mass == 0.0 && bodies[contact.b].inverse_mass == 0.0) {
      return Error{field + "b",
                   "both sides of the contact are immovable (inverse mass 0): nothing can move"};
    }
  }
  return Ok{};
}

/// Newton's joint rule A J = (1 + e)(-d) over the contacts in `order`: the Delassus matrix A,
/// the target and each contact's approach speed -d, in long double, and each body's inverse
/// inertia.
struct JointSystem {
  std::vector<Matrix3L> inverse_inertia;
  MatrixL delassus;
  VectorL target;
  VectorL approach;  // -d_k
};
JointSystem jointSystem(const std::vector<SolverBody>& bodies,
                        const std::vector<ClusterContact>& contacts,
                        const std::vector<std::size_t>& order) {
  const auto count = static_cast<Eigen::Index>(contacts.size());
  JointSystem system;
  std::vector<Matrix3L>& inverse_inertia = system.inverse_inertia;
  inverse_inertia.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) inverse_inertia[i] = inverseInertiaOf(bodies[i]);
  MatrixL& delassus = system.delassus;
  delassus = MatrixL::Zero(count, count);
  VectorL& target = system.target;
  target.resize(count);
  VectorL& approach = system.approach;
  approach.resize(count);
  for (Eigen::Index i = 0; i < count; ++i) {
    const ClusterContact& ci = contacts[order[static_cast<std::size_t>(i)]];
    const Vector3L ni = ci.normal.cast<RealL>();
    approach[i] =
        -(pointVelocity(bodies[ci.b], ci.lever_b) - pointVelocity(bodies[ci.a], ci.lever_a))
             .dot(ni);
    target[i] = (RealL(1) + RealL(ci.restitution)) * approach[i];
    for (Eigen::Index j = 0; j < count; ++j) {
      const ClusterContact& cj = contacts[order[static_cast<std::size_t>(j)]];
      const Vector3L nj = cj.normal.cast<RealL>();
      RealL value = 0;
      for (const ContactSideL& si : sidesOf(ci)) {
        for (const ContactSideL& sj : sidesOf(cj)) {
          if (si.body != sj.body || bodies[si.body].inverse_mass == 0.0) continue;
          value += si.sign * sj.sign *
                   (RealL(bodies[si.body].inverse_mass) * ni.dot(nj) +
                    si.lever.cross(ni).dot(inverse_inertia[si.body] * sj.lever.cross(nj)));
        }
      }
      delassus(i, j) = value;
    }
  }
  return system;
}

/// Impulses (each on b, its opposite on a; `impulses[i]` at the contact order[i]) applied: each
/// body's velocity changes summed free of order, every result checked representable; the bodies
/// updated in place only where all is (references to them stay valid).
Status applyImpulses(std::vector<SolverBody>& bodies, const std::vector<ClusterContact>& contacts,
                     const std::vector<std::size_t>& order,
                     const std::vector<Matrix3L>& inverse_inertia,
                     const std::vector<Vector3L>& impulses) {
  std::vector<std::array<std::vector<RealL>, 6>> changes(bodies.size());  // dv, dw per axis
  for (std::size_t i = 0; i < order.size(); ++i) {
    const ClusterContact& contact = contacts[order[i]];
    if (impulses[i].isZero(0)) continue;
    for (const ContactSideL& side : sidesOf(contact)) {
      const SolverBody& body = bodies[side.body];
      if (body.inverse_mass == 0.0) continue;
      const Vector3L force = side.sign * impulses[i];
      const Vector3L dv = RealL(body.inverse_mass) * force;
      const Vector3L dw = inverse_inertia[side.body] * side.lever.cross(force);
      for (int axis = 0; axis < 3; ++axis) {
        changes[side.body][static_cast<std::size_t>(axis)].push_back(dv[axis]);
        changes[side.body][static_cast<std::size_t>(axis) + 3].push_back(dw[axis]);
      }
    }
  }
  std::vector<SolverBody> after = bodies;
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    if (changes[b][0].empty()) continue;
    for (int axis = 0; axis < 3; ++axis) {
      const auto index = static_cast<std::size_t>(axis);
      after[b].velocity[axis] =
          static_cast<double>(RealL(bodies[b].velocity[axis]) + orderFreeSum(changes[b][index]));
      after[b].angular_velocity[axis] = static_cast<double>(
          RealL(bodies[b].angular_velocity[axis]) + orderFreeSum(changes[b][index + 3]));
    }
    if (auto status =
            checkRepresentable({namedResult("velocity", after[b].velocity),
                                namedResult("angular_velocity", after[b].angular_velocity)});
        !status) {
      return Error{"bodies[" + std::to_string(b) + "]." + status.error().field,
                   status.error().reason};
    }
  }
  std::copy(after.begin(), after.end(), bodies.begin());  // in place: references to them stay valid
  return Ok{};
}

/// The joint rule's impulses along the normals applied, and each contact's outcome in the order
/// of `contacts`.
Expected<std::vector<ContactOutcome>> applyJointImpulses(
    std::vector<SolverBody>& bodies, const std::vector<ClusterContact>& contacts,
    const std::vector<std::size_t>& order, const JointSystem& system,
    const std::vector<double>& impulses) {
  std::vector<ContactOutcome> outcomes(contacts.size());
  std::vector<Vector3L> along(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    const ClusterContact& contact = contacts[order[i]];
    const RealL impulse = impulses[i];
    const auto row = static_cast<Eigen::Index>(i);
    along[i] = impulse * contact.normal.cast<RealL>();
    ContactOutcome& outcome = outcomes[order[i]];
    outcome.impulse = impulses[i];
    outcome.approach_speed = static_cast<double>(system.approach[row]);
    outcome.energy_lost = static_cast<double>(
        RealL(0.5) * impulse * (RealL(1) - RealL(contact.restitution)) * system.approach[row]);
    if (!std::isfinite(outcome.impulse) || !std::isfinite(outcome.energy_lost)) {
      return Error{"impulse", kBeyondDoubles};
    }
  }
  if (auto status = applyImpulses(bodies, contacts, order, system.inverse_inertia, along);
      !status) {
    return status.error();
  }
  return outcomes;
}

/// The 3x3 block of the contacts' Delassus matrix between contacts i and j: the change of the
/// relative velocity at i's points per unit impulse at j's, summed over the bodies they share,
/// s_i s_j (w - [r_i]x I^-1 [r_j]x).
Matrix3L blockOf(const std::vector<SolverBody>& bodies,
                 const std::vector<Matrix3L>& inverse_inertia, const ClusterContact& ci,
                 const ClusterContact& cj) {
  const auto cross = [](const Vector3L& r) {
    Matrix3L m;
    m << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
    return m;
  };
  Matrix3L block = Matrix3L::Zero();
  for (const ContactSideL& si : sidesOf(ci)) {
    for (const ContactSideL& sj : sidesOf(cj)) {
      if (si.body != sj.body || bodies[si.body].inverse_mass == 0.0) continue;
      block += si.sign * sj.sign *
               (RealL(bodies[si.body].inverse_mass) * Matrix3L::Identity() -
                cross(si.lever) * inverse_inertia[si.body] * cross(sj.lever));
    }
  }
  return block;
}

using MaybeOutcomes = std::optional<std::vector<FrictionalOutcome>>;

/// Chatterjee and Ruina's law (resolveRigidImpactByLaw) over contacts struck at once (the header's
/// comment): P = (1 + e) P_I + kappa D, P_I the plastic frictionless joint impulses, D = P_II - P_I
/// with P_II the least-norm sticking impulses of the contacts P_I presses, kappa the largest in
/// [0, 1] within every contact's cone. The bodies updated and the outcomes; none (the caller
/// takes the frictionless joint rule) where the contacts' e differ, the sticking impulses do not
/// stop every slip (no such impulse exists: a moving obstacle's points no twist of the body
/// follows), or a contact P_I leaves approaches after P.
Expected<MaybeOutcomes> jointLaw(std::vector<SolverBody>& bodies,
                                 const std::vector<ClusterContact>& contacts,
                                 const std::vector<double>& friction) {
  const std::vector<std::size_t> order = canonicalOrder(contacts);
  const JointSystem system = jointSystem(bodies, contacts, order);
  const RealL e = contacts.front().restitution;
  for (const ClusterContact& contact : contacts) {
    if (contact.restitution != contacts.front().restitution) return MaybeOutcomes{};
  }
  const std::vector<double> plastic = jointImpulses(system.delassus, system.approach);
  std::vector<std::size_t> pressed;  // places in `order`
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (plastic[i] > 0) pressed.push_back(i);
  }
  if (pressed.empty()) return MaybeOutcomes{};
  const auto size = static_cast<Eigen::Index>(3 * pressed.size());
  MatrixL delassus(size, size);
  VectorL slip(size);  // the relative velocities u_k, which P_II stops
  for (std::size_t i = 0; i < pressed.size(); ++i) {
    const ClusterContact& ci = contacts[order[pressed[i]]];
    slip.segment<3>(static_cast<Eigen::Index>(3 * i)) =
        pointVelocity(bodies[ci.b], ci.lever_b) - pointVelocity(bodies[ci.a], ci.lever_a);
    for (std::size_t j = 0; j < pressed.size(); ++j) {
      delassus.block<3, 3>(static_cast<Eigen::Index>(3 * i), static_cast<Eigen::Index>(3 * j)) =
          blockOf(bodies, system.inverse_inertia, ci, contacts[order[pressed[j]]]);
    }
  }
  Eigen::CompleteOrthogonalDecomposition<MatrixL> decomposition(size, size);
  decomposition.setThreshold(kRedundantContacts);
  const VectorL sticking = decomposition.compute(delassus).solve(-slip);
  if (!((delassus * sticking + slip).norm() <= 1e-9L * slip.norm())) return MaybeOutcomes{};
  // D, and kappa: on each contact's cone kappa |D_t| = mu ((1 + e) J + kappa D.n).
  std::vector<Vector3L> d(pressed.size());
  RealL kappa = 1;
  for (std::size_t i = 0; i < pressed.size(); ++i) {
    const ClusterContact& contact = contacts[order[pressed[i]]];
    const Vector3L n = contact.normal.cast<RealL>();
    d[i] = sticking.segment<3>(static_cast<Eigen::Index>(3 * i)) - RealL(plastic[pressed[i]]) * n;
    const RealL d_normal = d[i].dot(n), d_tangential = (d[i] - d_normal * n).norm();
    const RealL mu = friction[order[pressed[i]]];
    const RealL pressing = (1 + e) * RealL(plastic[pressed[i]]);
    // Never pulling (where mu is 0 and D has no slip to stop there, the cone says nothing).
    if (d_normal < 0) kappa = std::min(kappa, pressing / -d_normal);
    if (d_tangential <= mu * (pressing + d_normal)) continue;  // P^ within this cone
    const RealL denominator = d_tangential - mu * d_normal;
    kappa = std::min(kappa,
                     denominator > 0 ? std::max(mu * pressing / denominator, RealL(0)) : RealL(0));
  }
  std::vector<Vector3L> impulses(order.size(), Vector3L::Zero());
  VectorL stacked_d(size);
  for (std::size_t i = 0; i < pressed.size(); ++i) {
    const Vector3L n = contacts[order[pressed[i]]].normal.cast<RealL>();
    impulses[pressed[i]] = (1 + e) * RealL(plastic[pressed[i]]) * n + kappa * d[i];
    stacked_d.segment<3>(static_cast<Eigen::Index>(3 * i)) = d[i];
  }
  const VectorL d_response = delassus * stacked_d;
  const std::vector<SolverBody> before = bodies;
  if (auto status = applyImpulses(bodies, contacts, order, system.inverse_inertia, impulses);
      !status) {
    return status.error();
  }
  // Every contact P_I left apart stays apart (D may press it).
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (plastic[i] > 0) continue;
    const ClusterContact& c = contacts[order[i]];
    const RealL after =
        (pointVelocity(bodies[c.b], c.lever_b) - pointVelocity(bodies[c.a], c.lever_a))
            .dot(c.normal.cast<RealL>());
    if (after < -1e-12L * slip.norm()) {
      std::copy(before.begin(), before.end(), bodies.begin());
      return MaybeOutcomes{};
    }
  }
  std::vector<FrictionalOutcome> outcomes(contacts.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    const ClusterContact& contact = contacts[order[i]];
    const Vector3L n = contact.normal.cast<RealL>();
    const RealL along = impulses[i].dot(n);
    FrictionalOutcome& outcome = outcomes[order[i]];
    outcome.normal.impulse = static_cast<double>(along);
    outcome.normal.approach_speed =
        static_cast<double>(system.approach[static_cast<Eigen::Index>(i)]);
    outcome.friction_impulse = static_cast<double>((impulses[i] - along * n).norm());
  }
  // The energy lost, (1 - e^2) P_I.A.P_I / 2 + kappa (2 - kappa) D.A.D / 2, each contact's share.
  for (std::size_t i = 0; i < pressed.size(); ++i) {
    FrictionalOutcome& outcome = outcomes[order[pressed[i]]];
    outcome.normal.energy_lost =
        static_cast<double>(RealL(0.5) * (1 - e) * (1 + e) * RealL(plastic[pressed[i]]) *
                            system.approach[static_cast<Eigen::Index>(pressed[i])]);
    outcome.friction_energy_lost =
        static_cast<double>(RealL(0.5) * kappa * (2 - kappa) *
                            d[i].dot(d_response.segment<3>(static_cast<Eigen::Index>(3 * i))));
  }
  return MaybeOutcomes(std::move(outcomes));
}

}  // namespace

Expected<std::vector<ContactOutcome>> resolveRigidSimultaneous(
    std::vector<SolverBody>& bodies, const std::vector<ClusterContact>& contacts) {
  if (auto status = checkSimultaneous(bodies, contacts); !status) return status.error();
  if (contacts.empty()) return std::vector<ContactOutcome>{};
  if (std::all_of(bodies.begin(), bodies.end(), [](const SolverBody& body) {
        return body.inertia_kind == InverseInertiaKind::kIsotropic;
      })) {
    return resolveSimultaneous(bodies, contacts);
  }
  const std::vector<std::size_t> order = canonicalOrder(contacts);
  const JointSystem system = jointSystem(bodies, contacts, order);
  const std::vector<double> impulses = jointImpulses(system.delassus, system.target);
  return applyJointImpulses(bodies, contacts, order, system, impulses);
}

Expected<std::vector<FrictionalOutcome>> resolveRigidSimultaneous(
    std::vector<SolverBody>& bodies, const std::vector<ClusterContact>& contacts,
    const std::vector<double>& friction) {
  if (friction.size() != contacts.size()) {
    return Error{"friction", "must give one coefficient per contact (" +
                                 std::to_string(contacts.size()) + "), not " +
                                 std::to_string(friction.size())};
  }
  for (std::size_t k = 0; k < friction.size(); ++k) {
    if (!(std::isfinite(friction[k]) && friction[k] >= 0)) {
      return Error{"friction[" + std::to_string(k) + "]", "must be finite and >= 0"};
    }
  }
  if (auto status = checkSimultaneous(bodies, contacts); !status) return status.error();
  const bool frictionless =
      std::all_of(friction.begin(), friction.end(), [](double mu) { return mu == 0.0; });
  if (!frictionless && !contacts.empty()) {
    std::vector<SolverBody> tried = bodies;
    auto joint = jointLaw(tried, contacts, friction);
    if (!joint) return joint.error();
    if (joint.value()) {
      std::copy(tried.begin(), tried.end(), bodies.begin());
      return std::move(*joint.value());
    }
  }
  // Frictionless, or where the law does not apply (jointLaw): the joint rule along the normals.
  auto normal = resolveRigidSimultaneous(bodies, contacts);
  if (!normal) return normal.error();
  std::vector<FrictionalOutcome> outcomes(contacts.size());
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    outcomes[k].normal = (*normal)[k];
    outcomes[k].frictionless_rule = !frictionless;
  }
  return outcomes;
}

}  // namespace collision_response::core
