// The live calibration's window and its answer without a node (live_calibration.h; issue 44,
// item 3): the window's bounds (seconds of stamps, states a body, off), and
// ~estimate_restitution for a tracked body from a track flown in closed form
// (test/core/bouncing_ball.h), its bad requests named.
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <iostream>
#include <string>
#include <vector>

#include "../core/bouncing_ball.h"
#include "collision_response/ros/live_calibration.h"
#include "collision_response/ros/monitor_cycle.h"

namespace collision_response {
namespace {

core::BodyStateSample at(std::size_t body, double time, double z = 0.0) {
  core::BodyStateSample sample;
  sample.body = body;
  sample.time = time;
  sample.position = Eigen::Vector3d(time, 0.0, z);
  return sample;
}

// A copy gives a body's newest 4,000 states, in order; past the log's capacity (64 states
// here) its oldest go first, whichever body's, never the newest (times k / 256 s: exact).
TEST(CalibrationWindow, PastItsBoundsTheOldestAreDroppedNeverTheNewest) {
  CalibrationWindow window(2, 1e6);
  const std::size_t total = CalibrationWindow::kMaxSamplesPerBody + 1234;
  for (std::size_t k = 0; k < total; ++k) {
    // One state an input, and every 7th input two (both bodies).
    std::vector<core::BodyStateSample> input{at(0, static_cast<double>(k) / 256.0)};
    if (k % 7 == 0) input.push_back(at(1, static_cast<double>(k) / 256.0));
    window.record(input);
  }
  EXPECT_EQ(window.size(0), total);
  EXPECT_EQ(window.size(1), (total + 6) / 7);
  const std::vector<core::TrackedSample> kept = window.copy(0);
  ASSERT_EQ(kept.size(), CalibrationWindow::kMaxSamplesPerBody);
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const double expected = static_cast<double>(total - kept.size() + k) / 256.0;
    ASSERT_EQ(kept[k].time, expected) << "sample " << k;
    ASSERT_EQ(kept[k].position.x(), expected) << "sample " << k;
  }
  EXPECT_EQ(window.copy(1).size(), (total + 6) / 7);

  CalibrationWindow small(2, 1e6, 100);  // rounded down to 64
  ASSERT_EQ(small.capacity(), 64u);
  for (int k = 0; k < 100; ++k) {
    small.record({at(0, k / 256.0), at(1, k / 256.0)});
    ASSERT_LE(small.size(), 64u);
    ASSERT_EQ(small.copy(0).back().time, k / 256.0) << "the newest is kept";
    ASSERT_EQ(small.copy(1).back().time, k / 256.0) << "the newest is kept";
  }
  const std::vector<core::TrackedSample> newest = small.copy(0);
  ASSERT_EQ(newest.size(), 32u);
  for (std::size_t k = 0; k < newest.size(); ++k)
    EXPECT_EQ(newest[k].time, static_cast<double>(68 + k) / 256.0);
}

// States older than the window's seconds before the newest go from the old end: at 256 Hz for
// 3 s with a window of 1 s, those from 2 s on (257 of them) are kept.
TEST(CalibrationWindow, StatesOlderThanItsSecondsGoFromTheOldEnd) {
  CalibrationWindow window(1, 1.0);
  for (int k = 0; k <= 3 * 256; ++k) window.record({at(0, k / 256.0)});
  const std::vector<core::TrackedSample> kept = window.copy(0);
  ASSERT_EQ(kept.size(), 257u);
  EXPECT_EQ(kept.front().time, 2.0);
  EXPECT_EQ(kept.back().time, 3.0);
  EXPECT_EQ(window.size(), 257u);
  // A state not newer than the body's newest is not kept (the monitor drops it as stale).
  window.record({at(0, 3.0), at(0, 2.5)});
  EXPECT_EQ(window.copy(0).size(), 257u);
  // A body no longer tracked: nothing of it within the window of the newest state of any body.
  CalibrationWindow two(2, 1.0);
  two.record({at(0, 0.0), at(1, 0.0)});
  two.record({at(1, 5.0)});
  EXPECT_TRUE(two.copy(0).empty());
  EXPECT_EQ(two.size(0), 0u);  // older than the window before the newest of any body: dropped
  EXPECT_EQ(two.copy(1).size(), 1u);
  two.clear();
  EXPECT_TRUE(two.copy(1).empty());
}

// Off (0 s) keeps nothing.
TEST(CalibrationWindow, OffKeepsNothing) {
  CalibrationWindow off(3, 0.0);
  EXPECT_FALSE(off.enabled());
  off.record({at(0, 0.0), at(1, 0.0)});
  EXPECT_EQ(off.size(), 0u);
  EXPECT_TRUE(off.copy(0).empty());
}

core::Scene floorScene() {
  core::Scene scene;
  scene.effects.gravity = true;
  scene.gravity = Eigen::Vector3d(0, 0, -core::bouncing_ball::kG);
  core::BodySpec ball;
  ball.id = "ball";
  ball.mass = 0.0027;
  ball.radius = 0.02;
  ball.material = "legal_ball";
  core::BodySpec still = ball;
  still.id = "still";
  scene.bodies = {ball, still};
  core::ObstacleSpec floor;
  floor.id = "table";
  floor.material = "concrete";
  scene.obstacles = {floor};
  return scene;
}

/// The track's samples into the window, as body `body`'s states, `offset` s on.
void play(CalibrationWindow& window, const std::vector<core::TrackedSample>& samples,
          std::size_t body, double offset = 0.0) {
  for (const core::TrackedSample& sample : samples) {
    core::BodyStateSample state = at(body, offset + sample.time);
    state.position = sample.position;
    window.record({state});
  }
}

// The closed-form throw (e 0.9, 5 bounces, 200 Hz, 1 mm) played into the window: the answer is
// e within +-0.005 of 0.9 and inside its interval, the pair named; the 2 most recent bounces
// alone; a body without a bounce, an unknown id, a negative max_bounces and an off window named.
TEST(LiveCalibration, AThrowsBouncesGiveEBackAndBadRequestsAreNamed) {
  namespace bb = core::bouncing_ball;
  bb::Throw t;
  t.seed = 44;
  const bb::Track track = bb::throwBall(t);
  LiveCalibration live(floorScene(), 10.0);
  play(live.window(), track.samples, 0, 100.0);
  // 'still' hangs above the floor for the same span.
  std::vector<core::TrackedSample> still = track.samples;
  for (core::TrackedSample& sample : still) sample.position = Eigen::Vector3d(1.0, 0.0, 1.0);
  play(live.window(), still, 1, 100.0);

  EstimateRestitution::Request request;
  EstimateRestitution::Response response;
  std::vector<PairEstimate> pairs;
  request.body = "ball";
  live.answer(request, response, pairs);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.bounces, 5);
  EXPECT_NEAR(response.restitution, 0.9, 0.005) << response.message;
  EXPECT_LE(response.restitution_low, 0.9) << response.message;
  EXPECT_GE(response.restitution_high, 0.9) << response.message;
  EXPECT_NE(response.message.find("pair [legal_ball, concrete]: 5 bounces"), std::string::npos)
      << response.message;
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].pair, "[legal_ball, concrete]");

  request.max_bounces = 2;
  pairs.clear();
  live.answer(request, response, pairs);
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.bounces, 2);
  EXPECT_LE(response.restitution_low, 0.9) << response.message;
  EXPECT_GE(response.restitution_high, 0.9) << response.message;

  request.max_bounces = -1;
  live.answer(request, response, pairs);
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message.rfind("max_bounces: must be 0", 0), 0u) << response.message;

  request.max_bounces = 0;
  request.body = "still";
  live.answer(request, response, pairs);
  EXPECT_FALSE(response.success);
  EXPECT_NE(response.message.find("body 'still'"), std::string::npos) << response.message;
  EXPECT_NE(response.message.find("no bounce"), std::string::npos) << response.message;

  request.body = "nobody";
  live.answer(request, response, pairs);
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message.rfind("body: 'nobody' is not a body of the scene", 0), 0u)
      << response.message;

  LiveCalibration off(floorScene(), 0.0);
  request.body = "ball";
  off.answer(request, response, pairs);
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message.rfind("body: ~calibration_window is 0", 0), 0u) << response.message;
}

// The most recent bounces alone (max_bounces: the states from just after the bounce before them,
// fitted again): their 95 % interval covers the truth as the whole window's does. 100 seeds of
// the throw, the last 3 of its 5 bounces: at least 88 covered (95 % of 100 less 3 binomial
// standard deviations, 3 x 2.2).
TEST(LiveCalibration, TheLastBouncesIntervalCoversTheTruth) {
  namespace bb = core::bouncing_ball;
  int covered = 0;
  for (unsigned seed = 1; seed <= 100; ++seed) {
    bb::Throw t;
    t.seed = seed;
    LiveCalibration live(floorScene(), 10.0);
    play(live.window(), bb::throwBall(t).samples, 0);
    EstimateRestitution::Request request;
    request.body = "ball";
    request.max_bounces = 3;
    EstimateRestitution::Response response;
    std::vector<PairEstimate> pairs;
    live.answer(request, response, pairs);
    ASSERT_TRUE(response.success) << "seed " << seed << ": " << response.message;
    ASSERT_EQ(response.bounces, 3) << "seed " << seed << ": " << response.message;
    ASSERT_NEAR(response.restitution, t.e, 0.005) << "seed " << seed << ": " << response.message;
    if (response.restitution_low <= t.e && t.e <= response.restitution_high) ++covered;
  }
  EXPECT_GE(covered, 88);
  std::cout << "the last 3 bounces' 95 % interval covered e in " << covered << " of 100 seeds\n";
}

/// ~estimate_restitution's answer for `body` (max_bounces, spin_before) from `live`.
EstimateRestitution::Response ask(const LiveCalibration& live, const std::string& body,
                                  int max_bounces = 0, std::vector<double> spin_before = {}) {
  EstimateRestitution::Request request;
  request.body = body;
  request.max_bounces = max_bounces;
  request.spin_before = std::move(spin_before);
  EstimateRestitution::Response response;
  std::vector<PairEstimate> pairs;
  live.answer(request, response, pairs);
  return response;
}

/// |mu - truth| within 4 standard errors of the answer's (its 95 % half width is 1.96 of them).
bool muWithin4(const EstimateRestitution::Response& response, double truth) {
  return std::abs(response.friction - truth) <=
         4.0 / 1.96 * (response.friction_high - response.friction);
}

// mu answered live (issue 44): the closed-form throw (mu = 0.03, every bounce sliding: it takes
// 3.5 mu (1 + e) |vz| = 0.2 |vz| of the 3 m/s slip a bounce) played into the window. Given the
// spin before its first bounce (thrown without spin: 0 0 0), mu with its 95 % interval; without
// it only mu >= a bound below the truth; the last 3 bounces' mu from the whole window's fit (the
// spin carried through the first two); a bounce that stops slipping (mu = 0.5, 1 m/s along the
// floor: J_stick = |u| / 3.5 below mu J_n) gives only a bound below 0.5; a spin_before of the
// wrong size or not finite is named.
TEST(LiveCalibration, MuIsAnsweredWithItsIntervalWhereTheBouncesSlid) {
  namespace bb = core::bouncing_ball;
  bb::Throw t;
  t.seed = 44;
  LiveCalibration live(floorScene(), 10.0);
  play(live.window(), bb::throwBall(t).samples, 0, 100.0);

  auto response = ask(live, "ball", 0, {0.0, 0.0, 0.0});
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_TRUE(response.friction_known) << response.message;
  EXPECT_TRUE(muWithin4(response, t.mu)) << response.message;
  EXPECT_LT(response.friction_low, response.friction);
  EXPECT_GT(response.friction_high, response.friction);
  EXPECT_LT(response.friction_high - response.friction_low, 0.01) << response.message;
  EXPECT_NE(response.message.find(", mu 0.0"), std::string::npos) << response.message;
  std::cout << response.message << "\n";

  response = ask(live, "ball", 3, {0.0, 0.0, 0.0});
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_EQ(response.bounces, 3);
  EXPECT_TRUE(response.friction_known) << response.message;
  EXPECT_TRUE(muWithin4(response, t.mu)) << response.message;

  response = ask(live, "ball");  // the spin before unknown
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_FALSE(response.friction_known) << response.message;
  EXPECT_GT(response.friction_lower_bound, 0.0) << response.message;
  EXPECT_LT(response.friction_lower_bound, t.mu) << response.message;
  EXPECT_NE(response.message.find("mu >= "), std::string::npos) << response.message;

  bb::Throw sticking;
  sticking.mu = 0.5;
  sticking.velocity = Eigen::Vector3d(1.0, 0.0, -1.0);
  sticking.bounces = 3;
  const bb::Track track = bb::throwBall(sticking);
  ASSERT_TRUE(track.bounces[0].stuck);
  LiveCalibration stuck(floorScene(), 10.0);
  play(stuck.window(), track.samples, 0);
  response = ask(stuck, "ball", 0, {0.0, 0.0, 0.0});
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_FALSE(response.friction_known) << response.message;
  EXPECT_GT(response.friction_lower_bound, 0.0) << response.message;
  EXPECT_LT(response.friction_lower_bound, sticking.mu) << response.message;

  response = ask(live, "ball", 0, {0.0, 0.0});
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message,
            "spin_before: must be empty (unknown) or 3 values (rad/s, the fixed frame), got 2");
  response = ask(live, "ball", 0, {0.0, std::nan(""), 0.0});
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message, "spin_before: must be finite");
}

// A scene with `magnus` is flown with the request's spin_before (core calibrate: the spin its
// flights fly with), refused naming spin_before without it; a body of C_L 0 feels no Magnus force,
// so e comes back as without the effect. A scene the fit cannot bounce in is refused, named: one
// whose only plane moves with a frame, one without obstacles.
TEST(LiveCalibration, AScenesMagnusNeedsTheSpinAndNoFixedPlaneIsRefusedNamed) {
  namespace bb = core::bouncing_ball;
  bb::Throw t;
  t.seed = 44;
  core::Scene magnus = floorScene();
  magnus.effects.spin = magnus.effects.magnus = true;
  magnus.bodies[0].lift_coefficient = 0.0;
  LiveCalibration flown(magnus, 10.0);
  play(flown.window(), bb::throwBall(t).samples, 0, 100.0);
  auto response = ask(flown, "ball");
  EXPECT_FALSE(response.success);
  EXPECT_NE(response.message.find("spin_before: magnus flies the spin"), std::string::npos)
      << response.message;
  response = ask(flown, "ball", 0, {0.0, 0.0, 0.0});
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_NEAR(response.restitution, t.e, 0.005) << response.message;

  core::Scene moving = floorScene();
  moving.obstacles[0].frame = "paddle";
  response = ask(LiveCalibration(moving, 10.0), "ball");
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message.rfind("body: the scene has no fixed plane obstacle", 0), 0u)
      << response.message;

  core::Scene bare = floorScene();
  bare.obstacles.clear();
  response = ask(LiveCalibration(bare, 10.0), "ball");
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message.rfind("body: the scene has no fixed plane obstacle", 0), 0u)
      << response.message;
}

// A body of the scene with no state in the window is named: none received yet, and one no longer
// tracked (its states older than the window's 1 s before the newest state of another body).
TEST(LiveCalibration, ABodyWithNoStateInTheWindowIsNamed) {
  LiveCalibration live(floorScene(), 1.0);
  auto response = ask(live, "ball");
  EXPECT_FALSE(response.success);
  EXPECT_EQ(
      response.message.rfind("body: no state of 'ball' in the window (~calibration_window 1 s", 0),
      0u)
      << response.message;
  live.window().record({at(0, 0.0), at(1, 0.0)});
  live.window().record({at(1, 5.0)});
  response = ask(live, "ball");
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message.rfind("body: no state of 'ball' in the window", 0), 0u)
      << response.message;
}

// The monitor's cycle records each state it takes, as received and on its time line (a ball
// hanging 1 m up, 100 Hz for 1 s: 101 states, 0.01 s apart), and forgets them when its line
// restarts (the stamps went back by more than ~clock_jump_back and the next input continued
// from there, as rosbag play --loop does): the old line's times would not compare.
TEST(LiveCalibration, TheCycleKeepsEachStateAndForgetsThemWhenItsLineRestarts) {
  core::Scene scene;
  scene.effects.gravity = true;
  core::BodySpec ball;
  ball.id = "ball";
  ball.radius = 0.02;
  ball.material = "tennis_ball";
  ball.position = Eigen::Vector3d(0, 0, 1);
  scene.bodies = {ball};
  core::ObstacleSpec floor;
  floor.id = "table";
  floor.material = "concrete";
  scene.obstacles = {floor};
  MonitorParams params;
  params.clock_jump_back = 0.5;  // s: the jump back below is 1 s
  MonitorCycle cycle(scene, params);
  tf2::BufferCore tf;
  std::deque<std::vector<BodyState>> inputs;  // the cycle reads them in place
  const auto send = [&](const ros::Time& stamp) {
    BodyState state;
    state.header.stamp = stamp;
    state.header.frame_id = "world";
    state.id = "ball";
    state.pose.position.z = 1.0;
    state.pose.orientation.w = 1.0;
    inputs.push_back({state});
    const MonitorCycle::Input input{&inputs.back(), "/body_states", "/tracker", ""};
    cycle.process(input, ros::Time(), false, tf);
  };
  const ros::Time start(1796500000, 0);
  for (int k = 0; k <= 100; ++k) send(start + ros::Duration(0.01 * k));
  const CalibrationWindow& window = cycle.liveCalibration().window();
  const std::vector<core::TrackedSample> kept = window.copy(0);
  ASSERT_EQ(kept.size(), 101u);
  for (std::size_t k = 1; k < kept.size(); ++k) {
    EXPECT_NEAR(kept[k].time - kept[k - 1].time, 0.01, 1e-9) << "state " << k;
    EXPECT_EQ(kept[k].position, Eigen::Vector3d(0, 0, 1)) << "state " << k;
  }
  send(start);  // held: a jump back, or one stamp off its clock?
  EXPECT_EQ(window.size(0), 101u);
  send(start + ros::Duration(0.01));  // continued: the line restarts
  // This one alone, on the new line (a body both in the held input and in this one enters with
  // this one's state).
  EXPECT_EQ(window.size(0), 1u);
  EXPECT_EQ(window.copy(0).size(), 1u);
}

}  // namespace
}  // namespace collision_response
