// A cluster too large for one dense solve (README, "Work per message"): a lattice of touching
// balls closing on its centre, 1,000 balls and 2,700 contacts, once a minute's dense solve.
// Solved block by block, by conjugate gradients above 128 contacts. What must hold is Newton's
// restitution on every contact (d' = -e d where an impulse acts, J >= 0, no contact left
// approaching), momentum to the rounding, no energy gained, and the same answer to the bit
// for any naming of the bodies (conditions that hold for the exact answer, whatever computes
// it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "collision_response/core/simultaneous.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;

struct Lattice {
  std::vector<ClusterBody> bodies;
  std::vector<ClusterContact> contacts;
};

/// n^3 balls of 0.1 kg on a cubic lattice of spacing 2r (touching neighbours), each moving
/// towards the centre at 0.1 of its distance per second; e = 0.8 on every contact. `order`
/// numbers the bodies (a renaming).
Lattice closingLattice(int n, const std::vector<std::size_t>& order) {
  Lattice lattice;
  const std::size_t count = static_cast<std::size_t>(n * n * n);
  lattice.bodies.resize(count);
  const V centre = V::Constant(0.05 * (n - 1));
  const auto index = [&](int i, int j, int k) {
    return order[static_cast<std::size_t>((i * n + j) * n + k)];
  };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        ClusterBody& body = lattice.bodies[index(i, j, k)];
        body.inverse_mass = 10.0;
        body.velocity = 0.1 * (centre - V(0.1 * i, 0.1 * j, 0.1 * k));
        for (int axis = 0; axis < 3; ++axis) {
          int next[3] = {i, j, k};
          if (++next[axis] == n) continue;
          ClusterContact contact;
          contact.a = index(i, j, k);
          contact.b = index(next[0], next[1], next[2]);
          contact.normal = V::Unit(axis);
          contact.restitution = 0.8;
          lattice.contacts.push_back(contact);
        }
      }
    }
  }
  return lattice;
}

double kinetic(const std::vector<ClusterBody>& bodies) {
  double energy = 0;
  for (const ClusterBody& body : bodies)
    energy += 0.5 * body.velocity.squaredNorm() / body.inverse_mass;
  return energy;
}

TEST(LargeCluster, ALatticeOfAThousandClosingOnItsCentreObeysRestitutionOnEveryContact) {
  const int n = 10;
  std::vector<std::size_t> identity(1000);
  std::iota(identity.begin(), identity.end(), 0);
  Lattice lattice = closingLattice(n, identity);
  ASSERT_EQ(lattice.contacts.size(), 2700u);
  std::vector<double> before(lattice.contacts.size());
  for (std::size_t c = 0; c < lattice.contacts.size(); ++c) {
    const ClusterContact& contact = lattice.contacts[c];
    before[c] = (lattice.bodies[contact.b].velocity - lattice.bodies[contact.a].velocity)
                    .dot(contact.normal);
  }
  V momentum_before = V::Zero();
  for (const ClusterBody& body : lattice.bodies)
    momentum_before += body.velocity / body.inverse_mass;
  const double energy_before = kinetic(lattice.bodies);
  const std::vector<ContactOutcome> outcomes =
      resolveSimultaneous(lattice.bodies, lattice.contacts);
  double pressed = 0;
  for (std::size_t c = 0; c < lattice.contacts.size(); ++c) {
    const ClusterContact& contact = lattice.contacts[c];
    const double after = (lattice.bodies[contact.b].velocity - lattice.bodies[contact.a].velocity)
                             .dot(contact.normal);
    ASSERT_GE(outcomes[c].impulse, 0.0);
    if (outcomes[c].impulse > 0) {
      ++pressed;
      EXPECT_NEAR(after, -0.8 * before[c], 1e-12) << "contact " << c;
    } else {
      EXPECT_GE(after, -1e-12) << "contact " << c << " left approaching";
    }
  }
  EXPECT_GT(pressed, 0);
  V momentum_after = V::Zero();
  for (const ClusterBody& body : lattice.bodies)
    momentum_after += body.velocity / body.inverse_mass;
  EXPECT_LE((momentum_after - momentum_before).norm(), 1e-13);
  EXPECT_LE(kinetic(lattice.bodies), energy_before);
}

TEST(LargeCluster, RenamingTheBodiesChangesNoBit) {
  const int n = 6;  // 216 balls, 540 contacts: the iterative path
  std::vector<std::size_t> identity(216);
  std::iota(identity.begin(), identity.end(), 0);
  std::vector<std::size_t> shuffled = identity;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(7));
  Lattice plain = closingLattice(n, identity);
  Lattice renamed = closingLattice(n, shuffled);
  // The renamed lattice lists its contacts in another order too.
  std::reverse(renamed.contacts.begin(), renamed.contacts.end());
  resolveSimultaneous(plain.bodies, plain.contacts);
  resolveSimultaneous(renamed.bodies, renamed.contacts);
  for (std::size_t i = 0; i < identity.size(); ++i) {
    EXPECT_EQ(plain.bodies[i].velocity, renamed.bodies[shuffled[i]].velocity) << "ball " << i;
  }
}

}  // namespace
}  // namespace collision_response::core
