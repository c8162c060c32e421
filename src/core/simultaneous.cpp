#include "collision_response/core/simultaneous.h"

#include <Eigen/Dense>
#include <algorithm>

#include "collision_response/core/impact.h"

namespace collision_response::core {
namespace {

double relativeNormalVelocity(const std::vector<ClusterBody>& bodies,
                              const ClusterContact& contact) {
  return (bodies[contact.b].velocity - bodies[contact.a].velocity).dot(contact.normal);
}

std::vector<ContactOutcome> resolveOne(std::vector<ClusterBody>& bodies,
                                       const ClusterContact& contact) {
  ClusterBody& a = bodies[contact.a];
  ClusterBody& b = bodies[contact.b];
  const ImpactResponse<double> response = resolveImpact(
      a.inverse_mass, a.velocity, b.inverse_mass, b.velocity, contact.normal, contact.restitution);
  a.velocity = response.velocity_a;
  b.velocity = response.velocity_b;
  return {ContactOutcome{response.normal_impulse, response.approach_speed, response.energy_lost}};
}

}  // namespace

std::vector<ContactOutcome> resolveSimultaneous(std::vector<ClusterBody>& bodies,
                                                const std::vector<ClusterContact>& contacts) {
  if (contacts.size() == 1) return resolveOne(bodies, contacts.front());

  const std::size_t count = contacts.size();
  Eigen::VectorXd approach(count);  // -d_k
  for (std::size_t k = 0; k < count; ++k) {
    approach[k] = -relativeNormalVelocity(bodies, contacts[k]);
  }
  // A_kl = sum over the bodies the two contacts share of w_i s_ik s_il n_k.n_l.
  Eigen::MatrixXd coupling = Eigen::MatrixXd::Zero(count, count);
  for (std::size_t k = 0; k < count; ++k) {
    for (std::size_t l = 0; l < count; ++l) {
      const double alignment = contacts[k].normal.dot(contacts[l].normal);
      const auto add = [&](std::size_t body_k, double sign_k, std::size_t body_l, double sign_l) {
        if (body_k == body_l)
          coupling(k, l) += bodies[body_k].inverse_mass * sign_k * sign_l * alignment;
      };
      add(contacts[k].a, -1, contacts[l].a, -1);
      add(contacts[k].a, -1, contacts[l].b, +1);
      add(contacts[k].b, +1, contacts[l].a, -1);
      add(contacts[k].b, +1, contacts[l].b, +1);
    }
  }

  // Active set: solve for the contacts still active; drop the one that would pull hardest.
  std::vector<bool> active(count, true);
  Eigen::VectorXd impulses = Eigen::VectorXd::Zero(count);
  for (std::size_t iteration = 0; iteration < count; ++iteration) {
    std::vector<std::size_t> rows;
    for (std::size_t k = 0; k < count; ++k) {
      if (active[k]) rows.push_back(k);
    }
    const auto size = static_cast<Eigen::Index>(rows.size());
    // Solved in long double (11 more bits) and rounded once: the impulses are the doubles
    // nearest the exact solution, so contacts that are mirror images of each other receive the
    // same impulse to the bit, whatever order the solver visits them in.
    using MatrixL = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
    using VectorL = Eigen::Matrix<long double, Eigen::Dynamic, 1>;
    MatrixL system(size, size);
    VectorL target(size);
    for (Eigen::Index i = 0; i < size; ++i) {
      target[i] = (1.0L + contacts[rows[i]].restitution) * approach[rows[i]];
      for (Eigen::Index j = 0; j < size; ++j) system(i, j) = coupling(rows[i], rows[j]);
    }
    // Minimum-norm least squares: also right when two contacts are redundant (A singular).
    const Eigen::VectorXd solution =
        system.completeOrthogonalDecomposition().solve(target).cast<double>();
    impulses.setZero();
    Eigen::Index most_negative = -1;
    for (Eigen::Index i = 0; i < size; ++i) {
      impulses[rows[i]] = solution[i];
      if (solution[i] < 0 && (most_negative < 0 || solution[i] < solution[most_negative])) {
        most_negative = i;
      }
    }
    if (most_negative < 0) break;
    active[rows[most_negative]] = false;
    impulses[rows[most_negative]] = 0.0;
    if (rows.size() == 1) {
      impulses.setZero();
      break;
    }
  }
  impulses = impulses.cwiseMax(0.0);

  std::vector<ContactOutcome> outcomes(count);
  OrderFreeSum changes(bodies.size());
  for (std::size_t k = 0; k < count; ++k) {
    const ClusterContact& contact = contacts[k];
    const double impulse = impulses[static_cast<Eigen::Index>(k)];
    changes.add(contact.a, -(bodies[contact.a].inverse_mass * impulse * contact.normal));
    changes.add(contact.b, bodies[contact.b].inverse_mass * impulse * contact.normal);
    outcomes[k].impulse = impulse;
    outcomes[k].approach_speed = approach[static_cast<Eigen::Index>(k)];
    outcomes[k].energy_lost =
        0.5 * impulse * (1.0 - contact.restitution) * approach[static_cast<Eigen::Index>(k)];
  }
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    bodies[i].velocity = changes.total(i, bodies[i].velocity);
  }
  return outcomes;
}

Eigen::Vector3d OrderFreeSum::total(std::size_t body, const Eigen::Vector3d& start) const {
  Eigen::Vector3d sum = start;
  std::vector<double> terms;
  for (int c = 0; c < 3; ++c) {
    terms.clear();
    for (const Eigen::Vector3d& change : terms_[body]) terms.push_back(change[c]);
    std::sort(terms.begin(), terms.end());
    double added = 0;
    for (const double term : terms) added += term;
    sum[c] += added;
  }
  return sum;
}

}  // namespace collision_response::core
