// A cluster too large for one dense solve (doc/model.md, "Work per message"): a lattice of touching
// balls closing on its centre, 1,000 balls and 2,700 contacts, once a minute's dense solve. Solved
// block by block, by conjugate gradients above 128 contacts. What must hold is Newton's
// restitution on every contact (d' = -e d where an impulse acts, J >= 0, no contact left
// approaching), momentum to the rounding, no energy gained, and the same answer to the bit
// for any naming of the bodies (conditions that hold for the exact answer, whatever computes
// it). With friction (and spin) the same lattice's tangential impulses: a block of 2,700
// contacts, solved by an accelerated projected gradient above 128 contacts; Coulomb's law on
// every contact, no energy gained, momentum to the rounding, renaming and mirroring exact; and
// a chain of 200 balls, one block above the size limit, against its closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "collision_response/core/simultaneous.h"
#include "solver/cluster_solver.h"
#include "solver/friction_impulses.h"

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

/// closingLattice with friction and spin: solid balls (I = 2/5 m r^2) of radius 0.05 m, the
/// closing velocity plus a swirl of 0.3 rad/s about z through the centre (every contact slips)
/// plus each ball's own velocity of up to 0.05 m/s and spin of up to 10 rad/s (seeded, by place
/// in the lattice, so a renamed lattice has the same balls). `mirrored`: the balls with
/// i >= n / 2 get the mirror images across the plane x = centre of their partners' (n - 1 - i):
/// velocity (-x, y, z), angular velocity (x, -y, -z) (a pseudovector).
Lattice frictionLattice(int n, const std::vector<std::size_t>& order, bool mirrored) {
  Lattice lattice = closingLattice(n, order);
  std::mt19937_64 engine(13);
  std::uniform_real_distribution<double> unit(-1, 1);
  const V centre = V::Constant(0.05 * (n - 1));
  const auto index = [&](int i, int j, int k) {
    return order[static_cast<std::size_t>((i * n + j) * n + k)];
  };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        ClusterBody& body = lattice.bodies[index(i, j, k)];
        body.radius = 0.05;
        body.spin_factor = 2.5;
        body.velocity += 0.3 * V::UnitZ().cross(V(0.1 * i, 0.1 * j, 0.1 * k) - centre) +
                         0.05 * V(unit(engine), unit(engine), unit(engine));
        body.angular_velocity = 10 * V(unit(engine), unit(engine), unit(engine));
      }
    }
  }
  if (mirrored) {
    for (int i = n / 2; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        for (int k = 0; k < n; ++k) {
          const ClusterBody& partner = lattice.bodies[index(n - 1 - i, j, k)];
          ClusterBody& body = lattice.bodies[index(i, j, k)];
          body.velocity = partner.velocity.cwiseProduct(V(-1, 1, 1));
          body.angular_velocity = partner.angular_velocity.cwiseProduct(V(1, -1, -1));
        }
      }
    }
  }
  return lattice;
}

/// Kinetic energy, translational and rotational (I = r^2 / (w k)).
double kineticWithSpin(const std::vector<ClusterBody>& bodies) {
  double energy = 0;
  for (const ClusterBody& body : bodies) {
    energy += 0.5 * body.velocity.squaredNorm() / body.inverse_mass +
              0.5 * body.radius * body.radius / (body.inverse_mass * body.spin_factor) *
                  body.angular_velocity.squaredNorm();
  }
  return energy;
}

constexpr double kLatticeFriction = 0.3;

/// The lattice's normal impulses (applied to its bodies), then the friction problem they pose.
std::pair<std::vector<ForceBody>, std::vector<ForceContact>> frictionProblem(
    Lattice& lattice, std::vector<double>& normal_impulses) {
  normal_impulses.clear();
  for (const ContactOutcome& outcome : resolveSimultaneous(lattice.bodies, lattice.contacts)) {
    normal_impulses.push_back(outcome.impulse);
  }
  std::vector<ForceBody> bodies;
  for (const ClusterBody& body : lattice.bodies) {
    ForceBody force_body;
    force_body.inverse_mass = body.inverse_mass;
    force_body.spin_factor = body.spin_factor;
    force_body.radius = body.radius;
    force_body.velocity = body.velocity;
    force_body.angular_velocity = body.angular_velocity;
    bodies.push_back(force_body);
  }
  std::vector<ForceContact> contacts;
  for (const ClusterContact& contact : lattice.contacts) {
    ForceContact force_contact;
    force_contact.a = contact.a;
    force_contact.b = contact.b;
    force_contact.normal = contact.normal;
    force_contact.friction = kLatticeFriction;
    contacts.push_back(force_contact);
  }
  return {bodies, contacts};
}

// Coulomb's law holds on every contact of the exact answer, whatever computes it: |T| <= mu J;
// where |T| < mu J the slip after is 0; where |T| = mu J, T is against the slip after (or that
// slip is 0). The normal impulses act along the axes, across no slip; the slips are below
// 2 m/s (spin up to 10 sqrt 3 rad/s at 0.05 m on either ball, 1.74 m/s; the swirl's 0.03 m/s;
// each ball's own 0.05 sqrt 3 m/s, 0.18 m/s), and the solve's residual is at most 1e-12 of the
// largest slip: 1e-10 m/s is far above it and far below the slips. The impulses of friction
// alone are internal: linear momentum is kept (to the rounding of the 1,000 changes), and the
// kinetic energy left is no more than before.
TEST(LargeCluster, FrictionOnALatticeOfAThousandObeysCoulombOnEveryContact) {
  const int n = 10;
  std::vector<std::size_t> identity(1000);
  std::iota(identity.begin(), identity.end(), 0);
  Lattice lattice = frictionLattice(n, identity, false);
  std::vector<double> normal_impulses;
  const auto [bodies, contacts] = frictionProblem(lattice, normal_impulses);
  const ContactForceSolution solution = solveFrictionImpulses(bodies, contacts, normal_impulses);
  EXPECT_TRUE(solution.converged);
  int sticking = 0, sliding = 0;
  double largest_slip = 0;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    const ContactForce& force = solution.contacts[c];
    const double bound = kLatticeFriction * normal_impulses[c];
    const V after = force.slip + force.slip_acceleration;
    largest_slip = std::max(largest_slip, force.slip.norm());
    ASSERT_LE(force.tangential.norm(), bound * (1 + 1e-15)) << "contact " << c;
    EXPECT_LE(std::abs(force.tangential.dot(contacts[c].normal)), 1e-15 * bound);
    if (bound == 0) continue;
    if (force.tangential.norm() < bound * (1 - 1e-9)) {
      ++sticking;
      EXPECT_LE(after.norm(), 1e-10) << "contact " << c << " sticks but slips";
    } else {
      ++sliding;
      // Against the slip left: T / |T| = -u / |u|.
      if (after.norm() > 1e-10) {
        EXPECT_LE((force.tangential.normalized() + after.normalized()).norm() * after.norm(), 1e-10)
            << "contact " << c;
      }
    }
  }
  EXPECT_GT(sticking, 100);
  EXPECT_GT(sliding, 100);
  EXPECT_LT(largest_slip, 2.0);
  V momentum_before = V::Zero(), momentum_after = V::Zero();
  double speeds = 0;
  std::vector<ClusterBody> after = lattice.bodies;
  for (std::size_t i = 0; i < after.size(); ++i) {
    after[i].velocity += solution.acceleration[i];
    after[i].angular_velocity += solution.angular_acceleration[i];
    momentum_before += lattice.bodies[i].velocity / lattice.bodies[i].inverse_mass;
    momentum_after += after[i].velocity / after[i].inverse_mass;
    speeds += lattice.bodies[i].velocity.norm() / lattice.bodies[i].inverse_mass;
  }
  EXPECT_LE((momentum_after - momentum_before).norm(), 1e-14 * speeds);
  EXPECT_LT(kineticWithSpin(after), kineticWithSpin(lattice.bodies));
}

// The frictional lattice through the cluster solver (normal impulses, then friction with spin):
// renaming the balls and listing the contacts backwards changes no bit of any velocity.
TEST(LargeCluster, FrictionRenamingTheBodiesChangesNoBit) {
  const int n = 6;  // 216 balls, 540 contacts: one block, the iterative path
  std::vector<std::size_t> identity(216);
  std::iota(identity.begin(), identity.end(), 0);
  std::vector<std::size_t> shuffled = identity;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(5));
  Lattice plain = frictionLattice(n, identity, false);
  Lattice renamed = frictionLattice(n, shuffled, false);
  std::reverse(renamed.contacts.begin(), renamed.contacts.end());
  const FrictionModel model = frictionModelFor(Effects{false, true, true});
  const std::vector<double> friction(plain.contacts.size(), kLatticeFriction);
  solveCluster(plain.bodies, plain.contacts, friction, model);
  solveCluster(renamed.bodies, renamed.contacts, friction, model);
  for (std::size_t i = 0; i < identity.size(); ++i) {
    EXPECT_EQ(plain.bodies[i].velocity, renamed.bodies[shuffled[i]].velocity) << "ball " << i;
    EXPECT_EQ(plain.bodies[i].angular_velocity, renamed.bodies[shuffled[i]].angular_velocity)
        << "ball " << i;
  }
}

// A lattice that is its own mirror image across the plane x = centre (its balls' velocities
// mirrored, their spins as pseudovectors) is left its own mirror image to the bit: each ball's
// velocity (x, y, z) is its partner's (-x, y, z), its angular velocity its partner's (x, -y, -z).
TEST(LargeCluster, FrictionOnAMirrorSymmetricLatticeIsMirrorExact) {
  const int n = 6;
  std::vector<std::size_t> identity(216);
  std::iota(identity.begin(), identity.end(), 0);
  Lattice lattice = frictionLattice(n, identity, true);
  const FrictionModel model = frictionModelFor(Effects{false, true, true});
  const std::vector<double> friction(lattice.contacts.size(), kLatticeFriction);
  const std::vector<ClusterBody> before = lattice.bodies;
  solveCluster(lattice.bodies, lattice.contacts, friction, model);
  for (int i = 0; i < n / 2; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        const ClusterBody& body = lattice.bodies[static_cast<std::size_t>((i * n + j) * n + k)];
        const ClusterBody& image =
            lattice.bodies[static_cast<std::size_t>(((n - 1 - i) * n + j) * n + k)];
        EXPECT_EQ(body.velocity, image.velocity.cwiseProduct(V(-1, 1, 1))) << i << j << k;
        EXPECT_EQ(body.angular_velocity, image.angular_velocity.cwiseProduct(V(1, -1, -1)))
            << i << j << k;
      }
    }
  }
  double changed = 0;
  for (std::size_t b = 0; b < before.size(); ++b) {
    changed =
        std::max(changed, (lattice.bodies[b].angular_velocity - before[b].angular_velocity).norm());
  }
  EXPECT_GT(changed, 0.1);  // friction acted
}

/// A row of `count` balls of 0.1 kg (w = 10 / kg) along x, each touching the next (contact k:
/// a = ball k, b = ball k + 1, normal +x), that do not turn (no spin), with velocities
/// `velocity(i)` and the same bound mu J = `bound` on every contact.
struct Chain {
  std::vector<ForceBody> bodies;
  std::vector<ForceContact> contacts;
  std::vector<double> normal_impulses;
};
template <class Velocity>
Chain chainOf(int count, double bound, Velocity velocity) {
  Chain chain;
  for (int i = 0; i < count; ++i) {
    ForceBody body;
    body.inverse_mass = 10.0;
    body.radius = 0.05;
    body.velocity = velocity(i);
    chain.bodies.push_back(body);
  }
  for (int k = 0; k + 1 < count; ++k) {
    ForceContact contact;
    contact.a = static_cast<std::size_t>(k);
    contact.b = static_cast<std::size_t>(k + 1);
    contact.normal = V::UnitX();
    contact.friction = 0.5;
    chain.contacts.push_back(contact);
    chain.normal_impulses.push_back(bound / 0.5);
  }
  return chain;
}

// Sticking, closed form. 200 balls (199 contacts, one block above the size limit), velocity
// (0, +-0.5, 0.01 (i - 99.5)) (+ for even i). Friction T_k on ball k + 1 and -T_k on ball k
// changes ball i's velocity by w (T_{i-1} - T_i) (T_{-1} = T_199 = 0). Stopping every slip
// leaves all balls the mean velocity, which is 0 (the y's cancel in pairs, the z's are
// antisymmetric about i = 99.5 to the bit): it needs T_i = m sum_{j <= i} v_j, whose y part is
// 0 or 0.05 N s and whose z part is at most 0.001 * 5000 = 5 N s in magnitude (i = 99), within
// the bound 10 N s. Stopping every slip removes all the energy relative to the mean, the least
// any impulses can leave, and the coupling (w times the tridiagonal (2, -1) matrix) is
// positive definite: it is the answer, and its only one. Each contact's slip is left at the
// residual, 1e-12 of the largest slip (1 m/s) at most; a ball's velocity is the sum of at most
// 199 such slips from the mean: |v| <= 2e-10 m/s, with rounding well below.
TEST(LargeCluster, FrictionStopsEverySlipOfAChainThatCanStick) {
  const Chain chain =
      chainOf(200, 10.0, [](int i) { return V(0, i % 2 == 0 ? 0.5 : -0.5, 0.01 * (i - 99.5)); });
  const ContactForceSolution solution =
      solveFrictionImpulses(chain.bodies, chain.contacts, chain.normal_impulses);
  EXPECT_TRUE(solution.converged);
  for (std::size_t i = 0; i < chain.bodies.size(); ++i) {
    const V after = chain.bodies[i].velocity + solution.acceleration[i];
    EXPECT_LE(after.norm(), 2e-10) << "ball " << i;
    EXPECT_EQ(after.x(), 0.0) << "ball " << i;  // friction acts across the normals
  }
  for (std::size_t k = 0; k < chain.contacts.size(); ++k) {
    EXPECT_EQ(solution.contacts[k].mode, ContactMode::kSticking) << "contact " << k;
  }
}

// Sliding, closed form. The same chain with velocities (0, +-0.5, 0) and the bound
// b = 1e-3 N s: every slip is 1 m/s along -+y. At the bound against every slip, ball i (even,
// +0.5 m/s) gets -b from both neighbours: its velocity drops by 2 w b = 0.02 m/s, the odd ones
// rise by as much, the two end balls change by w b = 0.01 m/s; every slip is then 1 - 4 w b =
// 0.96 (0.97 at the ends) in its old direction, so each friction is at its bound against the
// slip left: Coulomb's law, at the minimum of a positive definite problem, the only answer.
TEST(LargeCluster, FrictionSlidesEveryContactOfAChainThatCannotStick) {
  const Chain chain = chainOf(200, 1e-3, [](int i) { return V(0, i % 2 == 0 ? 0.5 : -0.5, 0); });
  const ContactForceSolution solution =
      solveFrictionImpulses(chain.bodies, chain.contacts, chain.normal_impulses);
  EXPECT_TRUE(solution.converged);
  for (std::size_t i = 0; i < chain.bodies.size(); ++i) {
    const double side = i % 2 == 0 ? 1.0 : -1.0;
    const double change = (i == 0 || i == 199) ? 0.01 : 0.02;
    const V after = chain.bodies[i].velocity + solution.acceleration[i];
    EXPECT_NEAR(after.y(), side * (0.5 - change), 1e-15) << "ball " << i;
    EXPECT_EQ(after.x(), 0.0);
    EXPECT_NEAR(after.z(), 0.0, 1e-15);
  }
  for (std::size_t k = 0; k < chain.contacts.size(); ++k) {
    EXPECT_EQ(solution.contacts[k].mode, ContactMode::kSliding) << "contact " << k;
    EXPECT_NEAR(solution.contacts[k].tangential.norm(), 1e-3, 1e-18) << "contact " << k;
  }
}

}  // namespace
}  // namespace collision_response::core
