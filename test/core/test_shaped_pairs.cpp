// Impacts between the monitor's shaped bodies (src/core/monitor/shaped_pairs.h): found where the
// closed forms say, resolved on both bodies, momentum kept and no energy gained; before, the
// monitor reported their touch and let them pass through each other.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "geometry/tumbling_contact.h"
#include "monitor/shaped_motion.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using Q = Eigen::Quaterniond;

/// Two boxes `a` and `b` (half sizes, masses) of material e (frictionless) in empty space, no
/// gravity: a scene with no obstacle but a far floor.
Scene twoBoxes(const V& half_a, double m_a, const V& half_b, double m_b, double e) {
  Scene scene;
  EXPECT_TRUE(scene.materials.addMaterial("block", Material{e, 0.0}, "m").ok());
  for (const auto& [id, half, m] :
       {std::make_tuple("a", half_a, m_a), std::make_tuple("b", half_b, m_b)}) {
    BodySpec body;
    body.id = id;
    body.mass = m;
    body.material = "block";
    body.shape = BodyShape::kBox;
    body.size = 2 * half;
    scene.bodies.push_back(body);
  }
  scene.obstacles = {scene_builders::plane("floor", V::UnitZ(), -100.0, "concrete")};
  return scene;
}

BodyStateSample stateOf(const ImpactMonitor& monitor, const std::string& id, const V& position,
                        const V& velocity, const Q& orientation = Q::Identity(),
                        const V& angular_velocity = V::Zero()) {
  BodyStateSample state;
  state.body = *monitor.bodyIndex(id);
  state.position = position;
  state.velocity = velocity;
  state.orientation = orientation;
  state.angular_velocity = angular_velocity;
  return state;
}

// A cube (m_a = 2, half 0.05) and a smaller block (m_b = 1, half 0.05 x 0.03 x 0.03) meet face to
// face, head on along x, their centres on one line: they touch when their faces do, (0.4 - 0.1)
// / 2 s after the start (1e-11 s), the block's four corners struck at once by the joint rule, and
// leave by the one-dimensional closed form v_a' = (m_a v_a + m_b v_b - m_b e (v_a - v_b)) / (m_a
// + m_b), v_b' = v_a' + e (v_a - v_b), without turning (1e-12); they lose (1/2) m_a m_b / (m_a +
// m_b) (1 - e^2) (v_a - v_b)^2. Before, they passed through each other, reported as unmodelled.
TEST(ShapedPairs, TwoBoxesMeetingFaceToFaceLeaveAsTheLineOfImpactSays) {
  const double e = 0.5, m_a = 2.0, m_b = 1.0, v_a = 1.0, v_b = -1.0;
  const Scene scene = twoBoxes(V(0.05, 0.05, 0.05), m_a, V(0.05, 0.03, 0.03), m_b, e);
  ImpactMonitor monitor(scene, MonitorSettings{});
  monitor.step(0.0, {stateOf(monitor, "a", V(-0.2, 0, 0), V(v_a, 0, 0)),
                     stateOf(monitor, "b", V(0.2, 0, 0), V(v_b, 0, 0))});
  std::vector<ImpactRecord> impacts;
  for (int k = 1; k <= 30; ++k) {
    const StepReport report = monitor.step(0.01 * k, {});
    for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << c.what;
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
  }
  ASSERT_EQ(impacts.size(), 4u);
  const double after_a = (m_a * v_a + m_b * v_b - m_b * e * (v_a - v_b)) / (m_a + m_b);
  const double after_b = after_a + e * (v_a - v_b);
  double lost = 0.0;
  for (const ImpactRecord& impact : impacts) {
    EXPECT_NEAR(impact.time, 0.15, 1e-11);
    EXPECT_FALSE(impact.other_is_obstacle);
    EXPECT_NEAR(impact.velocity_a_after.x(), after_a, 1e-12);
    EXPECT_NEAR(impact.velocity_b_after.x(), after_b, 1e-12);
    EXPECT_NEAR(impact.velocity_a_after.tail<2>().norm(), 0.0, 1e-12);
    EXPECT_NEAR(impact.angular_velocity_a_after.norm(), 0.0, 1e-12);
    EXPECT_NEAR(impact.angular_velocity_b_after.norm(), 0.0, 1e-12);
    lost += impact.energy_lost;
  }
  const double d = v_a - v_b;
  EXPECT_NEAR(lost, 0.5 * m_a * m_b / (m_a + m_b) * (1 - e * e) * d * d, 1e-12);
  const auto a = monitor.predictedState(*monitor.bodyIndex("a"), 0.3);
  const auto b = monitor.predictedState(*monitor.bodyIndex("b"), 0.3);
  ASSERT_TRUE(a && b);
  EXPECT_NEAR(a->first.x(), -0.05 + after_a * 0.15, 1e-11);
  EXPECT_NEAR(b->first.x(), 0.05 + after_b * 0.15, 1e-11);
}

// A cube (e 1/2, frictionless) dropped flat from rest onto an equal cube resting on the floor: the
// resting cube is still, the pair watched exactly, and the upper one lands on it at the parabola's
// instant sqrt(2 h / g) (1e-11 s), h its fall to the lower box's top, with its four corners at
// once. Each impact is the pair's alone (the lower box then strikes the floor at that instant:
// the floor and the pair are not one joint solve yet). When the upper box comes to rest on the
// lower one, that lasting contact is not modelled yet: both are held, reported once, naming both,
// neither ever inside the other. (Face to face after an impact, GJK sees the pair overlap by its
// tolerance: before, that was taken as an impact missed, and the upper cube fell through.)
TEST(ShapedPairs, ABoxDroppedOnABoxRestingOnTheFloorLandsOnItAtTheParabolasInstant) {
  const V half(0.05, 0.05, 0.05);
  const double h = 0.2;
  Scene scene = twoBoxes(half, 1.0, half, 1.0, 0.5);
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -9.81);
  scene.obstacles = {scene_builders::plane("floor", V::UnitZ(), 0.0, "concrete")};
  ImpactMonitor monitor(scene, MonitorSettings{});
  const std::size_t upper = *monitor.bodyIndex("a"), lower = *monitor.bodyIndex("b");
  monitor.step(0.0, {stateOf(monitor, "a", V(0, 0, 3 * half.z() + h), V::Zero()),
                     stateOf(monitor, "b", V(0, 0, half.z()), V::Zero())});
  std::vector<ImpactRecord> impacts;
  std::vector<UnmodelledContact> unmodelled;
  for (int k = 1; k <= 100; ++k) {
    const StepReport report = monitor.step(0.01 * k, {});
    impacts.insert(impacts.end(), report.impacts.begin(), report.impacts.end());
    unmodelled.insert(unmodelled.end(), report.unmodelled.begin(), report.unmodelled.end());
    const auto top = monitor.predictedState(upper, 0.01 * k);
    const auto bottom = monitor.predictedState(lower, 0.01 * k);
    ASSERT_TRUE(top && bottom);
    EXPECT_GE(bottom->first.z(), half.z() - 1e-9) << 0.01 * k;
    EXPECT_GE(top->first.z() - bottom->first.z(), 2 * half.z() - 1e-9) << 0.01 * k;
  }
  ASSERT_GE(impacts.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(impacts[k].time, std::sqrt(2 * h / 9.81), 1e-11);
    EXPECT_FALSE(impacts[k].other_is_obstacle);
    EXPECT_EQ(impacts[k].body_a, upper);
    EXPECT_EQ(impacts[k].other, lower);
  }
  // The lower box, struck down onto the floor it rests on, strikes it at that instant (its
  // records reported as any impact's).
  const auto on_floor = std::find_if(impacts.begin(), impacts.end(), [&](const ImpactRecord& i) {
    return i.body_a == lower && i.other_is_obstacle;
  });
  ASSERT_NE(on_floor, impacts.end());
  EXPECT_NEAR(on_floor->time, std::sqrt(2 * h / 9.81), 1e-11);
  EXPECT_LT(on_floor->velocity_a_before.z(), 0.0);
  ASSERT_EQ(unmodelled.size(), 1u);
  EXPECT_EQ(unmodelled[0].body, upper);
  EXPECT_EQ(unmodelled[0].other, lower);
  EXPECT_NE(unmodelled[0].what.find("lasting contact"), std::string::npos) << unmodelled[0].what;
}

// config/scenes/box_collide.yaml in the core: two 0.125 m cubes (0.5 kg, and 1 kg given as a
// mesh: the cube's 12 triangles, its hull) sliding on a frictionless floor into each other, e =
// 1/2, then the heavier into a wall at x = 0.425: the faces meet at t1 = (0.6 - 0.125) / 1.5 s
// (1e-11 s), leaving at -0.5 and 0.25 m/s (the line of impact's closed form, 1e-12), and the
// wall is struck at t1 + (0.425 - 0.0625 - 0.3 + 0.5 t1) / 0.25 = 1.2 s (1e-10 s), the mesh
// leaving it at -0.125 m/s.
TEST(ShapedPairs, TwoBoxesSlidingIntoEachOtherThenAWallAsTheSceneSays) {
  const V half(0.0625, 0.0625, 0.0625);
  Scene scene = twoBoxes(half, 0.5, half, 1.0, 0.5);
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -9.81);
  scene.bodies[1].shape = BodyShape::kMesh;
  scene.bodies[1].size = V::Zero();
  scene.bodies[1].mesh = scene_builders::cubeMesh(half);
  scene.obstacles = {scene_builders::plane("floor", V::UnitZ(), 0.0, "concrete"),
                     scene_builders::plane("wall", -V::UnitX(), -0.425, "concrete")};
  MonitorSettings settings;
  settings.body_timeout = 10.0;  // one state each, followed for 1.5 s
  ImpactMonitor monitor(scene, settings);
  monitor.step(0.0, {stateOf(monitor, "a", V(-0.3, 0, 0.0625), V(1.0, 0, 0)),
                     stateOf(monitor, "b", V(0.3, 0, 0.0625), V(-0.5, 0, 0))});
  std::vector<ImpactRecord> pair, wall;
  for (int k = 1; k <= 150; ++k) {
    const StepReport report = monitor.step(0.01 * k, {});
    for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << c.what;
    for (const ImpactRecord& impact : report.impacts) {
      if (!impact.other_is_obstacle) pair.push_back(impact);
      if (impact.other_is_obstacle && impact.other == 1) wall.push_back(impact);
    }
  }
  ASSERT_EQ(pair.size(), 4u);
  for (const ImpactRecord& impact : pair) {
    EXPECT_NEAR(impact.time, 0.475 / 1.5, 1e-11);
    EXPECT_NEAR(impact.velocity_a_after.x(), -0.5, 1e-12);
    EXPECT_NEAR(impact.velocity_b_after.x(), 0.25, 1e-12);
  }
  ASSERT_EQ(wall.size(), 4u);
  for (const ImpactRecord& impact : wall) {
    EXPECT_EQ(impact.other, 1u);
    EXPECT_NEAR(impact.time, 1.2, 1e-10);
    EXPECT_NEAR(impact.velocity_a_after.x(), -0.125, 1e-12);
  }
}

/// kg m/s and kg m^2/s: the linear momentum and the angular momentum about the origin of the
/// monitor's shaped bodies at `time`, and their kinetic energy (J).
struct Momenta {
  V linear = V::Zero();
  V angular = V::Zero();
  double energy = 0.0;
};
Momenta momentaOf(const ImpactMonitor& monitor, const Scene& scene, double time) {
  Momenta total;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const auto state = monitor.predictedState(i, time);
    EXPECT_TRUE(state);
    const double m = scene.bodies[i].mass;
    const V w = monitor.predictedAngularVelocity(i, time);
    const Eigen::Matrix3d turn = monitor.predictedOrientation(i, time).toRotationMatrix();
    const V s = scene.bodies[i].size;
    const Eigen::Matrix3d inertia = turn *
                                    (m / 12 *
                                     V(s.y() * s.y() + s.z() * s.z(), s.x() * s.x() + s.z() * s.z(),
                                       s.x() * s.x() + s.y() * s.y()))
                                        .asDiagonal() *
                                    turn.transpose();
    total.linear += m * state->second;
    total.angular += state->first.cross(m * state->second) + inertia * w;
    total.energy += 0.5 * m * state->second.squaredNorm() + 0.5 * w.dot(inertia * w);
  }
  return total;
}

// Two boxes of three different sides thrown at each other tumbling, in empty space, 30 random
// throws (e in [0.5, 1], frictionless: with less, turning bodies come to rest on each other more
// often): wherever they meet, at a corner, an edge or a face, their
// impacts keep the total linear momentum (1e-12 relative: the impulses are equal and opposite)
// and the angular momentum about the origin (1e-11 relative: the same points, and the exact free
// rotations' orientations, by elliptic functions, read back at the end) and never gain energy
// (1e-12 relative); after each throw they are apart, never inside each other (their gap by GJK).
// A throw whose bodies, turning into each other, strike again and again ever more slowly comes to
// a lasting contact, which is not modelled yet: both are held there, reported (its momentum is
// then not kept: such throws are counted, not checked for it).
TEST(ShapedPairs, RandomTumblingThrowsKeepMomentumAndNeverGainEnergyNorEndInside) {
  std::mt19937_64 random(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int met = 0, held = 0;
  for (int throw_index = 0; throw_index < 30; ++throw_index) {
    const double e = 0.75 + 0.25 * unit(random);
    const Scene scene = twoBoxes(V(0.06, 0.04, 0.02), 1.5, V(0.05, 0.03, 0.025), 0.8, e);
    ImpactMonitor monitor(scene, MonitorSettings{});
    const Q turn_a = Q(Eigen::AngleAxisd(3 * unit(random), V::Random().normalized()));
    const Q turn_b = Q(Eigen::AngleAxisd(3 * unit(random), V::Random().normalized()));
    const V aim = 0.03 * V(0, unit(random), unit(random));
    monitor.step(0.0, {stateOf(monitor, "a", V(-0.3, 0, 0), V(1.5 + unit(random), 0, 0) + aim,
                               turn_a, 20 * V(unit(random), unit(random), unit(random))),
                       stateOf(monitor, "b", V(0.3, 0, 0), V(-1 + unit(random), 0, 0), turn_b,
                               20 * V(unit(random), unit(random), unit(random)))});
    const Momenta before = momentaOf(monitor, scene, 0.0);
    std::size_t impacts = 0, unmodelled = 0;
    for (int k = 1; k <= 50; ++k) {
      const StepReport report = monitor.step(0.01 * k, {});
      for (const UnmodelledContact& c : report.unmodelled) {
        EXPECT_NE(c.what.find("two shaped bodies in lasting contact"), std::string::npos) << c.what;
        EXPECT_FALSE(c.other_is_obstacle);
      }
      unmodelled += report.unmodelled.size();
      impacts += report.impacts.size();
    }
    const Momenta after = momentaOf(monitor, scene, 0.5);
    met += impacts > 0;
    held += unmodelled > 0;
    if (unmodelled == 0) {
      EXPECT_LT((after.linear - before.linear).norm(), 1e-12 * before.linear.norm() + 1e-14)
          << throw_index;
      EXPECT_LT((after.angular - before.angular).norm(), 1e-11 * before.angular.norm() + 1e-14)
          << throw_index;
    }
    EXPECT_LE(after.energy, before.energy * (1 + 1e-12)) << throw_index;
    std::vector<TumblingBody> bodies;
    for (std::size_t i = 0; i < 2; ++i) {
      const auto state = monitor.predictedState(i, 0.5);
      const V half = 0.5 * scene.bodies[i].size;
      auto body = TumblingBody::create(Cuboid{half}, V::Ones(), 0.5, state->first, state->second,
                                       V::Zero(), monitor.predictedOrientation(i, 0.5),
                                       monitor.predictedAngularVelocity(i, 0.5));
      ASSERT_TRUE(body.ok());
      bodies.push_back(body.value());
    }
    const SurfaceGap gap = gapAt(bodies[0], bodies[1], 0.5);
    EXPECT_FALSE(gap.overlapping) << throw_index;
    EXPECT_GE(gap.gap_upper, 0.0) << throw_index;
  }
  EXPECT_GE(met, 25);  // the throws meet
  EXPECT_LE(held, 5);  // and few come to a lasting contact
}

}  // namespace
}  // namespace collision_response::core
