// A prediction's CPU budget (prediction.h, PredictionBudget): once spent, the prediction stops
// where it got to and answers what it found before, each impact at its closed form, and says so.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "collision_response/core/prediction.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;

constexpr double kG = 9.81;
constexpr double kEps = std::numeric_limits<double>::epsilon();

/// A tennis ball (the seed's e = 0.712 on concrete) over a concrete floor at z = 0.
Scene floorScene() {
  Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -kG);
  scene.bodies = {scene_builders::ball("ball", 0.057, 0.033, "tennis_ball")};
  scene.obstacles = {scene_builders::plane("floor", V::UnitZ(), 0.0, "concrete")};
  return scene;
}

/// Dropped from rest so that it falls for t1 = 0.3 s: h = g t1^2 / 2 above contact. It meets
/// the floor at t1 at g t1, leaves at e g t1; a flight after the k-th bounce lasts 2 e^k t1, so
/// the impacts are at t1, t1 (1 + 2 e), t1 (1 + 2 e + 2 e^2), ... (0.3, 0.7272, 1.0314 s).
PredictionRequest dropRequest(const Scene& scene, double t1) {
  PredictionRequest request;
  request.body = scene.bodies[0];
  request.state.position = V(0, 0, scene.bodies[0].radius + 0.5 * kG * t1 * t1);
  request.horizon = 10.0;
  request.max_impacts = 100;
  request.effects = scene.effects;
  return request;
}

// A budget on a clock that moves 1 s each time it is read: read once as the prediction begins,
// then before each piece after the first (0.1 s long: kBudgetCheckPeriod, as the request has no
// samples). A budget of 10 is spent before the 11th piece: the prediction stops at +1.0 s, with
// the two impacts before (0.3 s and 0.7272 s), not the third (1.0314 s), and the state at 1.0 s.
TEST(PredictionBudget, CutAtItsBudgetAnswersOnlyTheImpactsBeforeAtTheClosedForms) {
  const Scene scene = floorScene();
  const double e = *scene.materials.restitution("tennis_ball", "concrete");
  const double t1 = 0.3;
  const auto request = dropRequest(scene, t1);

  double ticks = 0.0;
  PredictionBudget budget;
  budget.seconds = 10.0;
  budget.name = "the test's budget";
  budget.clock = [&ticks] { return ticks++; };
  const auto prediction = predictImpacts(scene, nullptr, MonitorSettings{}, request, budget);
  ASSERT_TRUE(prediction.ok()) << prediction.error().message();
  EXPECT_TRUE(prediction->cut_short);
  EXPECT_TRUE(prediction->out_of_budget);
  EXPECT_NE(prediction->message.find("the test's budget (10 s of CPU) ran out at +1 s"),
            std::string::npos)
      << prediction->message;

  const double t2 = t1 * (1 + 2 * e);
  ASSERT_EQ(prediction->impacts.size(), 2u);
  EXPECT_NEAR(prediction->impacts[0].time, t1, 8 * kEps);
  EXPECT_NEAR(prediction->impacts[0].velocity_a_before.z(), -kG * t1, 16 * kEps);
  EXPECT_NEAR(prediction->impacts[0].velocity_a_after.z(), e * kG * t1, 16 * kEps);
  EXPECT_NEAR(prediction->impacts[1].time, t2, 8 * kEps);
  EXPECT_NEAR(prediction->impacts[1].velocity_a_before.z(), -e * kG * t1, 16 * kEps);
  EXPECT_NEAR(prediction->impacts[1].velocity_a_after.z(), e * e * kG * t1, 16 * kEps);

  // The state where it stopped: 1.0 s, in the flight after the second bounce.
  const double u = e * e * kG * t1, since = 1.0 - t2;
  EXPECT_EQ(prediction->final_state.time, 1.0);
  EXPECT_NEAR(prediction->final_state.velocity.z(), u - kG * since, 16 * kEps);
  EXPECT_NEAR(prediction->final_state.position.z(),
              scene.bodies[0].radius + u * since - 0.5 * kG * since * since, 64 * kEps);

  // Without the budget the third impact follows at t1 (1 + 2 e + 2 e^2): it was cut, not absent.
  const auto whole = predictImpacts(scene, nullptr, MonitorSettings{}, request);
  ASSERT_TRUE(whole.ok());
  EXPECT_FALSE(whole->out_of_budget);
  ASSERT_GE(whole->impacts.size(), 3u);
  EXPECT_NEAR(whole->impacts[2].time, t1 * (1 + 2 * e + 2 * e * e), 8 * kEps);
}

// A budget that is not spent changes nothing but the pieces (0.1 s): the same impacts, each at
// its closed form, and no cut. On the thread's own CPU time (the clock left empty), a budget
// of 1 ns is spent before the second piece: the answer holds the first 0.1 s only.
TEST(PredictionBudget, OnTheThreadsCpuTime) {
  const Scene scene = floorScene();
  const double e = *scene.materials.restitution("tennis_ball", "concrete");
  const auto request = dropRequest(scene, 0.3);

  PredictionBudget ample;
  ample.seconds = 1e6;
  const auto full = predictImpacts(scene, nullptr, MonitorSettings{}, request, ample);
  ASSERT_TRUE(full.ok()) << full.error().message();
  EXPECT_FALSE(full->cut_short) << full->message;
  ASSERT_GE(full->impacts.size(), 3u);
  EXPECT_NEAR(full->impacts[0].time, 0.3, 8 * kEps);
  EXPECT_NEAR(full->impacts[1].time, 0.3 * (1 + 2 * e), 8 * kEps);
  EXPECT_NEAR(full->impacts[2].time, 0.3 * (1 + 2 * e + 2 * e * e), 8 * kEps);

  PredictionBudget tiny;
  tiny.seconds = 1e-9;
  const auto cut = predictImpacts(scene, nullptr, MonitorSettings{}, request, tiny);
  ASSERT_TRUE(cut.ok()) << cut.error().message();
  EXPECT_TRUE(cut->out_of_budget);
  EXPECT_TRUE(cut->impacts.empty());
  EXPECT_EQ(cut->final_state.time, kBudgetCheckPeriod);
  EXPECT_NE(cut->message.find("the prediction's CPU budget (1e-09 s of CPU) ran out at +0.1 s"),
            std::string::npos)
      << cut->message;
}

}  // namespace
}  // namespace collision_response::core
