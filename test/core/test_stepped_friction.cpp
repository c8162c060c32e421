// The friction of a stepped cluster's sub-step (applyFrictionBySweeps): one contact against its
// closed form, Coulomb's conditions on random clusters checked from the impulses and the slips
// they leave, no energy gained, a warm start that would add energy dropped, and a contact's
// orientation (which names decide) changing no bit.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "solver/stepped_friction.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;

ClusterBody ballBody(double mass, double radius, const V& velocity, const V& angular) {
  ClusterBody body;
  body.inverse_mass = 1 / mass;
  body.radius = radius;
  body.velocity = velocity;
  body.angular_velocity = angular;
  body.spin_factor = 2.5;  // solid: I = 2/5 m r^2
  return body;
}

ClusterBody floorBody() { return ClusterBody{}; }

/// b's surface against a's at the contact, perpendicular to the normal (friction.h's slip),
/// computed here from its definition.
V slipAt(const std::vector<ClusterBody>& bodies, const ClusterContact& c) {
  const ClusterBody& a = bodies[c.a];
  const ClusterBody& b = bodies[c.b];
  const V u = (b.velocity + b.angular_velocity.cross(-b.radius * c.normal)) -
              (a.velocity + a.angular_velocity.cross(a.radius * c.normal));
  return u - u.dot(c.normal) * c.normal;
}

/// Kinetic energy with rotation, in long double: I = 2/5 m r^2 for the solid balls here.
long double kineticEnergy(const std::vector<ClusterBody>& bodies) {
  long double energy = 0;
  for (const ClusterBody& body : bodies) {
    if (body.inverse_mass == 0) continue;
    const long double m = 1 / static_cast<long double>(body.inverse_mass);
    const long double r = body.radius;
    energy +=
        0.5L * m * static_cast<long double>(body.velocity.squaredNorm()) +
        0.5L * (0.4L * m * r * r) * static_cast<long double>(body.angular_velocity.squaredNorm());
  }
  return energy;
}

// A solid ball on a floor: its slip u at the contact, the tangential inverse mass
// D = w (1 + 5/2) (friction.h). Stopping the slip takes |u| / D: within mu J it sticks, the slip
// stopped and the impulse -u / D; beyond it slides, the impulse mu J against u, the slip
// u (1 - mu J D / |u|).
TEST(SteppedFriction, OneContactSticksOrSlidesAsItsClosedFormSays) {
  const double m = 0.1, r = 0.05, w = 1 / m, d = w * 3.5;
  const V v(0.3, -0.4, 0.0), spin(2.0, 1.0, 0.0);  // the floor's normal +z: contact at -r z
  for (const double bound : {1.0, 0.01}) {
    std::vector<ClusterBody> bodies{floorBody(), ballBody(m, r, v, spin)};
    const std::vector<ClusterContact> contacts{ClusterContact{{0, 1, V::UnitZ()}, 0.0}};
    const V u = v + spin.cross(-r * V::UnitZ());  // (0.25, -0.3, 0): independent of the code
    std::vector<SweptFrictionOutcome> outcomes;
    const SweptFrictionReport report = applyFrictionBySweeps<true>(
        bodies, contacts, {SweptFrictionContact{bound, V::Zero()}}, 1e-15, 64, outcomes);
    EXPECT_TRUE(report.converged);
    const bool sticks = u.norm() / d <= bound;
    const V expected = sticks ? V(-u / d) : V(-bound * u.normalized());
    EXPECT_EQ(outcomes[0].sticking, sticks) << bound;
    EXPECT_LE((outcomes[0].impulse - expected).norm(), 1e-15 * expected.norm()) << bound;
    const V slip_after = sticks ? V::Zero() : V(u * (1 - bound * d / u.norm()));
    EXPECT_LE((slipAt(bodies, contacts[0]) - slip_after).norm(), 1e-14 * u.norm()) << bound;
    EXPECT_LE((bodies[1].velocity - (v + w * expected)).norm(), 1e-15);
  }
}

/// A random cluster: balls on a floor in a row, each touching the next, with random velocities
/// and spins, every contact with a random bound.
struct Cluster {
  std::vector<ClusterBody> bodies;
  std::vector<ClusterContact> contacts;
  std::vector<SweptFrictionContact> frictions;
};

Cluster randomCluster(std::mt19937_64& engine, int balls) {
  std::uniform_real_distribution<double> speed(-1.0, 1.0), bound(0.0, 0.05), angle(-0.3, 0.3);
  Cluster cluster;
  cluster.bodies.push_back(floorBody());
  const double r = 0.05;
  V centre(0, 0, r), previous_centre = centre;
  for (int i = 0; i < balls; ++i) {
    cluster.bodies.push_back(
        ballBody(0.1 * (1 + speed(engine) * 0.5), r, V(speed(engine), speed(engine), 0.0),
                 V(10 * speed(engine), 10 * speed(engine), 10 * speed(engine))));
    const std::size_t body = cluster.bodies.size() - 1;
    cluster.contacts.push_back(ClusterContact{{0, body, V::UnitZ()}, 0.0});
    cluster.frictions.push_back(SweptFrictionContact{bound(engine), V::Zero()});
    if (i > 0) {
      const double turn = angle(engine);
      centre = previous_centre + 2 * r * V(std::cos(turn), std::sin(turn), 0.0);
      cluster.contacts.push_back(
          ClusterContact{{body - 1, body, (centre - previous_centre).normalized()}, 0.0});
      cluster.frictions.push_back(SweptFrictionContact{bound(engine), V::Zero()});
    }
    previous_centre = centre;
  }
  return cluster;
}

// Coulomb's conditions, read from what the sweeps leave: every impulse within its disc; inside
// the disc the slip is stopped; on its edge the impulse is against the slip left. And the kinetic
// energy (long double, from the velocities) never grows.
TEST(SteppedFriction, CoulombsConditionsHoldOnRandomClusters) {
  std::mt19937_64 engine(7);
  int sliding = 0, sticking = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Cluster cluster = randomCluster(engine, 1 + trial % 6);
    const long double before = kineticEnergy(cluster.bodies);
    std::vector<SweptFrictionOutcome> outcomes;
    const SweptFrictionReport report = applyFrictionBySweeps<true>(
        cluster.bodies, cluster.contacts, cluster.frictions, 1e-13, 100000, outcomes);
    ASSERT_TRUE(report.converged) << trial;
    EXPECT_LE(kineticEnergy(cluster.bodies), before * (1 + 1e-15L)) << trial;
    for (std::size_t k = 0; k < outcomes.size(); ++k) {
      const double bound = cluster.frictions[k].bound;
      const V& impulse = outcomes[k].impulse;
      const V slip = slipAt(cluster.bodies, cluster.contacts[k]);
      EXPECT_LE(impulse.norm(), bound * (1 + 1e-15)) << trial << " " << k;
      EXPECT_LE(std::abs(impulse.dot(cluster.contacts[k].normal)), 1e-15) << trial << " " << k;
      if (impulse.norm() < bound * (1 - 1e-9)) {
        ++sticking;
        EXPECT_LE(slip.norm(), 1e-11) << trial << " " << k;
      } else {
        ++sliding;
        if (slip.norm() > 1e-11) {
          EXPECT_LE((impulse / bound + slip.normalized()).norm(), 1e-8) << trial << " " << k;
        }
      }
    }
  }
  EXPECT_GT(sticking, 50);
  EXPECT_GT(sliding, 50);
}

// A contact at rest (no slip) given a warm start from a sub-step that slid: applied, that
// impulse would set the ball moving, adding energy. It is dropped: the sweeps start from none,
// and the ball stays at rest.
TEST(SteppedFriction, AWarmStartThatWouldAddEnergyIsDropped) {
  std::vector<ClusterBody> bodies{floorBody(), ballBody(0.1, 0.05, V::Zero(), V::Zero())};
  std::vector<SweptFrictionOutcome> outcomes;
  const SweptFrictionReport report = applyFrictionBySweeps<true>(
      bodies, {ClusterContact{{0, 1, V::UnitZ()}, 0.0}},
      {SweptFrictionContact{0.1, V(0.05, 0.0, 0.0)}}, 1e-15, 64, outcomes);
  EXPECT_TRUE(report.cold);
  EXPECT_TRUE(report.converged);
  EXPECT_EQ(outcomes[0].impulse, V::Zero());
  EXPECT_EQ(bodies[1].velocity, V::Zero());
  EXPECT_EQ(bodies[1].angular_velocity, V::Zero());
}

// Which body is a contact's a and which its b follows the bodies' names. Swapped, with the
// normal turned, every impulse on b is the opposite one to the bit, and every body's velocities
// are the same bits: names change nothing (the sweeps keep the caller's order of contacts).
TEST(SteppedFriction, SwappingAContactsBodiesNegatesItsImpulseToTheBit) {
  std::mt19937_64 engine(3);
  for (int trial = 0; trial < 50; ++trial) {
    const Cluster cluster = randomCluster(engine, 5);
    Cluster swapped = cluster;
    for (std::size_t k = 0; k < swapped.contacts.size(); k += 2) {
      ClusterContact& c = swapped.contacts[k];
      std::swap(c.a, c.b);
      c.normal = -c.normal;
    }
    Cluster plain = cluster;
    std::vector<SweptFrictionOutcome> plain_out, swapped_out;
    applyFrictionBySweeps<true>(plain.bodies, plain.contacts, plain.frictions, 1e-12, 50,
                                plain_out);
    applyFrictionBySweeps<true>(swapped.bodies, swapped.contacts, swapped.frictions, 1e-12, 50,
                                swapped_out);
    for (std::size_t k = 0; k < plain_out.size(); ++k) {
      const V expected = k % 2 == 0 ? V(-plain_out[k].impulse) : plain_out[k].impulse;
      EXPECT_EQ(swapped_out[k].impulse, expected) << trial << " " << k;
    }
    for (std::size_t i = 0; i < plain.bodies.size(); ++i) {
      EXPECT_EQ(swapped.bodies[i].velocity, plain.bodies[i].velocity) << trial << " " << i;
      EXPECT_EQ(swapped.bodies[i].angular_velocity, plain.bodies[i].angular_velocity)
          << trial << " " << i;
    }
  }
}

// Without the spin effect (kSpin false) the bodies do not turn: D = w_a + w_b, the angular
// velocities untouched. One ball on a floor sliding at u: the impulse -u / D or mu J against u.
TEST(SteppedFriction, WithoutSpinTheBodiesDoNotTurn) {
  const double m = 0.2, w = 1 / m;
  const V v(0.6, 0.8, 0.0), spin(5.0, 0.0, 0.0);
  for (const double bound : {1.0, 0.02}) {
    std::vector<ClusterBody> bodies{floorBody(), ballBody(m, 0.05, v, spin)};
    std::vector<SweptFrictionOutcome> outcomes;
    applyFrictionBySweeps<false>(bodies, {ClusterContact{{0, 1, V::UnitZ()}, 0.0}},
                                 {SweptFrictionContact{bound, V::Zero()}}, 1e-15, 64, outcomes);
    const V expected = v.norm() / w <= bound ? V(-v / w) : V(-bound * v.normalized());
    EXPECT_LE((outcomes[0].impulse - expected).norm(), 1e-15) << bound;
    EXPECT_EQ(bodies[1].angular_velocity, spin);
  }
}

}  // namespace
}  // namespace collision_response::core
