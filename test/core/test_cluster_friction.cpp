// Friction in clusters: the tangential impulses of simultaneous contacts come from one joint solve,
// so mirror images get mirror answers to the bit, names and order change nothing, and energy
// never increases.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "scene_builders.h"
#include "solver/cluster_solver.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;

Scene frictionScene() {
  Scene scene;
  scene.effects.friction = true;
  scene.effects.spin = true;
  EXPECT_TRUE(scene.materials.addMaterial("cloth", Material{0.9, 0.3}, "m").ok());
  return scene;
}

BodySpec ball(const std::string& id, double mass, double radius) {
  return scene_builders::ball(id, mass, radius, "cloth");
}

struct Outcome {
  V velocity, angular_velocity;
};

/// Steps a monitor once over the strike and returns each body's velocities after it, by id.
std::vector<Outcome> strike(const std::vector<BodySpec>& bodies,
                            const std::vector<BodyStateSample>& states_by_scene_index) {
  Scene scene = frictionScene();
  scene.bodies = bodies;
  ImpactMonitor monitor(scene, MonitorSettings{});
  std::vector<BodyStateSample> states = states_by_scene_index;
  for (std::size_t i = 0; i < states.size(); ++i) {
    states[i].body = *monitor.bodyIndex(bodies[i].id);
  }
  monitor.step(0.0, states);
  const StepReport report = monitor.step(1e-3, {});
  EXPECT_FALSE(report.impacts.empty());
  std::vector<Outcome> outcomes;
  for (const BodySpec& body : bodies) {
    const std::size_t index = *monitor.bodyIndex(body.id);
    const auto state = monitor.predictedState(index, 0.0);
    Outcome outcome{state->second, V::Zero()};
    for (const ImpactRecord& impact : report.impacts) {
      if (impact.body_a == index) outcome.angular_velocity = impact.angular_velocity_a_after;
      if (!impact.other_is_obstacle && impact.other == index) {
        outcome.angular_velocity = impact.angular_velocity_b_after;
      }
    }
    outcomes.push_back(outcome);
  }
  return outcomes;
}

BodyStateSample at(const V& position, const V& velocity = V::Zero(), const V& angular = V::Zero()) {
  BodyStateSample state;
  state.position = position;
  state.velocity = velocity;
  state.angular_velocity = angular;
  return state;
}

// A spinning cue ball driven into two balls placed as mirror images across the x-z plane (y ->
// -y), touching it at once. Under that mirror a velocity (x, y, z) becomes (x, -y, z) and an
// angular velocity (x, y, z) becomes (-x, y, -z). The two struck balls' answers are mirror
// images to the bit, the cue ball keeps no sideways velocity and no spin about x or z, and
// renaming the struck balls (which changes the order the solver sees them in) changes nothing.
TEST(ClusterFriction, MirrorSymmetricStrikeGivesMirrorAnswers) {
  const double r = 0.0285;
  const V upper(2 * r * std::cos(M_PI / 6), 2 * r * std::sin(M_PI / 6), 0);
  const V lower(upper.x(), -upper.y(), 0);
  for (const auto& [first, second] : {std::pair{"ball_a", "ball_b"}, {"ball_b", "ball_a"}}) {
    const std::vector<BodySpec> bodies = {ball("cue", 0.17, r), ball(first, 0.16, r),
                                          ball(second, 0.16, r)};
    const auto outcomes =
        strike(bodies, {at(V::Zero(), V(3, 0, 0), V(0, 40, 0)), at(upper), at(lower)});
    const Outcome &cue = outcomes[0], &up = outcomes[1], &down = outcomes[2];
    EXPECT_EQ(up.velocity.x(), down.velocity.x()) << first;
    EXPECT_EQ(up.velocity.y(), -down.velocity.y()) << first;
    EXPECT_EQ(up.velocity.z(), down.velocity.z()) << first;
    EXPECT_EQ(up.angular_velocity.x(), -down.angular_velocity.x()) << first;
    EXPECT_EQ(up.angular_velocity.y(), down.angular_velocity.y()) << first;
    EXPECT_EQ(up.angular_velocity.z(), -down.angular_velocity.z()) << first;
    EXPECT_EQ(cue.velocity.y(), 0.0) << first;
    EXPECT_EQ(cue.angular_velocity.x(), 0.0) << first;
    EXPECT_EQ(cue.angular_velocity.z(), 0.0) << first;
    EXPECT_GT(up.velocity.norm(), 0.1) << "it was struck";
  }
}

// Four balls touching in an irregular cluster, one driven in with spin: every assignment of the
// four names (24, each a different order of the bodies and contacts) gives every physical ball
// the same velocities to the bit.
TEST(ClusterFriction, EveryPermutationOfNamesGivesTheSameAnswer) {
  const double r = 0.03;
  const V p0(0, 0, 0);
  const V p1 = p0 + 2 * r * V(std::cos(0.3), std::sin(0.3), 0);
  const V p2 = p0 + 2 * r * V(std::cos(-0.9), std::sin(-0.9), 0.1).normalized();
  const V p3 = p2 + 2 * r * V(std::cos(-0.2), std::sin(-0.2), -0.3).normalized();
  const std::vector<BodyStateSample> states = {at(p0, V(2, -0.3, 0.1), V(3, 20, -11)), at(p1),
                                               at(p2, V(0, 0.2, 0)), at(p3)};
  const std::vector<double> masses = {0.17, 0.2, 0.15, 0.3};
  std::array<std::string, 4> names = {"a", "b", "c", "d"};
  std::vector<Outcome> reference;
  int permutations = 0;
  do {
    std::vector<BodySpec> bodies;
    for (int i = 0; i < 4; ++i) bodies.push_back(ball(names[i], masses[i], r));
    const auto outcomes = strike(bodies, states);
    if (reference.empty()) reference = outcomes;
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(outcomes[i].velocity, reference[i].velocity) << permutations << " ball " << i;
      EXPECT_EQ(outcomes[i].angular_velocity, reference[i].angular_velocity)
          << permutations << " ball " << i;
    }
    ++permutations;
  } while (std::next_permutation(names.begin(), names.end()));
  EXPECT_EQ(permutations, 24);
}

// The joint friction of random clusters (friction and spin) never adds energy: kinetic energy,
// translational and rotational, after <= before (an obstacle at rest: a driven, spinning one may
// hand energy over), and each contact's impulse within mu J. Every contact approaches, as the
// monitor's striking contacts do.
TEST(ClusterFriction, EnergyNeverIncreases) {
  std::mt19937_64 engine(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  const FrictionModel model = frictionModelFor(Effects{false, true, true});
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<ClusterBody> bodies(4);
    for (ClusterBody& body : bodies) {
      body.inverse_mass = std::exp(2 * unit(engine));
      body.radius = 0.05 * (1.5 + unit(engine));
      body.spin_factor = trial % 2 ? 2.5 : 1.5;
      body.velocity = V(unit(engine), unit(engine), unit(engine));
      body.angular_velocity = 20 * V(unit(engine), unit(engine), unit(engine));
    }
    bodies[3].inverse_mass = 0;  // an obstacle, at rest
    bodies[3].spin_factor = 0;
    bodies[3].velocity.setZero();
    bodies[3].angular_velocity.setZero();
    std::vector<ClusterContact> contacts;
    std::vector<double> friction;
    for (const auto& [a, b] : {std::pair{0, 1}, {0, 2}, {1, 2}, {2, 3}}) {
      ClusterContact contact;
      contact.a = a;
      contact.b = b;
      contact.normal = V(unit(engine), unit(engine), unit(engine)).normalized();
      if ((bodies[b].velocity - bodies[a].velocity).dot(contact.normal) > 0) {
        contact.normal = -contact.normal;  // approaching
      }
      contact.restitution = 0.5 * (1 + unit(engine));
      contacts.push_back(contact);
      friction.push_back(1.5 * (1 + unit(engine)));
    }
    const auto energy = [&](const std::vector<ClusterBody>& all) {
      double total = 0;
      for (const ClusterBody& body : all) {
        if (body.inverse_mass == 0) continue;
        const double mass = 1 / body.inverse_mass;
        const double inertia = mass * body.radius * body.radius / body.spin_factor;
        total += 0.5 * mass * body.velocity.squaredNorm() +
                 0.5 * inertia * body.angular_velocity.squaredNorm();
      }
      return total;
    };
    const double before = energy(bodies);
    const ClusterOutcome outcome = solveCluster(bodies, contacts, friction, model);
    EXPECT_LE(energy(bodies), before * (1 + 1e-12)) << trial;
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      EXPECT_LE(outcome.friction[k].impulse, friction[k] * outcome.normal[k].impulse * (1 + 1e-12))
          << trial;
    }
  }
}

}  // namespace
}  // namespace collision_response::core
