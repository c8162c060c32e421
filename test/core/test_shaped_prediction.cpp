// A shaped body's prediction (src/core/monitor/shaped_prediction.h): flight, first contacts and
// impacts with rotation against the closed forms; what it does not model yet said, not hidden.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "collision_response/core/prediction.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using scene_builders::plane;

constexpr double kG = 9.81;

/// A box of edges 2 half over a concrete floor at z = 0, its material `e` against concrete.
Scene floorScene(double e, const V& half, double mass = 2.0) {
  Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -kG);
  EXPECT_TRUE(scene.materials.addMaterial("block", Material{e, 0.0}, "m").ok());
  BodySpec body;
  body.id = "block";
  body.mass = mass;
  body.material = "block";
  body.shape = BodyShape::kBox;
  body.size = 2 * half;
  scene.bodies = {body};
  scene.obstacles = {plane("floor", V::UnitZ(), 0.0, "concrete")};
  return scene;
}

PredictionRequest dropped(const Scene& scene, const V& position, const Eigen::Quaterniond& turn,
                          double horizon, std::size_t max_impacts) {
  PredictionRequest request;
  request.body = scene.bodies[0];
  request.state.position = position;
  request.state.orientation = turn;
  request.horizon = horizon;
  request.max_impacts = max_impacts;
  request.effects = scene.effects;
  return request;
}

// A box of e = 1 dropped flat from rest strikes with its four corners at once at the parabola's
// instant, leaves at the speed it came without turning, and is back at its drop height when the
// parabola says: the height to 1e-9 m (issue 42's "Done when").
TEST(ShapedPrediction, ElasticBoxDroppedFlatReturnsToItsDropHeight) {
  const V half(0.1, 0.05, 0.025);
  const Scene scene = floorScene(1.0, half);
  const double height = 1.0;  // the centre's
  const double fall = std::sqrt(2 * (height - half.z()) / kG);
  // At the top again after two falls: the horizon there, the impacts of the first landing only.
  auto request = dropped(scene, V(0.3, -0.2, height), Eigen::Quaterniond::Identity(), 2 * fall, 8);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_EQ(prediction->impacts.size(), 4u) << prediction->message;
  const double speed = kG * fall;
  for (const ImpactRecord& impact : prediction->impacts) {
    EXPECT_NEAR(impact.time, fall, 1e-11);
    EXPECT_NEAR(impact.contact_point.z(), 0.0, 1e-9);
    EXPECT_NEAR(impact.impulse, 2.0 * 2 * speed / 4, 1e-9);  // (1 + e) m v over four corners
    EXPECT_NEAR(impact.velocity_a_after.z(), speed, 1e-9);
    EXPECT_LE(impact.angular_velocity_a_after.norm(), 1e-9);
    EXPECT_NEAR(impact.energy_lost, 0.0, 1e-9);
  }
  EXPECT_NEAR(prediction->final_state.position.z(), height, 1e-9);
  EXPECT_NEAR(prediction->final_state.velocity.z(), 0.0, 1e-9);
  EXPECT_NEAR(prediction->final_state.position.x(), 0.3, 1e-15);
  EXPECT_LE(prediction->final_state.orientation.angularDistance(Eigen::Quaterniond::Identity()),
            1e-12);
}

// A box turned by theta about y lands on the edge of its two lowest corners, (a cos theta -
// c sin theta, +-b, -(a sin theta + c cos theta)) from its centre. Frictionless, the two take
// equal impulses whose moments about x cancel: as one contact at (x, 0, z), whose effective mass
// along z is 1 / (1/m + x^2 / I_yy), I_yy = m (a^2 + c^2) / 3. So J = (1 + e) v / (1/m + x^2 /
// I_yy), v_z' = -v + J / m, w_y' = -x J / I_yy (the floor's impulse +J z at r = (x, ., z)).
TEST(ShapedPrediction, BoxLandingOnAnEdgeTurnsAsTheClosedFormSays) {
  const double a = 0.1, b = 0.05, c = 0.025, m = 2.0, e = 0.5, theta = 0.3;
  const Scene scene = floorScene(e, V(a, b, c), m);
  const double low = a * std::sin(theta) + c * std::cos(theta);
  const double height = 0.5;
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(theta, V::UnitY()));
  auto request = dropped(scene, V(0, 0, height), turn, 0.5, 2);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_EQ(prediction->impacts.size(), 2u) << prediction->message;
  const double fall = std::sqrt(2 * (height - low) / kG), v = kG * fall;
  const double x = a * std::cos(theta) - c * std::sin(theta);
  const double inertia = m * (a * a + c * c) / 3;
  const double impulse = (1 + e) * v / (1 / m + x * x / inertia);
  double total = 0.0;
  for (const ImpactRecord& impact : prediction->impacts) {
    EXPECT_NEAR(impact.time, fall, 1e-11);
    total += impact.impulse;
    EXPECT_NEAR(impact.velocity_a_after.z(), -v + impulse / m, 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.y(), -x * impulse / inertia, 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.x(), 0.0, 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.z(), 0.0, 1e-9);
  }
  EXPECT_NEAR(total, impulse, 1e-9);
}

// A cube's inertia is isotropic, so its answer does not depend on how it is turned about the
// vertical: landing flat, turned by any angle about z, the same impacts and the same state.
TEST(ShapedPrediction, ACubeTurnedAboutTheVerticalGivesTheSameAnswer) {
  const Scene scene = floorScene(0.7, V(0.05, 0.05, 0.05));
  std::optional<Prediction> first;
  for (const double angle : {0.0, 0.4, 1.1, 2.9}) {
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(angle, V::UnitZ()));
    auto request = dropped(scene, V(0, 0, 0.4), turn, 1.0, 100);
    const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
    ASSERT_TRUE(prediction.ok()) << prediction.error().message();
    if (!first) {
      first = *prediction;
      ASSERT_GE(first->impacts.size(), 8u);
      continue;
    }
    ASSERT_EQ(prediction->impacts.size(), first->impacts.size()) << angle;
    for (std::size_t i = 0; i < prediction->impacts.size(); i += 4) {
      EXPECT_NEAR(prediction->impacts[i].time, first->impacts[i].time, 1e-11) << angle;
      EXPECT_NEAR(prediction->impacts[i].velocity_a_after.z(),
                  first->impacts[i].velocity_a_after.z(), 1e-9)
          << angle;
    }
    EXPECT_NEAR(prediction->final_state.position.z(), first->final_state.position.z(), 1e-9);
  }
}

// A box of e < 1 bouncing flat bounces lower each time, the heights e^2 apart, until its bounces
// accumulate: there its contact would last, which is not modelled yet for a shaped body. The
// prediction ends there and says so (cut short), rather than passing through the floor or
// bouncing for ever.
TEST(ShapedPrediction, BouncesThatAccumulateEndThePredictionSayingWhy) {
  const double e = 0.5;
  const V half(0.05, 0.05, 0.05);
  const Scene scene = floorScene(e, half);
  auto request = dropped(scene, V(0, 0, 0.5), Eigen::Quaterniond::Identity(), 10.0, 1000);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_TRUE(prediction->cut_short);
  EXPECT_NE(prediction->message.find("lasting contact with 'floor'"), std::string::npos)
      << prediction->message;
  // The bounces' instants: t_1 = fall, then each flight 2 e^k v / g.
  const double fall = std::sqrt(2 * (0.5 - half.z()) / kG), v = kG * fall;
  double t = fall, speed = v;
  for (std::size_t k = 0; k + 4 <= std::min<std::size_t>(prediction->impacts.size(), 40); k += 4) {
    EXPECT_NEAR(prediction->impacts[k].time, t, 1e-9 * static_cast<double>(1 + k)) << k;
    speed *= e;
    t += 2 * speed / kG;
  }
  // Never below the floor: the centre's height at the end at least the half height.
  EXPECT_GE(prediction->final_state.position.z(), half.z() - 1e-9);
  EXPECT_LT(prediction->final_state.time, 10.0);
}

/// The lowest point's height of a body's shape at `state` (the closed forms of each shape's
/// support along -z), and its kinetic plus potential energy (the uniform solid's moments).
struct ShapeCheck {
  BodySpec body;
  double lowest(const BodyStateSample& state) const {
    const Eigen::Matrix3d rotation = state.orientation.toRotationMatrix();
    const V down = rotation.transpose() * V(0, 0, -1);  // -z in the body's frame
    double reach = 0.0;
    if (body.shape == BodyShape::kBox) {
      reach = (0.5 * body.size).dot(down.cwiseAbs());
    } else {
      const double h = 0.5 * body.length, along = std::abs(down.z());
      const double across = std::sqrt(std::max(0.0, 1 - along * along));
      reach = body.shape == BodyShape::kCylinder ? body.radius * across + h * along
                                                 : body.radius + h * along;
    }
    return state.position.z() - reach;
  }
  V moments() const {
    const double m = body.mass;
    if (body.shape == BodyShape::kBox) {
      const V s = body.size.cwiseProduct(body.size);
      return m / 12 * V(s.y() + s.z(), s.x() + s.z(), s.x() + s.y());
    }
    const double r = body.radius, h = body.length;
    if (body.shape == BodyShape::kCylinder) {
      const double across = m * (3 * r * r + h * h) / 12;
      return V(across, across, m * r * r / 2);
    }
    const double mc = m * h / (h + 4 * r / 3), ms = m - mc;  // the capsule's closed form
    const double across =
        mc * (3 * r * r + h * h) / 12 + ms * (0.4 * r * r + h * h / 4 + 3 * h * r / 8);
    return V(across, across, mc * r * r / 2 + 0.4 * ms * r * r);
  }
  double energy(const BodyStateSample& state) const {
    const V w = state.orientation.conjugate() * state.angular_velocity;
    return 0.5 * body.mass * state.velocity.squaredNorm() + 0.5 * w.dot(moments().cwiseProduct(w)) +
           body.mass * kG * state.position.z();
  }
};

// Boxes, cylinders and capsules thrown tumbling onto the floor, with friction (one corner at a
// time by Chatterjee and Ruina's law, several at once frictionless): sampled every millisecond,
// no point of any is ever below the floor by more than the contact's rounding, and the energy
// (kinetic, rotational and potential) never grows, from throw to throw's end.
TEST(ShapedPrediction, TumblingThrowsNeverGoInsideNorGainEnergy) {
  std::mt19937_64 random(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int impacts = 0;
  for (int throw_index = 0; throw_index < 30; ++throw_index) {
    Scene scene = floorScene(0.6, V(0.05, 0.03, 0.02));
    scene.effects.friction = true;
    ASSERT_TRUE(scene.materials.addPair("block", "concrete", PairCoefficients{0.6, 0.4}, "p").ok());
    BodySpec& body = scene.bodies[0];
    body.shape =
        std::array{BodyShape::kBox, BodyShape::kCylinder, BodyShape::kCapsule}[throw_index % 3];
    if (body.shape != BodyShape::kBox) {
      body.size = V::Zero();
      body.radius = 0.03 + 0.02 * std::abs(unit(random));
      body.length = 0.05 + 0.1 * std::abs(unit(random));
    }
    const Eigen::Quaterniond turn =
        Eigen::Quaterniond(unit(random), unit(random), unit(random), unit(random)).normalized();
    auto request = dropped(scene, V(0, 0, 0.4 + 0.3 * std::abs(unit(random))), turn, 1.5, 1000);
    request.state.velocity = V(unit(random), unit(random), -std::abs(unit(random)));
    request.state.angular_velocity = 10 * V(unit(random), unit(random), unit(random));
    request.sample_period = 1e-3;
    const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
    ASSERT_TRUE(prediction.ok()) << prediction.error().message();
    impacts += static_cast<int>(prediction->impacts.size());
    const ShapeCheck check{body};
    BodyStateSample start = request.state;
    const double energy = check.energy(start);
    for (const BodyStateSample& sample : prediction->samples) {
      EXPECT_GE(check.lowest(sample), -1e-9) << throw_index << " at " << sample.time;
      EXPECT_LE(check.energy(sample), energy + 1e-9 * std::abs(energy))
          << throw_index << " at " << sample.time;
    }
  }
  EXPECT_GE(impacts, 30);
}

TEST(ShapedPrediction, ABoxRestingOnTheFloorIsSaidToLastNotPredicted) {
  const V half(0.05, 0.05, 0.05);
  const Scene scene = floorScene(0.5, half);
  auto request = dropped(scene, V(0, 0, half.z()), Eigen::Quaterniond::Identity(), 1.0, 10);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_TRUE(prediction->impacts.empty());
  EXPECT_TRUE(prediction->cut_short);
  EXPECT_NE(prediction->message.find("not yet modelled"), std::string::npos) << prediction->message;
  EXPECT_EQ(prediction->final_state.time, 0.0);
}

TEST(ShapedPrediction, WhatIsNotModelledYetIsRefusedByName) {
  Scene scene = floorScene(0.5, V(0.05, 0.05, 0.05));
  auto request = dropped(scene, V(0, 0, 1), Eigen::Quaterniond::Identity(), 1.0, 10);
  request.effects.drag = true;
  auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_FALSE(prediction.ok());
  EXPECT_EQ(prediction.error().field, "effects");

  request = dropped(scene, V(0, 0, 1), Eigen::Quaterniond(0, 0, 0, 0), 1.0, 10);
  prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_FALSE(prediction.ok());
  EXPECT_EQ(prediction.error().field, "body.orientation");

  request = dropped(scene, V(0, 0, 0.01), Eigen::Quaterniond::Identity(), 1.0, 10);
  prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_FALSE(prediction.ok());
  EXPECT_EQ(prediction.error().field, "body.position") << prediction.error().message();

  request = dropped(scene, V(0, 0, 1), Eigen::Quaterniond::Identity(), 1.0, 10);
  request.body.shape = BodyShape::kCylinder;  // no radius nor length
  prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_FALSE(prediction.ok());
  EXPECT_EQ(prediction.error().field.rfind("body.", 0), 0u) << prediction.error().message();
}

}  // namespace
}  // namespace collision_response::core
