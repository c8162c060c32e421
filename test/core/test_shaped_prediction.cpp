// A shaped body's prediction (src/core/monitor/shaped_prediction.h): flight, first contacts and
// impacts with rotation against the closed forms; what it does not model yet said, not hidden.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "collision_response/core/prediction.h"
#include "scene_builders.h"
#include "shaped_scenes.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using scene_builders::plane;

using shaped_scenes::AcrossSlope;
using shaped_scenes::EdgeLanding;
using shaped_scenes::floorScene;
using shaped_scenes::kG;
using shaped_scenes::RimFall;
using shaped_scenes::tableScene;

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

// A box turned by theta about y lands on the edge of its two lowest corners: the closed form's
// impulse and spin (shaped_scenes::EdgeLanding).
TEST(ShapedPrediction, BoxLandingOnAnEdgeTurnsAsTheClosedFormSays) {
  const EdgeLanding edge;
  const Scene scene = floorScene(edge.e, V(edge.a, edge.b, edge.c), edge.m);
  auto request = dropped(scene, V(0, 0, edge.height), edge.turn(), 0.5, 2);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_EQ(prediction->impacts.size(), 2u) << prediction->message;
  expectTheEdgeLanding(edge, prediction->impacts);
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
// accumulate: it rests on the floor from their end, fall + 2 e v / (g (1 - e)) (flatBouncesEnd,
// as a ball's: doc/model.md, "Coming to rest"), to the horizon, never passing through the floor
// nor bouncing for ever. At rest each corner carries m g / 4 (statics: four equal supports
// symmetric about the centre).
TEST(ShapedPrediction, BouncesThatAccumulateComeToRestOnTheFloor) {
  const double e = 0.5, m = 2.0;
  const V half(0.05, 0.05, 0.05);
  const Scene scene = floorScene(e, half, m);
  auto request = dropped(scene, V(0, 0, 0.5), Eigen::Quaterniond::Identity(), 10.0, 1000);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_FALSE(prediction->cut_short) << prediction->message;
  // The bounces' instants: t_1 = fall, then each flight 2 e^k v / g.
  const double fall = std::sqrt(2 * (0.5 - half.z()) / kG), v = kG * fall;
  double t = fall, speed = v;
  for (std::size_t k = 0; k + 4 <= std::min<std::size_t>(prediction->impacts.size(), 40); k += 4) {
    EXPECT_NEAR(prediction->impacts[k].time, t, 1e-9 * static_cast<double>(1 + k)) << k;
    speed *= e;
    t += 2 * speed / kG;
  }
  // At rest on the floor at the horizon, from the bounces' end.
  EXPECT_EQ(prediction->final_state.time, 10.0);
  EXPECT_NEAR(prediction->final_state.position.z(), half.z(), 1e-9);
  EXPECT_LE(prediction->final_state.velocity.norm(), 1e-12);
  EXPECT_LE(prediction->final_state.angular_velocity.norm(), 1e-12);
  ASSERT_EQ(prediction->contacts.size(), 4u);
  const double rests = fall + 2 * e * v / (kG * (1 - e));
  for (const ContactRecord& contact : prediction->contacts) {
    EXPECT_NEAR(contact.normal_force, m * kG / 4, 1e-9);
    EXPECT_EQ(contact.state, ContactState::kResting);
    EXPECT_NEAR(contact.since, rests, 1e-9);
    EXPECT_NEAR(contact.contact_point.z(), 0.0, 1e-9);
  }
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

// A box dropped flat 1 cm onto the floor (e = 0.5) while drifting at u = 1e-5 m/s towards a
// wall 0.06 u away: its four corners strike the floor at sqrt(2 (0.01) / g), and in the flight
// after it the face touches the wall at 0.06 s, approaching too slowly to bounce (lift u^2 / 2
// below 1e-6 of its reach times g): the prediction ends there, saying its contact with the wall
// would last. Before, the floor's points were looked at again from the floor's impact, where they
// still touched it, and the wall's from its graze: found again at once, each in turn, for ever
// (the CPU budget of 2 s ran out at +0.045 s, the floor's instant).
TEST(ShapedPrediction, AGrazeAfterAnImpactDoesNotFindTheImpactAgainForEver) {
  const V half(0.05, 0.05, 0.05);
  Scene scene = floorScene(0.5, half);
  scene.obstacles.push_back(plane("wall", V(-1, 0, 0), -0.1, "concrete"));
  const double u = 1e-5, touch = 0.06;
  auto request = dropped(scene, V(0.1 - half.x() - u * touch, 0, half.z() + 0.01),
                         Eigen::Quaterniond::Identity(), 0.2, 100);
  request.state.velocity = V(u, 0, 0);
  PredictionBudget budget;
  budget.seconds = 2.0;
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request, budget);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_FALSE(prediction->out_of_budget) << prediction->message;
  ASSERT_EQ(prediction->impacts.size(), 4u) << prediction->message;
  for (const ImpactRecord& impact : prediction->impacts) {
    EXPECT_NEAR(impact.time, std::sqrt(2 * 0.01 / kG), 1e-11);
    EXPECT_EQ(prediction->model->obstacle(impact.other).id, "floor");
  }
  EXPECT_NE(prediction->message.find("lasting contact with 'wall'"), std::string::npos)
      << prediction->message;
  EXPECT_NEAR(prediction->final_state.time, touch, 1e-8);
  EXPECT_NEAR(prediction->final_state.position.x() + half.x(), 0.1, 1e-12);
}

// A box given at rest on the floor rests there to the horizon (lastingOnFace), each corner
// carrying m g / 4, the contact lasting from the request's instant.
TEST(ShapedPrediction, ABoxRestingOnTheFloorRestsThere) {
  const V half(0.05, 0.04, 0.03);
  const double m = 2.0;
  const Scene scene = floorScene(0.5, half, m);
  auto request = dropped(scene, V(0.1, 0.2, half.z()), Eigen::Quaterniond::Identity(), 1.0, 10);
  request.sample_period = 0.25;
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_TRUE(prediction->impacts.empty());
  EXPECT_FALSE(prediction->cut_short) << prediction->message;
  EXPECT_EQ(prediction->final_state.time, 1.0);
  EXPECT_EQ(prediction->final_state.position, V(0.1, 0.2, half.z()));
  ASSERT_EQ(prediction->samples.size(), 5u);
  for (const BodyStateSample& sample : prediction->samples) {
    EXPECT_EQ(sample.position, V(0.1, 0.2, half.z())) << sample.time;
  }
  ASSERT_EQ(prediction->contacts.size(), 4u);
  for (const ContactRecord& contact : prediction->contacts) {
    EXPECT_NEAR(contact.normal_force, m * kG / 4, 1e-12);
    EXPECT_EQ(contact.since, 0.0);
    EXPECT_EQ(contact.state, ContactState::kResting);
  }
}

// A box given at rest on one of its edges (turned by 0.3 rad about y, its lowest edge on the
// frictionless floor) tips over it: its centre falls straight down (the floor's force is
// vertical), at the height h(phi) its tilt gives, and its face lands at the energy integral's
// instant (EdgeLanding::tipInstant, 1e-8 s: the integration's tolerance 1e-9), never through the
// floor. Before, the prediction ended there: tipping was not modelled.
TEST(ShapedPrediction, ABoxTippingOverAFrictionlessEdgeLandsOnItsFaceAtTheEnergyIntegralsInstant) {
  const EdgeLanding edge;
  const Scene scene = floorScene(edge.e, V(edge.a, edge.b, edge.c), edge.m);
  auto request = dropped(scene, V(0, 0, edge.low()), edge.turn(), 1.0, 1);
  request.sample_period = 0.01;
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_FALSE(prediction->impacts.empty()) << prediction->message;
  const double landing = edge.tipInstant();
  EXPECT_NEAR(prediction->impacts.front().time, landing, 1e-8);
  for (const BodyStateSample& sample : prediction->samples) {
    if (sample.time >= landing) break;
    EXPECT_NEAR(sample.position.x(), 0.0, 1e-9) << sample.time;
    EXPECT_NEAR(sample.position.y(), 0.0, 1e-12) << sample.time;
    const Eigen::AngleAxisd tilt(sample.orientation);
    const double phi = tilt.angle() * tilt.axis().y();
    EXPECT_NEAR(sample.position.z(), edge.heightAt(phi), 1e-9) << sample.time;
  }
}

// The same tipping on a table top (a box obstacle, its distances by GJK to 1e-12 m) lands at the
// same instant: the tipping hands the body over a hair above the top (1e-11 m), never
// overlapping it by the distance's tolerance. Before, the body touching exactly was taken as
// starting inside the top, its first contact never found, and it fell through (to z = -0.3 m).
TEST(ShapedPrediction, ABoxTippingOnATableTopLandsOnItNeverThroughIt) {
  const EdgeLanding edge;
  Scene scene = floorScene(edge.e, V(edge.a, edge.b, edge.c), edge.m);
  scene.obstacles = {
      scene_builders::box("table", V(0, 0, 0.745), V(2.74, 1.525, 0.03), "concrete")};
  auto request = dropped(scene, V(-1.0, 0, 0.76 + edge.low() + 1e-12), edge.turn(), 0.5, 1);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_FALSE(prediction->impacts.empty()) << prediction->message;
  EXPECT_NEAR(prediction->impacts.front().time, edge.tipInstant(), 1e-8);
  EXPECT_NEAR(prediction->final_state.position.z(), 0.76 + edge.c, 1e-9);
}

// A can given at rest leaning on its rim (its axis turned by 0.3 rad about x) on the frictionless
// floor tips back over its rim, its centre falling straight down, and its cap lands flat at the
// energy integral's instant (RimFall::landing): the prediction's first impacts, the cap's rim's
// points at once, there (1e-8 s).
// Before, the prediction ended where it began, saying the contact was not modelled.
TEST(ShapedPrediction, ACanLeaningOnItsRimFallsBackOntoItsCapAtTheEnergyIntegralsInstant) {
  const RimFall fall;
  const Scene scene = fall.scene();
  auto request = dropped(scene, fall.centre(), fall.orientation(), 1.0, 1);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  ASSERT_FALSE(prediction->impacts.empty()) << prediction->message;
  for (const ImpactRecord& impact : prediction->impacts) {
    EXPECT_NEAR(impact.time, fall.landing(), 1e-8) << "the cap's rim lands at once";
  }
  EXPECT_NEAR(prediction->final_state.position.y(), 0.0, 1e-10) << "straight down";
}

// A box sliding across a table's top onto its corner (ShapedMonitor.ABoxSlidingOntoATablesCorner
// GoesOverItAndFalls): the prediction carries it over the corner and off it, not cut short, its
// next impact the floor's. Before, it ended at 0.3 s, "not yet: the body overhangs two of the
// face's edges".
TEST(ShapedPrediction, ABoxSlidingOntoATablesCornerGoesOverItToTheFloor) {
  Scene scene = tableScene(0.5, V(0.05, 0.05, 0.05), 1.0);
  auto request = dropped(scene, V(0.3, 0.3, 0.55), Eigen::Quaterniond::Identity(), 1.0, 10);
  request.state.velocity = V(0.5, 0.5, 0);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_FALSE(prediction->cut_short) << prediction->message;
  ASSERT_FALSE(prediction->impacts.empty());
  EXPECT_EQ(prediction->impacts.front().other, 0u) << "the floor";
  EXPECT_GT(prediction->impacts.front().time, 0.3);
}

// A cube sliding across an incline turns down it and stops (AcrossSlope's closed form): the
// prediction carries it there, at rest at the horizon where the path's integral puts it (1e-8 m),
// not cut short. Before, the prediction ended at once, "not yet: sliding across the slope".
TEST(ShapedPrediction, ACubeSlidingAcrossAnInclineIsPredictedToRestWhereTheClosedFormSays) {
  const AcrossSlope slope;
  const Scene scene = slope.scene();
  const BodyStateSample state = slope.state(0, 0.0);
  auto request = dropped(scene, state.position, state.orientation, 1.0, 10);
  request.state.velocity = state.velocity;
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_TRUE(prediction->impacts.empty());
  EXPECT_FALSE(prediction->cut_short) << prediction->message;
  EXPECT_EQ(prediction->final_state.time, 1.0);
  EXPECT_LT((prediction->final_state.position - state.position - AcrossSlope::moved(0.0)).norm(),
            1e-8);
  EXPECT_EQ(prediction->final_state.velocity, V::Zero());
}

// A can standing on its cap on a floor of mu 0.5, spinning at 3 rad/s about the vertical: its
// four rim points' friction stops it at (w0 - 1e-6 / r) r / (2 mu g) (ShapedRim's closed form),
// where it rests: at the horizon it is where it stood, still. Before, the prediction ended at
// once, saying a can spinning on its cap was not modelled.
TEST(ShapedPrediction, ACanSpinningOnItsCapStopsWhereItStands) {
  Scene scene = RimFall{}.scene();
  ASSERT_TRUE(scene.materials.addMaterial("rough", Material{0.5, 0.5}, "m").ok());
  scene.bodies[0].material = "rough";
  scene.effects.friction = true;
  auto request = dropped(scene, V(0.2, -0.1, 0.1), Eigen::Quaterniond::Identity(), 1.0, 10);
  request.state.angular_velocity = V(0, 0, 3.0);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_FALSE(prediction->cut_short) << prediction->message;
  EXPECT_TRUE(prediction->impacts.empty());
  EXPECT_NEAR((prediction->final_state.position - V(0.2, -0.1, 0.1)).norm(), 0.0, 1e-9);
  EXPECT_EQ(prediction->final_state.angular_velocity, V::Zero());
  EXPECT_EQ(prediction->final_state.velocity, V::Zero());
}

// A box sliding on the floor (mu 0.3, e 1/2) towards a wall d ahead of its front face: its slide
// ends where the face reaches the wall, u t - mu g t^2 / 2 = d, t = 2 d / (u + u_s) with u_s =
// sqrt(u^2 - 2 mu g d) the speed there; the four corners of the face strike at once (their joint
// rule frictionless), sending it back at e u_s without turning, and it slides back to rest after
// (e u_s)^2 / (2 mu g). Before, the lasting slide watched its face alone and went through the
// wall.
TEST(ShapedPrediction, ABoxSlidingIntoAWallStrikesItAndSlidesBackToRest) {
  const V half(0.05, 0.04, 0.03);
  const double e = 0.5, mu = 0.3, u = 1.5, d = 0.2, wall = 0.5;
  Scene scene = floorScene(e, half);
  ASSERT_TRUE(scene.materials.addMaterial("sliding", Material{e, mu}, "m").ok());
  scene.bodies[0].material = "sliding";
  scene.effects.friction = true;
  scene.obstacles.push_back(plane("wall", -V::UnitX(), -wall, "concrete"));
  const double x0 = wall - half.x() - d;
  auto request = dropped(scene, V(x0, 0, half.z()), Eigen::Quaterniond::Identity(), 1.0, 10);
  request.state.velocity = V(u, 0, 0);
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_FALSE(prediction->cut_short) << prediction->message;
  const double u_s = std::sqrt(u * u - 2 * mu * kG * d);
  const double strike = 2 * d / (u + u_s);
  std::size_t on_wall = 0;
  for (const ImpactRecord& impact : prediction->impacts) {
    EXPECT_NEAR(impact.time, strike, 1e-11);
    EXPECT_NEAR(impact.velocity_a_before.x(), u_s, 1e-9);
    EXPECT_NEAR(impact.velocity_a_after.x(), -e * u_s, 1e-9);
    EXPECT_NEAR(impact.velocity_a_after.z(), 0.0, 1e-9);
    EXPECT_NEAR(impact.angular_velocity_a_after.norm(), 0.0, 1e-9);
    if (impact.other_is_obstacle && impact.other == 1) ++on_wall;
  }
  EXPECT_EQ(on_wall, 4u);
  const double back = e * u_s;
  EXPECT_NEAR(prediction->final_state.position.x(), wall - half.x() - back * back / (2 * mu * kG),
              1e-9);
  EXPECT_NEAR(prediction->final_state.position.z(), half.z(), 1e-9);
  EXPECT_EQ(prediction->final_state.velocity, V::Zero());
}

TEST(ShapedPrediction, WhatIsNotModelledYetIsRefusedByName) {
  Scene scene = floorScene(0.5, V(0.05, 0.05, 0.05));
  auto request = dropped(scene, V(0, 0, 1), Eigen::Quaterniond(0, 0, 0, 0), 1.0, 10);
  auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request);
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

// ---- A shaped body thrown tumbling at every obstacle kind (issue 42, steps 5 and 7) ----
//
// Each throw is checked by distances of its own, closed forms that share nothing with the code
// under test: the signed distance of a point to a box, a cylinder and a capsule (< 0 inside; the
// standard closed forms, e.g. Ericson, "Real-Time Collision Detection", 2005, chapter 5), to a
// sphere, and to a closed convex mesh from its triangles (the nearest point of each triangle,
// inside where behind every triangle's plane). Between a body and an obstacle, each side's edges
// (a box's twelve, a mesh's triangles' sides), sides (a cylinder's generators, from rim to rim)
// and cores (a capsule's segment, a sphere's centre, with their radius) are looked at in the
// other side: the least signed distance along a segment by golden-section search (the distance to
// a convex set is convex along a line), over a cylinder's generators by 96 angles refined the
// same way. Two convex solids whose interiors meet have a point of an edge, a side or a core of
// one inside the other.

/// A convex solid (or the open floor mesh's sheet) at one instant, in the fixed frame.
struct Solid {
  enum Kind { kBox, kCylinder, kCapsule, kSphere, kConvexMesh, kSheet } kind = kBox;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // fixed <- solid
  V half = V::Zero();                                      // a box's
  double radius = 0.0, half_length = 0.0;                  // cylinder, capsule (axis z), sphere
  std::vector<std::array<V, 3>> triangles;                 // a convex mesh's, in its frame
  double sheet_half = 0.0;                                 // the sheet z = 0, |x|, |y| <= it

  /// m: the signed distance of `world` to the solid (< 0 inside).
  double distance(const V& world) const {
    const V p = pose.inverse() * world;
    switch (kind) {
      case kBox: {
        const V q = p.cwiseAbs() - half;
        return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
      }
      case kCylinder: {
        const double radial = std::hypot(p.x(), p.y()) - radius;
        const double axial = std::abs(p.z()) - half_length;
        return std::hypot(std::max(radial, 0.0), std::max(axial, 0.0)) +
               std::min(std::max(radial, axial), 0.0);
      }
      case kCapsule:
        return (p - V(0, 0, std::clamp(p.z(), -half_length, half_length))).norm() - radius;
      case kSphere:
        return p.norm() - radius;
      case kConvexMesh: {
        double nearest = std::numeric_limits<double>::infinity();
        bool inside = true;
        for (const auto& t : triangles) {
          nearest = std::min(nearest, (p - nearestOnTriangle(p, t)).norm());
          const V normal = (t[1] - t[0]).cross(t[2] - t[0]);
          inside = inside && normal.dot(p - t[0]) < 0;
        }
        return inside ? -nearest : nearest;
      }
      case kSheet:  // the body stays over it: below is inside
        return std::max(std::abs(p.x()), std::abs(p.y())) <= sheet_half
                   ? p.z()
                   : std::numeric_limits<double>::infinity();
    }
    return 0.0;
  }

  /// Ericson's closest point of a triangle to p (Voronoi regions of its vertices, edges, face).
  static V nearestOnTriangle(const V& p, const std::array<V, 3>& t) {
    const V& a = t[0];
    const V& b = t[1];
    const V& c = t[2];
    const V ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const V bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
    const V cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
      return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
    const double denominator = 1 / (va + vb + vc);
    return a + ab * (vb * denominator) + ac * (vc * denominator);
  }

  /// m: the farthest point from the pose's origin (the sheet: none, it is checked from above).
  double reach() const {
    switch (kind) {
      case kBox:
        return half.norm();
      case kCylinder:
        return std::hypot(radius, half_length);
      case kCapsule:
        return radius + half_length;
      case kSphere:
        return radius;
      case kConvexMesh: {
        double r = 0.0;
        for (const auto& t : triangles) {
          for (const V& v : t) r = std::max(r, v.norm());
        }
        return r;
      }
      case kSheet:
        return std::numeric_limits<double>::infinity();
    }
    return 0.0;
  }

  /// Its segments (ends and a radius about them: a capsule's core, a sphere's centre) in the
  /// fixed frame.
  std::vector<std::tuple<V, V, double>> segments() const {
    std::vector<std::tuple<V, V, double>> out;
    const auto edge = [&](const V& a, const V& b, double r) {
      out.emplace_back(pose * a, pose * b, r);
    };
    if (kind == kBox) {
      for (int corner = 0; corner < 8; ++corner) {
        for (int axis = 0; axis < 3; ++axis) {
          if (corner & (1 << axis)) continue;
          const auto at = [&](int c) {
            return V((c & 1) ? half.x() : -half.x(), (c & 2) ? half.y() : -half.y(),
                     (c & 4) ? half.z() : -half.z());
          };
          edge(at(corner), at(corner | (1 << axis)), 0.0);
        }
      }
    } else if (kind == kCapsule) {
      edge(V(0, 0, -half_length), V(0, 0, half_length), radius);
    } else if (kind == kSphere) {
      edge(V::Zero(), V::Zero(), radius);
    } else if (kind == kConvexMesh) {
      for (const auto& t : triangles) {
        for (int k = 0; k < 3; ++k) edge(t[k], t[(k + 1) % 3], 0.0);
      }
    }
    return out;
  }

  /// A cylinder's side: its generator at angle phi, from rim to rim, in the fixed frame.
  std::pair<V, V> generator(double phi) const {
    const double x = radius * std::cos(phi), y = radius * std::sin(phi);
    return {pose * V(x, y, -half_length), pose * V(x, y, half_length)};
  }
};

/// The least of f on [lo, hi] (f convex there: golden-section search to the doubles' rounding).
template <class F>
double leastOn(double lo, double hi, F&& f) {
  const double ratio = (std::sqrt(5.0) - 1) / 2;
  double a = lo, b = hi;
  double c = b - ratio * (b - a), d = a + ratio * (b - a);
  double fc = f(c), fd = f(d);
  for (int i = 0; i < 80 && b - a > 1e-15 * std::max(1.0, std::abs(b)); ++i) {
    if (fc < fd) {
      b = d, d = c, fd = fc, c = b - ratio * (b - a), fc = f(c);
    } else {
      a = c, c = d, fc = fd, d = a + ratio * (b - a), fd = f(d);
    }
  }
  return std::min({f(lo), f(hi), fc, fd});
}

/// m: the least signed distance to `b` along the segment from p to q.
double leastAlong(const Solid& b, const V& p, const V& q) {
  return leastOn(0.0, 1.0, [&](double s) { return b.distance(p + s * (q - p)); });
}

/// m: how deep the segments and the side of `a` reach into `b` (< 0: how far the nearest is).
double depthOf(const Solid& a, const Solid& b) {
  double depth = -std::numeric_limits<double>::infinity();
  for (const auto& [p, q, r] : a.segments()) depth = std::max(depth, r - leastAlong(b, p, q));
  if (a.kind != Solid::kCylinder) return depth;
  // The cylinder lies within the capsule of its axis and radius: further than 1 mm from b, it
  // cannot reach it. Nearer, its side's generators (their ends its rims) at 96 angles, the
  // nearest refined between its neighbours.
  const double axis =
      leastAlong(b, a.pose * V(0, 0, -a.half_length), a.pose * V(0, 0, a.half_length)) - a.radius;
  if (axis > 1e-3) return std::max(depth, -axis);
  const auto along = [&](double phi) {
    const auto [p, q] = a.generator(phi);
    return leastAlong(b, p, q);
  };
  constexpr int kSamples = 96;
  const double slice = 2 * M_PI / kSamples;
  int best = 0;
  double least = std::numeric_limits<double>::infinity();
  for (int k = 0; k < kSamples; ++k) {
    const double d = along(k * slice);
    if (d < least) least = d, best = k;
  }
  least = std::min(least, leastOn((best - 1) * slice, (best + 1) * slice, along));
  return std::max(depth, -least);
}

/// m: how deep two solids are in each other (< 0: apart).
double overlapOf(const Solid& body, const Solid& obstacle) {
  // Far apart (the body's reach from its centre clear of the obstacle): nothing to look at.
  if (obstacle.distance(body.pose.translation()) > body.reach() + 1e-2) return -1e-2;
  return std::max(depthOf(body, obstacle), depthOf(obstacle, body));
}

/// The thrown body as a Solid at a sample.
Solid bodySolid(const BodySpec& body, const BodyStateSample& state) {
  Solid solid;
  solid.pose = Eigen::Translation3d(state.position) * state.orientation.normalized();
  if (body.shape == BodyShape::kBox) {
    solid.kind = Solid::kBox;
    solid.half = 0.5 * body.size;
  } else {
    solid.kind = body.shape == BodyShape::kCylinder ? Solid::kCylinder : Solid::kCapsule;
    solid.radius = body.radius;
    solid.half_length = 0.5 * body.length;
  }
  return solid;
}

/// An obstacle of the scene as a Solid where it is `time` after the throw (a paddle moving at
/// `velocity` from `position`), or none for a plane.
std::optional<Solid> obstacleSolid(const ObstacleSpec& o, const V& position, const V& velocity,
                                   double time) {
  Solid solid;
  solid.pose = Eigen::Translation3d(position + time * velocity) * o.orientation;
  switch (o.shape) {
    case ObstacleShape::kSphere:
      solid.kind = Solid::kSphere;
      solid.radius = o.radius;
      return solid;
    case ObstacleShape::kBox:
      solid.kind = Solid::kBox;
      solid.half = 0.5 * o.size;
      return solid;
    case ObstacleShape::kCylinder:
    case ObstacleShape::kCapsule:
      solid.kind = o.shape == ObstacleShape::kCylinder ? Solid::kCylinder : Solid::kCapsule;
      solid.radius = o.radius;
      solid.half_length = 0.5 * o.length;
      return solid;
    case ObstacleShape::kMesh:
      if (o.mesh->closed()) {
        solid.kind = Solid::kConvexMesh;
        for (const auto& t : o.mesh->triangles()) {
          solid.triangles.push_back(
              {o.mesh->vertices()[t[0]], o.mesh->vertices()[t[1]], o.mesh->vertices()[t[2]]});
        }
      } else {  // the open floor: z = 0 over a square about the origin
        solid.kind = Solid::kSheet;
        for (const V& v : o.mesh->vertices()) {
          solid.sheet_half = std::max(solid.sheet_half, std::abs(v.x()));
          EXPECT_EQ(v.z(), 0.0);
        }
      }
      return solid;
    default:
      return std::nullopt;
  }
}

// The throws' own check against closed forms: a box's edge turned down onto a box's ridge
// turned up, crossing at right angles d = 1e-6 deep, has the point of the edge above the ridge
// inside by d / sqrt(2) (its distance to either face of the ridge); a cylinder tilted by alpha
// with the lowest point of its rim d below a table's top, inside by d; a capsule lying on a
// cube mesh sunk by d, inside by d; two cylinders crossing side to side d deep, inside by d; each
// raised by 2 d, apart (< 0).
TEST(ShapedPrediction, TheThrowsCheckSeesAPointInsideByTheClosedForm) {
  const double d = 1e-6, s2 = std::sqrt(2.0);
  Solid edge, ridge;
  edge.half = ridge.half = V(0.1, 0.1, 0.1);
  ridge.pose = Eigen::Translation3d(0, 0, 0) * Eigen::AngleAxisd(M_PI / 4, V::UnitY());
  const auto edgeAt = [&](double z) {
    edge.pose = Eigen::Translation3d(0.02, 0.03, z) * Eigen::AngleAxisd(M_PI / 4, V::UnitX());
    return overlapOf(edge, ridge);
  };
  EXPECT_NEAR(edgeAt(0.2 * s2 - d), d / s2, 1e-12);
  EXPECT_LT(edgeAt(0.2 * s2 + d), 0.0);

  Solid table;
  table.half = V(0.3, 0.3, 0.025);
  table.pose = Eigen::Translation3d(0, 0, 0.4) * Eigen::Quaterniond::Identity();
  Solid can;
  can.kind = Solid::kCylinder;
  can.radius = 0.04;
  can.half_length = 0.06;
  const double alpha = 0.3, low = can.radius * std::sin(alpha) + can.half_length * std::cos(alpha);
  const auto canAt = [&](double z) {
    can.pose = Eigen::Translation3d(0.1, 0, z) * Eigen::AngleAxisd(alpha, V::UnitX());
    return overlapOf(can, table);
  };
  EXPECT_NEAR(canAt(0.425 + low - d), d, 1e-12);
  EXPECT_LT(canAt(0.425 + low + d), 0.0);

  ObstacleSpec crate =
      scene_builders::mesh("crate", scene_builders::cubeMesh(V(0.15, 0.12, 0.1)), V::Zero(), "c");
  const Solid mesh = *obstacleSolid(crate, V(0, 0, 0.1), V::Zero(), 0.0);
  Solid pill;
  pill.kind = Solid::kCapsule;
  pill.radius = 0.03;
  pill.half_length = 0.05;
  const auto pillAt = [&](double z) {
    pill.pose = Eigen::Translation3d(0.01, 0.02, z) * Eigen::AngleAxisd(M_PI / 2, V::UnitY());
    return overlapOf(pill, mesh);
  };
  EXPECT_NEAR(pillAt(0.2 + 0.03 - d), d, 1e-12);
  EXPECT_LT(pillAt(0.2 + 0.03 + d), 0.0);

  // Two cylinders crossing at right angles side to side, their axes D = r1 + r2 - d apart: the
  // point of either's side nearest the other's axis is inside it by d (no rim is inside).
  Solid log, can_across;
  log.kind = can_across.kind = Solid::kCylinder;
  log.radius = 0.12;
  log.half_length = 0.3;
  log.pose = Eigen::Translation3d(0, 0, 0.12) * Eigen::AngleAxisd(M_PI / 2, V::UnitY());
  can_across.radius = 0.04;
  can_across.half_length = 0.06;
  const auto acrossAt = [&](double z) {
    can_across.pose = Eigen::Translation3d(0.05, 0.01, z) * Eigen::AngleAxisd(M_PI / 2, V::UnitX());
    return overlapOf(can_across, log);
  };
  EXPECT_NEAR(acrossAt(0.12 + 0.16 - d), d, 1e-12);
  EXPECT_LT(acrossAt(0.12 + 0.16 + d), 0.0);
}

enum class Target {
  kSphere,
  kTable,
  kCylinder,
  kCapsule,
  kCubeMesh,
  kFloorMesh,
  kHeldBall,
  kPaddle
};

const char* nameOf(Target target) {
  constexpr std::array names{"sphere",    "table",      "cylinder",  "capsule",
                             "cube mesh", "floor mesh", "held ball", "paddle"};
  return names[static_cast<std::size_t>(target)];
}

const char* nameOf(BodyShape shape) {
  return shape == BodyShape::kBox ? "box" : shape == BodyShape::kCylinder ? "cylinder" : "capsule";
}

/// One throw: the scene, the live monitor that holds a ball or moves the paddle, the request.
struct Throw {
  Scene scene;
  std::unique_ptr<ImpactMonitor> live;
  PredictionRequest request;
  V paddle_start = V::Zero(), paddle_velocity = V::Zero();  // the paddle's frame (origin)
};

/// A body of `shape` thrown tumbling (|w| up to 17 rad/s), with friction (mu 0.4, e 0.6), at
/// `target`; a concrete floor at z = 0 under all but the floor mesh.
Throw throwAt(Target target, BodyShape shape, std::mt19937_64& random) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Throw t;
  Scene& scene = t.scene;
  scene.effects.gravity = true;
  scene.effects.friction = true;
  scene.gravity = V(0, 0, -kG);
  EXPECT_TRUE(scene.materials.addMaterial("block", Material{0.6, 0.4}, "m").ok());
  EXPECT_TRUE(scene.materials.addPair("block", "concrete", PairCoefficients{0.6, 0.4}, "p").ok());
  BodySpec body;
  body.id = "block";
  body.mass = 0.5 + std::abs(unit(random));
  body.material = "block";
  body.shape = shape;
  if (shape == BodyShape::kBox) {
    body.size = V(0.04, 0.04, 0.04) +
                0.08 * V(std::abs(unit(random)), std::abs(unit(random)), std::abs(unit(random)));
  } else {
    body.radius = 0.02 + 0.03 * std::abs(unit(random));
    body.length = 0.04 + 0.1 * std::abs(unit(random));
  }
  scene.bodies = {body};
  if (target != Target::kFloorMesh) {
    scene.obstacles.push_back(plane("floor", V::UnitZ(), 0.0, "concrete"));
  }
  V at(0.08 * unit(random), 0.08 * unit(random), 0.55 + 0.2 * std::abs(unit(random)));
  V velocity(0.5 * unit(random), 0.5 * unit(random), -std::abs(unit(random)));
  switch (target) {
    case Target::kSphere:
      scene.obstacles.push_back(scene_builders::sphere("ball", V(0, 0, 0.15), 0.15, "concrete"));
      break;
    case Target::kTable:  // landing on its top near the +x edge, moving off it
      scene.obstacles.push_back(
          scene_builders::box("table", V(0, 0, 0.4), V(0.6, 0.6, 0.05), "concrete"));
      at.x() = 0.15 + 0.05 * unit(random);
      at.z() += 0.4;
      velocity.x() = 0.1 + 0.4 * std::abs(unit(random));
      break;
    case Target::kCylinder: {  // lying along x on the floor
      ObstacleSpec cylinder;
      cylinder.id = "log";
      cylinder.shape = ObstacleShape::kCylinder;
      cylinder.material = "concrete";
      cylinder.position = V(0, 0, 0.12);
      cylinder.radius = 0.12;
      cylinder.length = 0.6;
      cylinder.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, V::UnitY()));
      scene.obstacles.push_back(cylinder);
      break;
    }
    case Target::kCapsule: {  // turned, its ends raised
      ObstacleSpec capsule;
      capsule.id = "pill";
      capsule.shape = ObstacleShape::kCapsule;
      capsule.material = "concrete";
      capsule.position = V(0, 0, 0.2);
      capsule.radius = 0.1;
      capsule.length = 0.3;
      capsule.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(1.2, V(1, 1, 0).normalized()));
      scene.obstacles.push_back(capsule);
      break;
    }
    case Target::kCubeMesh:
      scene.obstacles.push_back(scene_builders::mesh(
          "crate", scene_builders::cubeMesh(V(0.15, 0.12, 0.1)), V(0, 0, 0.1), "concrete"));
      break;
    case Target::kFloorMesh:
      scene.obstacles.push_back(
          scene_builders::mesh("ground", scene_builders::floorMesh(8, 4.0), V::Zero(), "concrete"));
      break;
    case Target::kHeldBall: {  // another body, held where the live monitor has it
      scene.bodies.push_back(scene_builders::ball("target", 1.0, 0.12, "concrete"));
      Scene tracked = scene;
      tracked.bodies = {scene.bodies[1]};
      t.live = std::make_unique<ImpactMonitor>(tracked, MonitorSettings{});
      BodyStateSample held;
      held.body = *t.live->bodyIndex("target");
      held.position = V(0.02, -0.02, 0.12);
      t.live->step(0.0, {held});
      break;
    }
    case Target::kPaddle: {  // a paddle on its frame moving at 1 to 3 m/s along +x at the body
      ObstacleSpec paddle;
      paddle.id = "paddle";
      paddle.shape = ObstacleShape::kBox;
      paddle.size = V(0.02, 0.4, 0.4);
      paddle.frame = "paddle_link";
      paddle.material = "concrete";
      scene.obstacles.push_back(paddle);
      Scene moving = scene;
      moving.bodies = {scene_builders::ball("dummy", 1.0, 0.01, "concrete", V(5, 5, 5))};
      t.live = std::make_unique<ImpactMonitor>(moving, MonitorSettings{});
      t.paddle_start = V(-0.35, 0.0, 0.45);
      t.paddle_velocity = V(1.0 + 2.0 * std::abs(unit(random)), 0, 0);
      RigidPose frame;
      frame.transform = Eigen::Translation3d(t.paddle_start) * Eigen::Quaterniond::Identity();
      frame.velocity = t.paddle_velocity;
      t.live->setObstaclePose(1, frame);
      at = V(0.0, 0.05 * unit(random), 0.5);
      velocity = V(-0.5 * std::abs(unit(random)), 0.3 * unit(random), 0.5 * unit(random));
      break;
    }
  }
  t.request = dropped(
      scene, at,
      Eigen::Quaterniond(unit(random), unit(random), unit(random), unit(random)).normalized(), 1.0,
      1000);
  t.request.state.velocity = velocity;
  t.request.state.angular_velocity = 10 * V(unit(random), unit(random), unit(random));
  t.request.sample_period = 1e-3;
  return t;
}

/// What a throw's check found.
struct ThrowFindings {
  double deepest = -std::numeric_limits<double>::infinity();  // m, into any obstacle (< 0 apart)
  double energy_gain = 0.0;                                   // J, past the throw's
  std::size_t impacts = 0;
  std::string ending;
};

ThrowFindings checkThrow(Target target, const Throw& t, const Prediction& prediction) {
  ThrowFindings findings;
  findings.impacts = prediction.impacts.size();
  const BodySpec& body = t.request.body;
  const ShapeCheck check{body};
  const double energy = check.energy(t.request.state);
  std::vector<std::pair<ObstacleSpec, V>> obstacles;  // the solids with their start
  for (const ObstacleSpec& o : t.scene.obstacles) obstacles.emplace_back(o, o.position);
  if (target == Target::kHeldBall) {
    obstacles.emplace_back(scene_builders::sphere("target", V(0.02, -0.02, 0.12), 0.12, "c"),
                           V(0.02, -0.02, 0.12));
  }
  for (const BodyStateSample& sample : prediction.samples) {
    const Solid solid = bodySolid(body, sample);
    findings.deepest = std::max(findings.deepest, -check.lowest(sample));  // the floor plane
    for (const auto& [o, start] : obstacles) {
      const bool paddle = !o.frame.empty();
      const auto obstacle = obstacleSolid(o, paddle ? t.paddle_start : start,
                                          paddle ? t.paddle_velocity : V::Zero(), sample.time);
      if (obstacle) findings.deepest = std::max(findings.deepest, overlapOf(solid, *obstacle));
    }
    if (target != Target::kPaddle) {
      findings.energy_gain = std::max(findings.energy_gain, check.energy(sample) - energy);
    }
  }
  if (target == Target::kFloorMesh) {  // no plane: the sheet's own check above counts
    findings.deepest = -std::numeric_limits<double>::infinity();
    for (const BodyStateSample& sample : prediction.samples) {
      const Solid solid = bodySolid(body, sample);
      const auto sheet = obstacleSolid(t.scene.obstacles[0], V::Zero(), V::Zero(), 0.0);
      findings.deepest = std::max(findings.deepest, depthOf(solid, *sheet));
    }
  }
  const bool horizon = prediction.final_state.time == t.request.horizon;
  const bool counted = prediction.impacts.size() >= t.request.max_impacts;
  const bool lasting = prediction.message.find("lasting contact") != std::string::npos;
  findings.ending = horizon ? "horizon" : counted ? "max_impacts" : lasting ? "lasting" : "";
  return findings;
}

/// How many throws a shape and target: 2 in the suite, COLLISION_RESPONSE_SHAPED_THROWS for the
/// long lane (COLLISION_RESPONSE_SHAPED_THROWS_PRINT prints each throw: its prediction's CPU, the
/// deepest point found (< 0: the nearest approach sampled), the energy gained, how it ended and
/// its impacts by obstacle).
int throwsEach() {
  const char* asked = std::getenv("COLLISION_RESPONSE_SHAPED_THROWS");
  return asked ? std::max(1, std::atoi(asked)) : 2;
}

// Boxes, cylinders and capsules thrown tumbling with friction at each obstacle kind: a sphere, a
// table top (landing on its face, going off its edge), a cylinder, a capsule, a closed mesh, an
// open floor mesh, a ball held where the live monitor has it, and a paddle moving on its frame
// at the body. Sampled every millisecond: no point of the body inside any obstacle (by the
// independent distances above) by more than 1e-9 m, the energy (kinetic, rotational, potential)
// never above the throw's (but against the paddle, which gives energy), and every prediction
// ends at its horizon, at max_impacts, or saying its contact would last.
TEST(ShapedPrediction, ThrowsAtEveryObstacleKindNeverGoInsideNorGainEnergy) {
  std::mt19937_64 random(4207);
  const int each = throwsEach();
  for (int target_index = 0; target_index < 8; ++target_index) {
    const auto target = static_cast<Target>(target_index);
    int struck = 0;     // throws that strike the obstacle aimed at
    int off_table = 0;  // throws that strike the table, then the floor
    for (const BodyShape shape : {BodyShape::kBox, BodyShape::kCylinder, BodyShape::kCapsule}) {
      for (int n = 0; n < each; ++n) {
        const Throw t = throwAt(target, shape, random);
        const double cpu_before = threadCpuSeconds();
        const auto prediction = predictImpacts(t.scene, t.live.get(), MonitorSettings{}, t.request);
        const double cpu = threadCpuSeconds() - cpu_before;
        const std::string what =
            std::string(nameOf(shape)) + " at " + nameOf(target) + " throw " + std::to_string(n);
        ASSERT_TRUE(prediction.ok()) << what << ": " << prediction.error().message();
        const ThrowFindings findings = checkThrow(target, t, *prediction);
        if (std::getenv("COLLISION_RESPONSE_SHAPED_THROWS_PRINT") != nullptr) {
          std::map<std::string, int> by;
          for (const auto& i : prediction->impacts) by[prediction->model->obstacle(i.other).id]++;
          std::string hits;
          for (const auto& [k, v] : by) hits += k + "=" + std::to_string(v) + " ";
          std::printf("%s: cpu %.6f deepest %.3g gain %.3g end %s t %.4f impacts %s| %s\n",
                      what.c_str(), cpu, findings.deepest, findings.energy_gain,
                      findings.ending.c_str(), prediction->final_state.time, hits.c_str(),
                      prediction->message.c_str());
        }
        EXPECT_LE(findings.deepest, 1e-9) << what << ": " << prediction->message;
        EXPECT_LE(findings.energy_gain,
                  1e-9 * (1 + std::abs(ShapeCheck{t.request.body}.energy(t.request.state))))
            << what;
        EXPECT_FALSE(findings.ending.empty())
            << what << " ended at " << prediction->final_state.time << ": " << prediction->message;
        const std::string aimed_at = t.scene.obstacles.back().id;  // the floor's after it
        bool on_it = false, then_floor = false;
        for (const ImpactRecord& impact : prediction->impacts) {
          const std::string& id = prediction->model->obstacle(impact.other).id;
          const bool aimed = id == aimed_at || (target == Target::kHeldBall && id == "target");
          then_floor = then_floor || (on_it && id == "floor");
          on_it = on_it || aimed;
        }
        struck += on_it ? 1 : 0;
        off_table += then_floor ? 1 : 0;
      }
    }
    // Each kind is met by most of its throws (of 720, 76 to 90 of each kind's 90), and the table
    // is left over its edge.
    EXPECT_GE(2 * struck, 3 * each) << nameOf(target);
    if (target == Target::kTable) {
      EXPECT_GE(off_table, 1);
    }
  }
}

}  // namespace
}  // namespace collision_response::core
