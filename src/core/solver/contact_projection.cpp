#include "solver/contact_projection.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/contact_group.h"

namespace collision_response::core {

using namespace contact_group;

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
}  // namespace collision_response::core
