// The monitor's update cycle and its parts (the state intake, the time line, the throttle),
// without a master: messages built here, tf from a tf2::BufferCore filled by hand. The attacks
// of issue 13 that need no node are here, each a named test with the attack's numbers.
//
// The two-ball closed form used throughout: 1 kg, radius 0.1 m, e = 0.5; a at x = t moving
// +1 m/s, b at x = 1.06 - t moving -1 m/s: the gap 0.86 m closes at 2 m/s, contact at t = 0.43
// s; equal masses: v_a' = -0.5, v_b' = +0.5, impulse 1.5 N s, energy lost 0.75 J.
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "collision_response/ros/monitor_cycle.h"
#include "collision_response/ros/monitor_diagnostics.h"
#include "collision_response/ros/throttled_warning.h"

namespace collision_response {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

core::Scene twoBallScene(double mass = 1.0, int extra_bodies = 0) {
  core::Scene scene;
  scene.materials.addMaterial("test_half", core::Material{0.5, std::nullopt}, "materials");
  for (const char* id : {"a", "b"}) {
    core::BodySpec body;
    body.id = id;
    body.mass = mass;
    body.radius = 0.1;
    body.material = "test_half";
    scene.bodies.push_back(body);
  }
  for (int i = 0; i < extra_bodies; ++i) {
    core::BodySpec body = scene.bodies[0];
    body.id = "extra_" + std::to_string(100000 + i);
    scene.bodies.push_back(body);
  }
  return scene;
}

BodyState state(const std::string& id, const ros::Time& stamp, const Eigen::Vector3d& position,
                const Eigen::Vector3d& velocity, const std::string& frame = "world") {
  BodyState s;
  s.header.stamp = stamp;
  s.header.frame_id = frame;
  s.id = id;
  s.pose.position.x = position.x();
  s.pose.position.y = position.y();
  s.pose.position.z = position.z();
  s.pose.orientation.w = 1.0;
  s.twist.linear.x = velocity.x();
  s.twist.linear.y = velocity.y();
  s.twist.linear.z = velocity.z();
  return s;
}

ros::Time at(const ros::Time& start, double seconds) { return start + ros::Duration(seconds); }

class Cycle : public ::testing::Test {
 protected:
  explicit Cycle(const core::Scene& scene = twoBallScene()) : cycle_(scene, MonitorParams{}) {}

  MonitorCycle::Update send(const std::vector<BodyState>& states,
                            const std::string& publisher = "/source",
                            const std::string& topic = "/body_states",
                            const std::string& own_body = "") {
    inputs_.push_back(states);
    MonitorCycle::Input input{&inputs_.back(), topic, publisher, own_body};
    MonitorCycle::Update update = cycle_.process(input, clock_, false, tf_);
    for (const Impact& impact : update.impacts.impacts) impacts_.push_back(impact);
    for (const Report& report : update.reports) reports_.push_back(report);
    return update;
  }

  /// The two-ball case at 10 Hz from `start`, both bodies in one array a message.
  void playTwoBalls(const ros::Time& start) {
    for (int k = 0; k <= 10; ++k) {
      const double t = 0.1 * k;
      const ros::Time stamp = start + ros::Duration(0, 100000000 * k);
      send({state("a", stamp, {t, 0, 0}, {1, 0, 0}),
            state("b", stamp, {1.06 - t, 0, 0}, {-1, 0, 0})});
    }
  }

  void expectTwoBallImpactOnce(const ros::Time& start) {
    ASSERT_EQ(impacts_.size(), 1u);
    const Impact& impact = impacts_[0];
    EXPECT_EQ(impact.body_a, "a");
    EXPECT_EQ(impact.body_b, "b");
    EXPECT_NEAR((impact.header.stamp - start).toSec(), 0.43, 1e-9);
    EXPECT_NEAR(impact.velocity_a_after.linear.x, -0.5, 1e-9);
    EXPECT_NEAR(impact.velocity_b_after.linear.x, 0.5, 1e-9);
    EXPECT_NEAR(impact.impulse, 1.5, 1e-9);
    EXPECT_NEAR(impact.energy_lost, 0.75, 1e-9);
  }

  /// playTwoBalls' source ignores the collision (its balls pass through each other): its next
  /// states lack the impact, said once for each ball; nothing else is reported.
  void expectOnlyTheTwoBallsLackingTheirImpact() const {
    EXPECT_EQ(reportsOf(Reason::kImpactContradicted), 2u);
    EXPECT_EQ(reportsOf(Reason::kImpactContradicted), reports_.size());
  }

  std::size_t reportsOf(Reason reason) const {
    std::size_t count = 0;
    for (const Report& report : reports_) count += report.reason == reason ? report.count : 0;
    return count;
  }
  const Report* firstReport(Reason reason) const {
    for (const Report& report : reports_) {
      if (report.reason == reason) return &report;
    }
    return nullptr;
  }

  MonitorCycle cycle_;
  tf2::BufferCore tf_;
  ros::Time clock_{1000, 0};
  std::deque<std::vector<BodyState>> inputs_;  // kept alive: the cycle reads them in place
  std::vector<Impact> impacts_;
  std::vector<Report> reports_;
};

TEST_F(Cycle, TwoBallsHitBetweenSamples) {
  const ros::Time start(1000, 0);
  playTwoBalls(start);
  expectTwoBallImpactOnce(start);
  expectOnlyTheTwoBallsLackingTheirImpact();
}

// Issue 13, item 1: the first state ever stamped secs 4294967295 set the time line there, and
// every later valid message was dropped with "Duration is out of dual 32-bit range", forever.
TEST_F(Cycle, Item1_AFirstStampAtTheEndOfTimeIsDroppedByNameAndTheMonitorLivesOn) {
  send({state("a", ros::Time(4294967295u, 0), {0, 0, 0}, {1, 0, 0})});
  ASSERT_EQ(reportsOf(Reason::kStampAhead), 1u);
  const std::string& text = firstReport(Reason::kStampAhead)->text;
  EXPECT_NE(text.find("header.stamp: 4294967295.000000000"), std::string::npos) << text;
  EXPECT_NE(text.find("ahead of this node's clock"), std::string::npos) << text;
  EXPECT_FALSE(cycle_.timeLine().started()) << "a dropped state does not start the time line";
  reports_.clear();
  const ros::Time start(1000, 0);
  playTwoBalls(start);
  expectTwoBallImpactOnce(start);
  expectOnlyTheTwoBallsLackingTheirImpact();
}

// Issue 13, item 1, mid-stream: the same stamp was dropped without naming header.stamp.
TEST_F(Cycle, Item1_AStampAtTheEndOfTimeMidStreamIsDroppedByName) {
  const ros::Time start(1000, 0);
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.1 * k;
    const ros::Time stamp = start + ros::Duration(0, 100000000 * k);
    send(
        {state("a", stamp, {t, 0, 0}, {1, 0, 0}), state("b", stamp, {1.06 - t, 0, 0}, {-1, 0, 0})});
    if (k == 2) send({state("b", ros::Time(4294967295u, 999999999), {0, 0, 0}, {0, 0, 0})});
  }
  EXPECT_EQ(reportsOf(Reason::kStampAhead), 1u);
  EXPECT_EQ(reportsOf(Reason::kClockJumpedBack), 0u) << "one bad stamp does not reset the line";
  expectTwoBallImpactOnce(start);
}

// Without a clock (sim time before the first /clock) the stamp cannot be judged: it starts the
// line, and the next valid state, its source's clock going back, restarts it. One reset, then
// the monitor is right again: no exception, whatever the stamps.
TEST_F(Cycle, Item1_WithoutAClockAFarStampCostsOneReset) {
  clock_ = ros::Time();
  send({state("a", ros::Time(4294967295u, 999999999), {0, 0, 0}, {1, 0, 0})});
  const ros::Time start(1000, 0);
  playTwoBalls(start);
  EXPECT_EQ(reportsOf(Reason::kClockJumpedBack), 1u);
  EXPECT_EQ(reportsOf(Reason::kInternalError), 0u);
  expectTwoBallImpactOnce(start);
}

// Issue 13, item 2: bodies of 1e200 kg meeting at 1e110 m/s published `impulse: inf` and
// `energy_lost: nan`; the service refuses such answers by name, and so does the monitor now:
// nothing that is not finite is published, and the refusal names the field.
class HeavyCycle : public Cycle {
 protected:
  HeavyCycle() : Cycle(twoBallScene(1e200)) {}
};

TEST_F(HeavyCycle, Item2_AnImpactBeyondTheDoublesIsNotPublished) {
  const ros::Time start(1000, 0);
  // Closing at 2e110 m/s from 0.86 m apart: contact 4.3e-111 s after the first state.
  send({state("a", start, {0, 0, 0}, {1e110, 0, 0}),
        state("b", start, {1.06, 0, 0}, {-1e110, 0, 0})});
  send({state("a", at(start, 0.1), {1e109, 0, 0}, {1e110, 0, 0}),
        state("b", at(start, 0.1), {1.06 - 1e109, 0, 0}, {-1e110, 0, 0})});
  EXPECT_TRUE(impacts_.empty()) << "impulse " << impacts_.front().impulse;
  ASSERT_EQ(reportsOf(Reason::kImpactNotFinite), 1u);
  const std::string& text = firstReport(Reason::kImpactNotFinite)->text;
  EXPECT_NE(text.find("'a' and 'b'"), std::string::npos) << text;
  EXPECT_NE(text.find(": is beyond the range of double"), std::string::npos) << text;
}

// Issue 13, item 2: touching balls at 1.3e308 m/s published NaN velocities. Here the line of
// impact is (0.6, 0.8, 0) and a moves at 1.3e308 along x and y: its normal speed 1.8e308 is
// beyond the doubles.
TEST_F(Cycle, Item2_TouchingBallsAtTheTopOfTheDoublesPublishNoNaN) {
  const ros::Time start(1000, 0);
  const Eigen::Vector3d fast(1.3e308, 1.3e308, 0);
  send({state("a", start, {0, 0, 0}, fast), state("b", start, {0.12, 0.16, 0}, {0, 0, 0})});
  send({state("a", at(start, 0.1), {0, 0, 0}, fast),
        state("b", at(start, 0.1), {0.12, 0.16, 0}, {0, 0, 0})});
  for (const Impact& impact : impacts_) {
    EXPECT_TRUE(std::isfinite(impact.velocity_a_after.linear.x)) << "a NaN was published";
    EXPECT_TRUE(std::isfinite(impact.velocity_a_after.linear.y)) << "a NaN was published";
    EXPECT_TRUE(std::isfinite(impact.energy_lost));
  }
  ASSERT_GE(reportsOf(Reason::kImpactNotFinite), 1u);
  EXPECT_NE(firstReport(Reason::kImpactNotFinite)->text.find("is beyond the range of double"),
            std::string::npos);
  // And the monitor goes on: the ordinary case afterwards (the tracks start again from states).
  impacts_.clear();
  const ros::Time later = at(start, 10.0);
  playTwoBalls(later);
  EXPECT_EQ(reportsOf(Reason::kInternalError), 0u);
  expectTwoBallImpactOnce(later);
}

// Issue 13, item 3: a finite state far away and fast overflowed the grid's int64 cell count,
// which wrapped past the guard; the node walked and stored cells until memory ran out.
class FarFastCycle : public Cycle {
 protected:
  FarFastCycle() : Cycle(twoBallScene(1.0, 2)) {}
};

TEST_F(FarFastCycle, Item3_AFarFastStateIsBoundedWork) {
  const ros::Time start(1000, 0);
  const auto others = [&](const ros::Time& stamp) {
    return std::vector<BodyState>{state("a", stamp, {0, 0, 0}, {0, 0, 0}),
                                  state("b", stamp, {1, 0, 0}, {0, 0, 0}),
                                  state("extra_100001", stamp, {2, 0, 0}, {0, 0, 0})};
  };
  auto first = others(start);
  first.push_back(state("extra_100000", start, {5, -1.76e13, 5}, {1.05e8, 7.04e13, 0}));
  send(first);
  auto second = others(at(start, 0.5));
  second.push_back(state("extra_100000", at(start, 0.5),
                         {5 + 0.5 * 1.05e8, -1.76e13 + 0.5 * 7.04e13, 5}, {1.05e8, 7.04e13, 0}));
  send(second);  // before the fix: gigabytes and minutes here
  EXPECT_TRUE(impacts_.empty());
  EXPECT_TRUE(reports_.empty());
  EXPECT_EQ(cycle_.monitor().trackedBodies(), 4u);
}

// Issue 13, item 5: two sources whose clocks differ by 5 s gave a "time jumped back" warning
// per message and reset every track each time: no impact was ever found. The lagging source is
// shifted onto the line once, said once, and the impact is found.
TEST_F(Cycle, Item5_TwoSourcesWhoseClocksDifferBy5s) {
  const ros::Time start(1000, 0);
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.1 * k;
    const ros::Time stamp = start + ros::Duration(0, 100000000 * k);
    send({state("a", stamp, {t, 0, 0}, {1, 0, 0})}, "/tracker_a");
    send({state("", stamp - ros::Duration(5.0), {1.06 - t, 0, 0}, {-1, 0, 0})}, "/tracker_b",
         "/b/state", "b");
  }
  EXPECT_EQ(reportsOf(Reason::kClockJumpedBack), 0u);
  ASSERT_EQ(reportsOf(Reason::kClockOffset), 1u) << "said once";
  const std::string& text = firstReport(Reason::kClockOffset)->text;
  EXPECT_NE(text.find("/b/state from /tracker_b"), std::string::npos) << text;
  EXPECT_NE(text.find("5 s behind"), std::string::npos) << text;
  EXPECT_NE(text.find("/body_states from /tracker_a"), std::string::npos) << text;
  EXPECT_EQ(cycle_.timeLine().offset("/b/state from /tracker_b"), 5.0);
  expectTwoBallImpactOnce(start);
}

// A bag played with --loop: the source's own stamps go back; every track is reset, once.
TEST_F(Cycle, ASourceWhoseOwnClockGoesBackRestartsTheLine) {
  playTwoBalls(ros::Time(1000, 0));
  impacts_.clear();
  const ros::Time again(900, 0);
  playTwoBalls(again);
  EXPECT_EQ(reportsOf(Reason::kClockJumpedBack), 1u);
  EXPECT_NE(firstReport(Reason::kClockJumpedBack)->text.find("jumped back"), std::string::npos);
  expectTwoBallImpactOnce(again);
}

// Issue 27, item 3: a second source sent one state stamped now + 299 s (inside
// ~future_stamp_tolerance); the tracker's states were then shifted onto the line by 299 s and
// its impact was stamped 299 s late. The tracker keeps the node's clock here (the node's clock
// is each message's stamp): it keeps offset 0, its instants and its impact's stamp; the odd
// source gets an offset of its own, said once, naming it and header.stamp.
class ThirdBodyCycle : public Cycle {
 protected:
  ThirdBodyCycle() : Cycle(twoBallScene(1.0, 1)) {}

  /// The two-ball case from /tracker, the node's clock at each stamp; `odd` before state k.
  void playWithOddStamp(const ros::Time& start, int odd_at) {
    for (int k = 0; k <= 10; ++k) {
      const double t = 0.1 * k;
      const ros::Time stamp = start + ros::Duration(0, 100000000 * k);
      clock_ = stamp;
      if (k == odd_at) {
        send({state("extra_100000", stamp + ros::Duration(299.0), {0, 5, 0}, {0, 0, 0})}, "/other");
      }
      times_.push_back(send({state("a", stamp, {t, 0, 0}, {1, 0, 0}),
                             state("b", stamp, {1.06 - t, 0, 0}, {-1, 0, 0})},
                            "/tracker")
                           .time);
    }
  }

  void expectTheTrackerUnmoved(const ros::Time& start) {
    EXPECT_EQ(cycle_.timeLine().offset("/body_states from /tracker"), 0.0);
    ASSERT_EQ(times_.size(), 11u);
    for (int k = 1; k <= 10; ++k) {
      EXPECT_NEAR(times_[k] - times_[0], 0.1 * k, 1e-9) << "the tracker's instants: its stamps";
    }
    EXPECT_EQ(reportsOf(Reason::kClockJumpedBack), 0u);
    ASSERT_EQ(reportsOf(Reason::kClockOffset), 1u) << "said once";
    const std::string& text = firstReport(Reason::kClockOffset)->text;
    EXPECT_NE(text.find("/body_states from /other"), std::string::npos) << text;
    EXPECT_NE(text.find("299 s ahead of"), std::string::npos) << text;
    EXPECT_NE(text.find("header.stamp 1299."), std::string::npos) << text;
    expectTwoBallImpactOnce(start);
  }

  std::vector<double> times_;
};

TEST_F(ThirdBodyCycle, Issue27_Item3_OneStamp299sAheadFromASecondSourceMovesNoOtherSource) {
  const ros::Time start(1000, 0);
  playWithOddStamp(start, 3);
  expectTheTrackerUnmoved(start);
  EXPECT_EQ(cycle_.timeLine().offset("/body_states from /other"), -299.0);
}

TEST_F(ThirdBodyCycle, Issue27_Item3_OneStamp299sAheadAsTheFirstStampEverMovesNoOtherSource) {
  const ros::Time start(1000, 0);
  playWithOddStamp(start, 0);
  expectTheTrackerUnmoved(start);
}

// Issue 27, item 3: one publisher interleaving two clocks reset every track on every message,
// and the pair's impact was never found. Here /mixed sends a's states on the node's clock (at
// the true instants 0.1 k s) and, 0.05 s after each, b's on a clock 299 s behind it. Expected:
// no reset; b's clock is placed on the line on its own from its first state (said once), by
// the node's clock at its arrival (exact here: the clock is each message's true instant); the
// impact once, with the closed form, stamped in a's clock, the one that keeps the node's:
// start + 0.43 s.
TEST_F(Cycle, Issue27_Item3_OnePublisherInterleavingTwoClocksForThePairsTwoBodies) {
  const ros::Time start(1000, 0);
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.1 * k;
    clock_ = start + ros::Duration(t);
    send({state("a", clock_, {t, 0, 0}, {1, 0, 0})}, "/mixed");
    clock_ = start + ros::Duration(t + 0.05);
    send({state("b", clock_ - ros::Duration(299.0), {1.06 - (t + 0.05), 0, 0}, {-1, 0, 0})},
         "/mixed");
  }
  EXPECT_EQ(reportsOf(Reason::kClockJumpedBack), 0u);
  ASSERT_EQ(reportsOf(Reason::kClockOffset), 1u) << "said once";
  EXPECT_NE(firstReport(Reason::kClockOffset)->text.find("/body_states from /mixed"),
            std::string::npos);
  expectTwoBallImpactOnce(start);
}

// The same, the two clocks alternating message by message with both bodies in each: {a, b} at
// 0.1 k s on the node's clock, then at 0.1 k + 0.05 s on the clock 299 s behind. Expected: no
// reset; the impact once, stamped in the clock of the states it was predicted from (those at
// 0.4 s, on the node's clock; the ones at 0.45 s reveal it): start + 0.43 s.
TEST_F(Cycle, Issue27_Item3_OnePublisherInterleavingTwoClocksForTheSameBodies) {
  const ros::Time start(1000, 0);
  for (int k = 0; k <= 10; ++k) {
    for (const double late : {0.0, 0.05}) {
      const double t = 0.1 * k + late;
      clock_ = start + ros::Duration(t);
      const ros::Time stamp = late > 0.0 ? clock_ - ros::Duration(299.0) : clock_;
      send({state("a", stamp, {t, 0, 0}, {1, 0, 0}),
            state("b", stamp, {1.06 - t, 0, 0}, {-1, 0, 0})},
           "/mixed");
    }
  }
  EXPECT_EQ(reportsOf(Reason::kClockJumpedBack), 0u);
  EXPECT_EQ(reportsOf(Reason::kClockOffset), 1u) << "said once";
  expectTwoBallImpactOnce(start);
}

// The time line itself (issue 27, item 3), the node's clock at each stamp's true instant.
ros::Time stampAt(const ros::Time& start, double seconds) { return start + ros::Duration(seconds); }

TEST(TimeLine, Issue27_Item3_A299sStampFromASecondSourceLeavesTheGoodSourceAtOffsetZero) {
  TimeLine line(1.0);
  const ros::Time start(1000, 0);
  double now = 0.0;
  for (int k = 0; k <= 5; ++k) {
    const ros::Time stamp = stampAt(start, 0.1 * k);
    if (k == 3) {
      const TimeLine::Placed odd = line.place("/odd", stamp + ros::Duration(299.0), stamp, now);
      EXPECT_EQ(odd.event, TimeLine::Event::kOffsetChanged);
      EXPECT_NEAR(odd.time, 0.3, 1e-9) << "at the line's present";
      EXPECT_NEAR(line.offset("/odd"), -299.0, 1e-9);
    }
    const TimeLine::Placed good = line.place("/good", stamp, stamp, now);
    EXPECT_EQ(good.event, k == 0 ? TimeLine::Event::kStarted : TimeLine::Event::kNone);
    EXPECT_NEAR(good.time, 0.1 * k, 1e-9) << "its own stamps";
    EXPECT_EQ(good.clock_offset, 0);
    now = good.time;
  }
  EXPECT_EQ(line.offset("/good"), 0.0);
  ros::Time stamp;
  ASSERT_TRUE(line.stampOf(0.43, 0, stamp));
  EXPECT_EQ(stamp, ros::Time(1000, 430000000));
}

// Interleaving: /mixed keeps clock A for four messages, then alternates A and B = A - 299 s.
// B's first stamp is held (its clock went back), dropped when A's next one continues A, and
// B's second makes B the source's second clock; from then on each is placed on its own clock
// at its true instant, and nothing is ever reset.
TEST(TimeLine, Issue27_Item3_ASourceInterleavingTwoClocksDoesNotResetOnEveryMessage) {
  TimeLine line(1.0);
  const ros::Time start(1000, 0);
  double now = 0.0;
  std::vector<TimeLine::Event> events;
  for (int k = 0; k <= 8; ++k) {
    const ros::Time a = stampAt(start, 0.1 * k);
    const TimeLine::Placed on_a = line.place("/mixed", a, a, now);
    EXPECT_NEAR(on_a.time, 0.1 * k, 1e-9);
    EXPECT_EQ(on_a.clock_offset, 0);
    EXPECT_EQ(on_a.dropped_held, k == 4);
    now = on_a.time;
    events.push_back(on_a.event);
    if (k < 3) continue;
    const ros::Time clock = stampAt(start, 0.1 * k + 0.05);
    const TimeLine::Placed on_b = line.place("/mixed", clock - ros::Duration(299.0), clock, now);
    events.push_back(on_b.event);
    if (on_b.event == TimeLine::Event::kHeld) continue;
    EXPECT_NEAR(on_b.time, 0.1 * k + 0.05, 1e-9) << "at its true instant";
    EXPECT_EQ(on_b.clock_offset, 299000000000);
    now = on_b.time;
  }
  using E = TimeLine::Event;
  // A0 A1 A2 A3 B3 (held) A4 (drops it) B4 (second clock), then A5 B5 ... A8 B8 on their clocks.
  std::vector<E> expected{E::kStarted, E::kNone, E::kNone,       E::kNone,
                          E::kHeld,    E::kNone, E::kSecondClock};
  expected.resize(expected.size() + 8, E::kNone);
  EXPECT_EQ(events, expected);
  const auto sources = line.sources();
  ASSERT_EQ(sources.count("/mixed"), 1u);
  EXPECT_EQ(sources.at("/mixed").offsets.size(), 2u);
  EXPECT_EQ(sources.at("/mixed").dropped, 1u);
}

// rosbag play --loop: the source's stamps go back 100 s and continue from there. The first is
// held, the second confirms: the line restarts at the first, every track to be reset.
TEST(TimeLine, Issue27_Item3_ABagLoopStillResets) {
  TimeLine line(1.0);
  const ros::Time start(1000, 0);
  double now = 0.0;
  for (int k = 0; k <= 10; ++k) {
    const ros::Time stamp = stampAt(start, 0.1 * k);
    now = line.place("/bag", stamp, stamp, now).time;
  }
  const ros::Time again(900, 0);
  const TimeLine::Placed held = line.place("/bag", again, stampAt(start, 1.1), now);
  EXPECT_EQ(held.event, TimeLine::Event::kHeld);
  const TimeLine::Placed loop = line.place("/bag", stampAt(again, 0.1), stampAt(start, 1.2), now);
  EXPECT_EQ(loop.event, TimeLine::Event::kJumpedBack);
  EXPECT_TRUE(loop.release_held);
  EXPECT_EQ(loop.held_stamp, again);
  EXPECT_NEAR(loop.time, 0.1, 1e-9) << "the line restarts at the held stamp";
  ros::Time stamp;
  ASSERT_TRUE(line.stampOf(0.43, loop.clock_offset, stamp));
  EXPECT_EQ(stamp, ros::Time(900, 430000000)) << "in the bag's clock";
}

// A single stamp back from a good source is dropped, not a reset.
TEST(TimeLine, Issue27_Item3_OneStampBackFromItsClockIsDroppedNotAReset) {
  TimeLine line(1.0);
  const ros::Time start(1000, 0);
  double now = 0.0;
  for (int k = 0; k <= 10; ++k) {
    const ros::Time stamp = stampAt(start, 0.1 * k);
    if (k == 5) {
      EXPECT_EQ(line.place("/good", stamp - ros::Duration(299.0), stamp, now).event,
                TimeLine::Event::kHeld);
    }
    const TimeLine::Placed placed = line.place("/good", stamp, stamp, now);
    EXPECT_EQ(placed.event, k == 0 ? TimeLine::Event::kStarted : TimeLine::Event::kNone);
    EXPECT_EQ(placed.dropped_held, k == 5);
    EXPECT_NEAR(placed.time, 0.1 * k, 1e-9);
    now = placed.time;
  }
  EXPECT_EQ(line.sources().at("/good").dropped, 1u);
}

// A second machine whose clock is 5 s behind the node's (and the first source's): its offset
// is 5 s, once, and its states land at their true instants.
TEST(TimeLine, Issue27_Item3_AMachine5sBehindIsStillAligned) {
  TimeLine line(1.0);
  const ros::Time start(1000, 0);
  double now = 0.0;
  for (int k = 0; k <= 10; ++k) {
    const ros::Time stamp = stampAt(start, 0.1 * k);
    const TimeLine::Placed on_a = line.place("/tracker_a", stamp, stamp, now);
    EXPECT_NEAR(on_a.time, 0.1 * k, 1e-9);
    const TimeLine::Placed on_b =
        line.place("/tracker_b", stamp - ros::Duration(5.0), stamp, on_a.time);
    EXPECT_EQ(on_b.event, k == 0 ? TimeLine::Event::kOffsetChanged : TimeLine::Event::kNone);
    EXPECT_NEAR(on_b.time, 0.1 * k, 1e-9);
    // A second topic of the same machine, 1 ms later by the node's clock: the same offset.
    const TimeLine::Placed on_imu = line.place("/tracker_b_imu", stamp - ros::Duration(5.0),
                                               stamp + ros::Duration(0.001), on_b.time);
    EXPECT_EQ(on_imu.clock_offset, on_b.clock_offset) << "sources sharing a clock share it";
    EXPECT_NEAR(on_imu.time, 0.1 * k, 1e-9);
    now = on_imu.time;
  }
  EXPECT_EQ(line.offset("/tracker_a"), 0.0);
  EXPECT_EQ(line.offset("/tracker_b"), 5.0);
  EXPECT_EQ(line.offset("/tracker_b_imu"), 5.0);
}

// The README's "By hand" example: two `rostopic pub` (two publisher nodes, two sources) send
// hand-made stamps 100 s and 101 s, far off the node's clock, typed 4 s apart. The second
// continues the first's clock (not before its last stamp, not ahead of where it is now), so it
// shares that clock's offset: the two states are 1 s apart on the line, as their stamps say,
// not 4 s (which would let ~body_timeout forget the tracks before the impact is found). A
// stamp off that clock too (5 s ahead of where it is now) still gets a clock of its own.
TEST(TimeLine, TwoPublishersOfHandMadeStampsShareTheirClock) {
  TimeLine line(1.0);
  const ros::Time node(1796322132, 0);
  const TimeLine::Placed first =
      line.place("/body_states from /rostopic_1", ros::Time(100, 0), node, 0.0);
  const TimeLine::Placed second = line.place("/body_states from /rostopic_2", ros::Time(101, 0),
                                             node + ros::Duration(4.0), first.time);
  EXPECT_EQ(second.clock_offset, first.clock_offset);
  EXPECT_NEAR(second.time - first.time, 1.0, 1e-9);
  const TimeLine::Placed odd = line.place("/body_states from /rostopic_3", ros::Time(110, 0),
                                          node + ros::Duration(5.0), second.time);
  EXPECT_NE(odd.clock_offset, first.clock_offset);
}

// Issue 13, item 7: the same id twice in one array was dropped as "not newer" without naming
// the id or the duplicate.
TEST_F(Cycle, Item7_TheSameIdTwiceInOneArrayIsNamed) {
  const ros::Time start(1000, 0);
  send({state("a", start, {0, 0, 0}, {1, 0, 0}), state("b", start, {1, 0, 0}, {0, 0, 0}),
        state("a", at(start, 0.001), {0.001, 0, 0}, {1, 0, 0})});
  ASSERT_EQ(reportsOf(Reason::kDuplicateId), 1u);
  const std::string& text = firstReport(Reason::kDuplicateId)->text;
  EXPECT_NE(text.find("states[0]"), std::string::npos) << text;  // the older one, dropped
  EXPECT_NE(text.find("states[2]"), std::string::npos) << text;  // the newer, kept
  EXPECT_NE(text.find("'a'"), std::string::npos) << text;
  // The newer state is the track: a at 0.001 m at the array's newest stamp (the line's now).
  const auto track =
      cycle_.monitor().predictedState(*cycle_.monitor().bodyIndex("a"), cycle_.monitor().now());
  ASSERT_TRUE(track);
  EXPECT_EQ(track->first.x(), 0.001);
  EXPECT_EQ(reportsOf(Reason::kStale), 0u);
}

// Issue 13, item 9: one array of 10,000 states with distinct stamps 10 us apart took one full
// step per stamp (23 s, the service blocked meanwhile). It is one step now, each state entering
// at its own stamp.
class ManyBodies : public Cycle {
 protected:
  ManyBodies() : Cycle(twoBallScene(1.0, 9998)) {}
};

TEST_F(ManyBodies, Item9_AnArrayOfDistinctStampsIsOneStep) {
  const ros::Time start(1000, 0);
  const auto& monitor = cycle_.monitor();
  std::vector<BodyState> array;
  for (std::size_t i = 0; i < monitor.bodyCount(); ++i) {
    const ros::Time stamp = start + ros::Duration(0, static_cast<std::int32_t>(10000 * i));
    array.push_back(
        state(monitor.body(i).id, stamp, {2.0 * static_cast<double>(i), 5, 0}, {0, 1, 0}));
  }
  send(array);
  const std::uint64_t before = cycle_.steps();
  for (auto& s : array) s.header.stamp += ros::Duration(1.0);
  send(array);
  EXPECT_EQ(cycle_.steps(), before + 1) << "one step for the whole array";
  EXPECT_TRUE(reports_.empty());
  EXPECT_EQ(monitor.trackedBodies(), monitor.bodyCount());
  // Each track starts at its own state's stamp: at the array's newest instant, body i has
  // moved 1 m/s for the 10 us x (n - 1 - i) between its stamp and the newest.
  const double newest = monitor.now();
  for (const std::size_t i : {std::size_t{0}, std::size_t{1234}, monitor.bodyCount() - 1}) {
    const auto track = monitor.predictedState(i, newest);
    ASSERT_TRUE(track);
    const double lag = 1e-5 * static_cast<double>(monitor.bodyCount() - 1 - i);
    EXPECT_NEAR(track->first.y(), 5.0 + lag, 2e-9) << i;
  }
}

// Issue 13, item 4: 1,000 distinct unknown ids a message gave one warning each, and the
// throttle's map kept every id for ever. The intake quotes an id at most 64 characters long,
// the throttle's key is (topic, reason), and its map has a hard cap.
TEST_F(Cycle, Item4_UnknownIdsAreOneReasonAndTheThrottleIsBounded) {
  std::vector<BodyState> array;
  for (int i = 0; i < 1000; ++i) {
    array.push_back(
        state("ghost_" + std::to_string(i) + std::string(500, 'x'), clock_, {0, 0, 0}, {0, 0, 0}));
  }
  send(array);
  EXPECT_EQ(reportsOf(Reason::kUnknownId), 1000u);
  for (const Report& report : reports_) EXPECT_LT(report.text.size(), 200u);
  // The throttle logs the first of each key: quietly here.
  ros::console::set_logger_level(ROSCONSOLE_DEFAULT_NAME, ros::console::levels::Error);
  ros::console::notifyLoggerLevelsChanged();
  ThrottledWarning warnings(1.0);
  for (int i = 0; i < 100000; ++i) {
    warnings.warn("/body_states", Reason::kUnknownId,
                  reports_[static_cast<std::size_t>(i % 1000)].text);
  }
  EXPECT_EQ(warnings.keys(), 1u);
  for (int i = 0; i < 1100; ++i) {
    warnings.warn("/topic_" + std::to_string(i), Reason::kUnknownId, "text");
  }
  EXPECT_LE(warnings.keys(), ThrottledWarning::kMaxKeys + kReasonCount);
}

TEST_F(Cycle, StatesInAStaticFrameAreTransformed) {
  geometry_msgs::TransformStamped camera;
  camera.header.frame_id = "world";
  camera.child_frame_id = "camera";
  camera.transform.translation.x = 10.0;
  camera.transform.rotation.w = 1.0;
  tf_.setTransform(camera, "test", /*is_static=*/true);
  const ros::Time start(1000, 0);
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.1 * k;
    const ros::Time stamp = start + ros::Duration(0, 100000000 * k);
    send({state("a", stamp, {t, 0, 0}, {1, 0, 0}),
          state("b", stamp, {1.06 - t - 10.0, 0, 0}, {-1, 0, 0}, "camera")});
  }
  expectTwoBallImpactOnce(start);
}

TEST_F(Cycle, AMissingTransformMakesTheInputWaitThenDropsItsStateByName) {
  std::vector<BodyState> states = {state("a", clock_, {0, 0, 0}, {0, 0, 0}, "nowhere")};
  MonitorCycle::Input input{&states, "/body_states", "/source", ""};
  EXPECT_TRUE(cycle_.process(input, clock_, true, tf_).waiting);
  const MonitorCycle::Update update = cycle_.process(input, clock_, false, tf_);
  EXPECT_FALSE(update.waiting);
  ASSERT_EQ(update.reports.size(), 1u);
  EXPECT_EQ(update.reports[0].reason, Reason::kTransformMissing);
  EXPECT_NE(update.reports[0].text.find("header.frame_id: nowhere"), std::string::npos)
      << update.reports[0].text;
}

// A tf-attached obstacle: the plane x = 0 of frame "paddle", its normal +x, the frame at
// x = -1 in the world (a static transform, so at rest). a at x = -t moving -1 m/s touches it
// (radius 0.1) at x = -0.9, t = 0.9 s; e = 0.5 against the immovable plane: v' = +0.5 m/s,
// impulse (1 + e) m v = 1.5 N s, energy lost m v^2 (1 - e^2) / 2 = 0.375 J.
core::Scene twoBallsAndPaddleScene() {
  core::Scene scene = twoBallScene();
  core::ObstacleSpec paddle;
  paddle.id = "paddle";
  paddle.material = "test_half";
  paddle.frame = "paddle";
  paddle.normal = Eigen::Vector3d::UnitX();
  scene.obstacles.push_back(paddle);
  return scene;
}

class CycleWithPaddle : public Cycle {
 protected:
  CycleWithPaddle() : Cycle(twoBallsAndPaddleScene()) {}
};

TEST_F(CycleWithPaddle, AMissingObstacleFrameMakesTheInputWaitThenTheObstacleIsPlacedOnceKnown) {
  const ros::Time start = clock_;
  std::vector<BodyState> first = {state("a", start, {0, 0, 0}, {-1, 0, 0})};
  MonitorCycle::Input input{&first, "/body_states", "/source", ""};
  const MonitorCycle::Update waited = cycle_.process(input, clock_, true, tf_);
  EXPECT_TRUE(waited.waiting);
  EXPECT_TRUE(waited.reports.empty());
  // Not waiting any more: the step goes on without the obstacle, counted but not warned of
  // (tf has no history of its frame yet).
  const MonitorCycle::Update update = send(first);
  EXPECT_FALSE(update.waiting);
  EXPECT_TRUE(update.stepped);
  ASSERT_EQ(update.reports.size(), 1u);
  EXPECT_EQ(update.reports[0].reason, Reason::kObstacleTransform);
  EXPECT_FALSE(update.reports[0].warn);
  EXPECT_NE(update.reports[0].text.find("obstacle 'paddle'"), std::string::npos)
      << update.reports[0].text;

  geometry_msgs::TransformStamped frame;
  frame.header.frame_id = "world";
  frame.child_frame_id = "paddle";
  frame.transform.translation.x = -1.0;
  frame.transform.rotation.w = 1.0;
  tf_.setTransform(frame, "test", /*is_static=*/true);
  reports_.clear();
  for (int k = 1; k <= 10; ++k) {
    const double t = 0.1 * k;
    send({state("a", start + ros::Duration(0, 100000000 * k), {-t, 0, 0}, {-1, 0, 0})});
  }
  // The obstacle is placed at every input from then on; the source ignores the impact, and
  // its state at t = 1 lacks it (said once).
  EXPECT_EQ(reportsOf(Reason::kObstacleTransform), 0u);
  EXPECT_EQ(reportsOf(Reason::kImpactContradicted), 1u);
  EXPECT_EQ(reports_.size(), 1u);
  ASSERT_EQ(impacts_.size(), 1u);
  const Impact& impact = impacts_[0];
  EXPECT_EQ(impact.body_a, "a");
  EXPECT_EQ(impact.body_b, "paddle");
  EXPECT_NEAR((impact.header.stamp - start).toSec(), 0.9, 1e-9);
  EXPECT_NEAR(impact.contact_point.x, -1.0, 1e-9);
  EXPECT_NEAR(impact.velocity_a_after.linear.x, 0.5, 1e-9);
  EXPECT_NEAR(impact.impulse, 1.5, 1e-9);
  EXPECT_NEAR(impact.energy_lost, 0.375, 1e-9);
}

// Live tuning (dynamic_reconfigure) reaches the next impact and the scene the node reports:
// with restitution_threshold 3 m/s above the two balls' approach at 2 m/s, e = 0: equal masses
// end at the common velocity 0, impulse m v_rel / 2 = 1 N s, energy lost m v^2 = 1 J.
TEST_F(Cycle, ATunedRestitutionThresholdReachesTheNextImpactAndTheScene) {
  cycle_.tune(core::Detection::kContinuous, 3.0, core::CombineRule::kMax);
  EXPECT_EQ(cycle_.scene().restitution_threshold, 3.0);
  EXPECT_EQ(cycle_.scene().materials.combineRule(), core::CombineRule::kMax);
  playTwoBalls(ros::Time(1000, 0));
  ASSERT_EQ(impacts_.size(), 1u);
  const Impact& impact = impacts_[0];
  EXPECT_NEAR((impact.header.stamp - ros::Time(1000, 0)).toSec(), 0.43, 1e-9);
  EXPECT_EQ(impact.restitution, 0.0);
  EXPECT_NEAR(impact.velocity_a_after.linear.x, 0.0, 1e-9);
  EXPECT_NEAR(impact.velocity_b_after.linear.x, 0.0, 1e-9);
  EXPECT_NEAR(impact.impulse, 1.0, 1e-9);
  EXPECT_NEAR(impact.energy_lost, 1.0, 1e-9);
}

// Issue 12, item 3: an elastic ball between two walls 1e-5 m wider than it, crossing at 1 m/s,
// strikes a wall every 1e-5 s: a 1 s message interval asks for 100,000 impacts, beyond the
// step's budget (10,000 instants). The fallback is counted by name in diagnostics, and every
// impact it published has the ball in the gap: its contact point is on a wall, never beyond.
core::Scene wedgedBallScene() {
  core::Scene scene;
  scene.materials.addMaterial("test_elastic", core::Material{1.0, std::nullopt}, "materials");
  core::BodySpec ball;
  ball.id = "a";
  ball.mass = 0.1;
  ball.radius = 0.05;
  ball.material = "test_elastic";
  scene.bodies.push_back(ball);
  const double wall = 0.05 + 0.5e-5;  // each wall's distance from the gap's middle
  for (const double side : {1.0, -1.0}) {
    core::ObstacleSpec plane;
    plane.id = side > 0 ? "left" : "right";
    plane.material = "test_elastic";
    plane.normal = Eigen::Vector3d(side, 0, 0);
    plane.offset = -wall;
    scene.obstacles.push_back(plane);
  }
  return scene;
}

class WedgedCycle : public Cycle {
 protected:
  WedgedCycle() : Cycle(wedgedBallScene()) {}
};

TEST_F(WedgedCycle, Item12_AStepWhoseBudgetRunsOutIsCountedAndKeepsTheBallInTheGap) {
  const ros::Time start(1000, 0);
  send({state("a", start, {0, 0, 0}, {1, 0, 0})});
  send({state("a", at(start, 1.0), {0, 0, 0}, {1, 0, 0})});
  ASSERT_GE(reportsOf(Reason::kStepTruncated), 1u);
  const std::string& text = firstReport(Reason::kStepTruncated)->text;
  EXPECT_NE(text.find("fallback"), std::string::npos) << text;
  EXPECT_STREQ(counterName(Reason::kStepTruncated), "steps truncated");
  ASSERT_FALSE(impacts_.empty());
  for (const Impact& impact : impacts_) {
    // The contact point of a ball on a wall is on the wall: |x| = 0.05 + 0.5e-5.
    EXPECT_LE(std::abs(impact.contact_point.x), 0.05 + 0.5e-5 + 1e-12);
    EXPECT_TRUE(std::isfinite(impact.velocity_a_after.linear.x));
  }
}

// Lasting contact (README, "Topics": `contacts`): two balls resting on a floor under gravity, a
// light one (1 kg, r = 0.1 m, at rest touching: the floor carries m g = 9.81 N) and one of
// 1e308 kg, whose weight 9.81e308 N is beyond the doubles: that contact is not published, named
// and counted (as an impact beyond the doubles is), and the light one's is.
core::Scene floorScene() {
  core::Scene scene = twoBallScene();
  scene.bodies[1].id = "heavy";
  scene.bodies[1].mass = 1e308;
  scene.bodies[0].id = "light";
  scene.effects.gravity = true;
  scene.gravity = Eigen::Vector3d(0, 0, -9.81);
  core::ObstacleSpec floor;
  floor.id = "floor";
  floor.normal = Eigen::Vector3d::UnitZ();
  floor.material = "test_half";
  scene.obstacles.push_back(floor);
  return scene;
}

class FloorCycle : public Cycle {
 protected:
  FloorCycle() : Cycle(floorScene()) {}
};

TEST_F(FloorCycle, ContactsArePublishedFiniteAndNamed) {
  const ros::Time start(1000, 0);
  MonitorCycle::Update update;
  for (int k = 0; k <= 5; ++k) {
    update = send({state("light", at(start, 0.1 * k), {0, 0, 0.1}, {0, 0, 0}),
                   state("heavy", at(start, 0.1 * k), {10, 0, 0.1}, {0, 0, 0})});
  }
  EXPECT_EQ(update.contacts.header.stamp, at(start, 0.5));
  EXPECT_EQ(update.contacts.header.frame_id, "world");
  ASSERT_EQ(update.contacts.contacts.size(), 1u);
  const Contact& contact = update.contacts.contacts[0];
  EXPECT_EQ(contact.body_a, "light");
  EXPECT_EQ(contact.body_b, "floor");
  EXPECT_NEAR(contact.normal_force, 9.81, 1e-12);
  EXPECT_EQ(contact.state, "resting");
  EXPECT_NEAR(contact.normal.z, -1.0, 1e-15);  // from the ball into the floor
  EXPECT_NEAR(contact.contact_point.z, 0.0, 1e-12);
  EXPECT_LE(contact.since, at(start, 0.5));
  EXPECT_GE(contact.since, start);
  ASSERT_GE(reportsOf(Reason::kContactNotFinite), 1u);
  const std::string& text = firstReport(Reason::kContactNotFinite)->text;
  EXPECT_NE(text.find("'heavy' and 'floor'"), std::string::npos) << text;
  EXPECT_TRUE(isDrop(Reason::kContactNotFinite));
}

// Stepped clusters (README, "Scene file"): a layer of `count` balls (r = 0.05 m, 0.1 kg) at rest
// on a floor, in a grid of rows of 8 whose neighbours touch (centres 2 r apart, at z = r), gravity
// on. Each ball touches the floor and its neighbours: the whole layer is one connected set of
// near bodies.
constexpr double kLayerRadius = 0.05, kLayerMass = 0.1, kG = 9.81;

core::Scene layerScene(int count) {
  core::Scene scene;
  scene.effects.gravity = true;
  scene.gravity = Eigen::Vector3d(0, 0, -kG);
  scene.materials.addMaterial("test_half", core::Material{0.5, std::nullopt}, "materials");
  for (int i = 0; i < count; ++i) {
    core::BodySpec body;
    body.id = "ball_" + std::to_string(100 + i);
    body.mass = kLayerMass;
    body.radius = kLayerRadius;
    body.material = "test_half";
    body.position = Eigen::Vector3d(kLayerRadius * (1 + 2 * (i % 8)),
                                    kLayerRadius * (1 + 2 * (i / 8)), kLayerRadius);
    scene.bodies.push_back(body);
  }
  core::ObstacleSpec floor;
  floor.id = "floor";
  floor.normal = Eigen::Vector3d::UnitZ();
  floor.material = "test_half";
  scene.obstacles.push_back(floor);
  return scene;
}

/// The states of `scene`'s bodies at rest where the scene places them, stamped `stamp`.
std::vector<BodyState> atRest(const core::Scene& scene, const ros::Time& stamp) {
  std::vector<BodyState> states;
  for (const core::BodySpec& body : scene.bodies) {
    states.push_back(state(body.id, stamp, body.position, Eigen::Vector3d::Zero()));
  }
  return states;
}

/// The value diagnostics shows under `key`, or "(none)".
std::string diagnosticValue(const diagnostic_updater::DiagnosticStatusWrapper& status,
                            const std::string& key) {
  for (const diagnostic_msgs::KeyValue& value : status.values) {
    if (value.key == key) return value.value;
  }
  return "(none)";
}

class LayerCycle : public Cycle {
 protected:
  LayerCycle() : Cycle(layerScene(32)) {}
};

// 32 touching balls: a stepped cluster of 32 (the default stepped_cluster_min_bodies) from the
// first update on (the first input only starts the time line), shown in diagnostics. At rest,
// every sub-step's gravity kick m g h is taken back by the floor's keeping impulse alone (the
// neighbours' normals are horizontal): each ball's floor contact carries m g = 0.981 N.
TEST_F(LayerCycle, ATouchingLayerOf32IsOneSteppedClusterShownInDiagnostics) {
  const ros::Time start(1000, 0);
  MonitorCycle::Update update = send(atRest(cycle_.scene(), start));
  EXPECT_EQ(update.stepped_bodies, 0u) << "the first input starts the time line only";
  for (int k = 1; k <= 5; ++k) {
    update = send(atRest(cycle_.scene(), at(start, 0.01 * k)));
    EXPECT_EQ(update.stepped_bodies, 32u) << "update " << k;
  }
  EXPECT_EQ(cycle_.steppedBodies(), 32u);
  EXPECT_EQ(reportsOf(Reason::kSteppedHeld), 0u);
  EXPECT_TRUE(impacts_.empty()) << "at rest: nothing strikes";
  std::size_t on_floor = 0;
  for (const Contact& contact : update.contacts.contacts) {
    if (contact.body_b == "floor") {
      ++on_floor;
      EXPECT_NEAR(contact.normal_force, kLayerMass * kG, 1e-6 * kLayerMass * kG) << contact.body_a;
    } else {
      // Horizontal between neighbours: nothing pushes them together (rounding only).
      EXPECT_NEAR(contact.normal_force, 0.0, 1e-9) << contact.body_a << " and " << contact.body_b;
    }
  }
  EXPECT_EQ(on_floor, 32u) << "one floor contact a ball";

  MonitorDiagnostics diagnostics;
  for (const Report& report : reports_) diagnostics.count(report.reason, report.count);
  diagnostic_updater::DiagnosticStatusWrapper status;
  diagnostics.report(status, cycle_, 0);
  EXPECT_EQ(diagnosticValue(status, "bodies in stepped clusters"), "32");
  EXPECT_EQ(diagnosticValue(status, "stepped sub-steps held (total)"), "(none)")
      << "a counter is shown once it has counted";
}

// One ball fewer than stepped_cluster_min_bodies: the exact model's, no cluster.
class SmallLayerCycle : public Cycle {
 protected:
  SmallLayerCycle() : Cycle(layerScene(31)) {}
};

TEST_F(SmallLayerCycle, ALayerOf31IsNotStepped) {
  const ros::Time start(1000, 0);
  MonitorCycle::Update update;
  for (int k = 0; k <= 5; ++k) update = send(atRest(cycle_.scene(), at(start, 0.01 * k)));
  EXPECT_EQ(update.stepped_bodies, 0u);
  EXPECT_EQ(cycle_.steppedBodies(), 0u);
  EXPECT_EQ(update.contacts.contacts.size(), 31u) << "resting on the floor all the same";
}

// A held sub-step, from real inputs: a ball (1 kg, r = 0.1 m) in a gripper, between two
// immovable balls (the jaws, r = 0.1 m) that touch it on either side along x, gravity on,
// stepped_cluster_min_bodies 1 (the ball alone is a cluster). The tracker sees the ball at the
// origin at rest (a real gripper holds it by friction), the jaws at rest for 0.02 s, then
// closing at 0.1 m/s each. Inputs come at 100 Hz, so each update is one sub-step of 0.01 s
// (stepped_cluster_time_step). No velocity of the ball keeps both gaps open over a sub-step in
// which both jaws close on it from opposite sides: such a sub-step holds it still. Those are
// the sub-steps of the updates at 0.03, 0.04 and 0.05 s (the jaws' tracks close from the states
// of 0.02 s on): three held sub-steps, counted by name, and no step reported truncated.
core::Scene squeezedScene() {
  core::Scene scene = layerScene(0);
  scene.obstacles.clear();
  scene.stepped_cluster_min_bodies = 1;
  for (const char* id : {"ball", "jaw_left", "jaw_right"}) {
    core::BodySpec body;
    body.id = id;
    body.mass = std::string(id) == "ball" ? 1.0 : kInf;
    body.radius = 0.1;
    body.material = "test_half";
    scene.bodies.push_back(body);
  }
  return scene;
}

class SqueezedCycle : public Cycle {
 protected:
  SqueezedCycle() : Cycle(squeezedScene()) {}

  static constexpr double kCloseFrom = 0.02;  ///< s: the jaws close from then on
  static constexpr double kClosing = 0.1;     ///< m/s, each jaw

  /// The states at `t` s after `start`.
  std::vector<BodyState> grip(const ros::Time& start, double t) {
    const ros::Time stamp = at(start, t);
    const double speed = t >= kCloseFrom ? kClosing : 0.0;
    const double jaw = 0.2 - speed * (t - kCloseFrom);  // each jaw's centre from the ball's
    return {state("ball", stamp, {0, 0, 0}, {0, 0, 0}),
            state("jaw_left", stamp, {-jaw, 0, 0}, {speed, 0, 0}),
            state("jaw_right", stamp, {jaw, 0, 0}, {-speed, 0, 0})};
  }
};

TEST_F(SqueezedCycle, ASqueezedClusterIsHeldAndSaysSo) {
  const ros::Time start(1000, 0);
  std::vector<std::size_t> held;  // per update
  MonitorCycle::Update update;
  for (int k = 0; k <= 5; ++k) {
    const std::size_t before = reportsOf(Reason::kSteppedHeld);
    update = send(grip(start, 0.01 * k));
    held.push_back(reportsOf(Reason::kSteppedHeld) - before);
  }
  EXPECT_EQ(held, (std::vector<std::size_t>{0, 0, 0, 1, 1, 1}));
  EXPECT_EQ(update.stepped_bodies, 1u);
  EXPECT_EQ(reportsOf(Reason::kStepTruncated), 0u);
  ASSERT_NE(firstReport(Reason::kSteppedHeld), nullptr);
  const std::string& text = firstReport(Reason::kSteppedHeld)->text;
  EXPECT_NE(text.find("held still"), std::string::npos) << text;
  EXPECT_NE(text.find("over 1 sub-step(s)"), std::string::npos) << text;
  EXPECT_FALSE(isDrop(Reason::kSteppedHeld));
  EXPECT_STREQ(counterName(Reason::kSteppedHeld), "stepped sub-steps held");

  MonitorDiagnostics diagnostics;
  for (const Report& report : reports_) diagnostics.count(report.reason, report.count);
  diagnostic_updater::DiagnosticStatusWrapper status;
  diagnostics.report(status, cycle_, 0);
  EXPECT_EQ(diagnosticValue(status, "stepped sub-steps held (total)"), "3");
  EXPECT_EQ(diagnosticValue(status, "bodies in stepped clusters"), "1");
}

// Issue 26, item 3: a ball dropped onto the top of one resting on the floor (stack.yaml's balls)
// bounces on it ever lower; the lower one, struck and pressed into the floor at each bounce, runs
// over an exact_work_budget of 4 in one update and is stepped from there with the ball near it.
// The tracker sends only a third ball far from both (a clock), so the monitor moves the two
// itself. The fallback is counted, its warning names the body and the budget, and /diagnostics
// shows the count and the last such warning.
core::Scene droppedOnAStack() {
  core::Scene scene = layerScene(0);
  scene.exact_work_budget = 4;
  const std::pair<const char*, Eigen::Vector3d> balls[] = {
      {"lower", Eigen::Vector3d(0, 0, kLayerRadius)},
      {"upper", Eigen::Vector3d(0, 0, 5 * kLayerRadius)},
      {"clock", Eigen::Vector3d(10, 0, kLayerRadius)}};
  for (const auto& [id, position] : balls) {
    core::BodySpec body;
    body.id = id;
    body.mass = kLayerMass;
    body.radius = kLayerRadius;
    body.material = "test_half";
    body.position = position;
    scene.bodies.push_back(body);
  }
  return scene;
}

class DroppedOnAStackCycle : public Cycle {
 protected:
  DroppedOnAStackCycle() : Cycle(droppedOnAStack()) {}
};

TEST_F(DroppedOnAStackCycle, BodiesOverTheExactWorkBudgetAreNamedAndCounted) {
  const ros::Time start(1000, 0);
  send(atRest(cycle_.scene(), start));
  MonitorCycle::Update update;
  for (int k = 1; k <= 100; ++k) {
    update = send({state("clock", at(start, 0.01 * k), {10, 0, kLayerRadius}, {0, 0, 0})});
  }
  ASSERT_GE(reportsOf(Reason::kOverWorkBudget), 1u);
  const std::string& text = firstReport(Reason::kOverWorkBudget)->text;
  EXPECT_EQ(text.find("the exact model's work on 'lower' ran over ~scene/exact_work_budget (4)"),
            0u)
      << text;
  EXPECT_EQ(update.stepped_bodies, 2u) << "the stack, stepped while its balls touch";
  EXPECT_EQ(reportsOf(Reason::kSteppedHeld), 0u) << "the budget's fallback is not a held sub-step";
  EXPECT_FALSE(isDrop(Reason::kOverWorkBudget));

  MonitorDiagnostics diagnostics;
  for (const Report& report : reports_) {
    diagnostics.count(report.reason, report.count);
    if (report.reason == Reason::kOverWorkBudget) diagnostics.noteOverWorkBudget(report.text);
  }
  diagnostic_updater::DiagnosticStatusWrapper status;
  diagnostics.report(status, cycle_, 0);
  EXPECT_EQ(diagnosticValue(status, "bodies stepped over the exact work budget (total)"),
            std::to_string(reportsOf(Reason::kOverWorkBudget)));
  EXPECT_EQ(diagnosticValue(status, "last bodies stepped over the exact work budget"), text);
  EXPECT_EQ(diagnosticValue(status, "bodies in stepped clusters"), "2");
}

// Issue 27, item 5: a light ball on the floor placed at x = 1.7e308 gave an empty `contacts`
// and no word (past 2^1023 the monitor's sums of two coordinates overflow: no contact, the ball
// fell through the floor). Its state
// is dropped at intake, every time, naming the body and the field, and no contact of it is
// published.
TEST_F(FloorCycle, Issue27_Item5_AStatePastTheMonitorsResolutionIsDroppedByName) {
  const ros::Time start(1000, 0);
  MonitorCycle::Update update;
  for (int k = 0; k <= 5; ++k) {
    update = send({state("light", at(start, 0.1 * k), {1.7e308, 0, 0.1}, {0, 0, 0}),
                   state("heavy", at(start, 0.1 * k), {10, 0, 0.1}, {0, 0, 0})});
  }
  EXPECT_EQ(reportsOf(Reason::kBeyondResolution), 6u);
  const Report* report = firstReport(Reason::kBeyondResolution);
  ASSERT_NE(report, nullptr);
  EXPECT_EQ(report->text,
            "dropped states[0] ('light'): pose.position.x: 1.7e+308 m is beyond where the monitor "
            "can resolve a contact (|x| must be below 2^1022 = 4.49423283715579e+307 m: past "
            "2^1023 the sum of two bodies' coordinates overflows)");
  EXPECT_STREQ(counterName(Reason::kBeyondResolution), "dropped: position beyond resolution");
  EXPECT_TRUE(isDrop(Reason::kBeyondResolution));
  for (const Contact& contact : update.contacts.contacts) EXPECT_NE(contact.body_a, "light");
}

// Issue 39, item 4: a ball (r = 0.0335 m, e = 0.712 on the floor z = 0, gravity 9.81) thrown from
// (0, 0, 1) at (5, 0, -5) m/s every 0.7 s, its states at 100 Hz the free parabola of each throw
// (the tracker's ball passes through the floor: it never saw a bounce). Each throw meets the
// floor where 1 - 5 s - g s^2 / 2 = r: s = (sqrt(25 + 2 g (1 - r)) - 5) / g after it, at x = 5 s.
// The state after a bounce of the monitor's ball was not used: the monitor's ball bounced on.
// Now every state is the ball's track, each throw's impact is published once, and the state that
// lacks it is said (a throttled warning naming the ball, a counter in diagnostics).
core::Scene throwScene() {
  core::Scene scene;
  scene.effects.gravity = true;
  scene.gravity = Eigen::Vector3d(0, 0, -9.81);
  core::BodySpec ball;
  ball.id = "ball";
  ball.mass = 0.057;
  ball.radius = 0.0335;
  ball.material = "tennis_ball";
  scene.bodies.push_back(ball);
  core::ObstacleSpec floor;
  floor.id = "floor";
  floor.normal = Eigen::Vector3d::UnitZ();
  floor.material = "concrete";
  scene.obstacles.push_back(floor);
  return scene;
}

class ThrowCycle : public Cycle {
 protected:
  ThrowCycle() : Cycle(throwScene()) {}
};

TEST_F(ThrowCycle, Issue39_Item4_EveryThrowIsFollowedAndTheStateLackingItsBounceIsSaid) {
  const double g = 9.81, r = 0.0335, period = 0.7;
  const int throws = 6, per_throw = 70;  // 100 Hz
  const ros::Time start(1000, 0);
  for (int k = 0; k < throws * per_throw; ++k) {
    const double s = 0.01 * (k % per_throw);  // since the throw
    const Eigen::Vector3d position(5 * s, 0, 1 - 5 * s - 0.5 * g * s * s),
        velocity(5, 0, -5 - g * s);
    clock_ = at(start, 0.01 * k);
    const MonitorCycle::Update update = send({state("ball", clock_, position, velocity)});
    // The monitor follows its input: the ball's track is the state.
    const auto track = cycle_.monitor().predictedState(0, update.time);
    ASSERT_TRUE(track);
    EXPECT_NEAR((track->first - position).norm(), 0.0, 1e-12) << "state " << k;
    EXPECT_NEAR((track->second - velocity).norm(), 0.0, 1e-12) << "state " << k;
  }
  const double s = (std::sqrt(25 + 2 * g * (1 - r)) - 5) / g;
  ASSERT_EQ(impacts_.size(), static_cast<std::size_t>(throws));
  for (int i = 0; i < throws; ++i) {
    const Impact& impact = impacts_[static_cast<std::size_t>(i)];
    EXPECT_EQ(impact.body_b, "floor");
    EXPECT_NEAR((impact.header.stamp - start).toSec(), period * i + s, 1e-6) << "throw " << i;
    EXPECT_NEAR(impact.contact_point.x, 5 * s, 1e-9) << "throw " << i;
  }
  EXPECT_EQ(reportsOf(Reason::kImpactContradicted), static_cast<std::size_t>(throws));
  EXPECT_EQ(reportsOf(Reason::kSetAside), 0u);
  const Report* report = firstReport(Reason::kImpactContradicted);
  ASSERT_NE(report, nullptr);
  EXPECT_EQ(report->text.find("the state of 'ball' "), 0u) << report->text;
  EXPECT_NE(report->text.find("s after its impact lacks it"), std::string::npos) << report->text;
  EXPECT_NE(report->text.find("the impact stays published"), std::string::npos) << report->text;
  EXPECT_FALSE(isDrop(Reason::kImpactContradicted)) << "a state taken, an impact published";
  MonitorDiagnostics diagnostics;
  for (const Report& item : reports_) diagnostics.count(item.reason, item.count);
  diagnostic_updater::DiagnosticStatusWrapper status;
  diagnostics.report(status, cycle_, 0);
  EXPECT_EQ(diagnosticValue(status, "impacts a later state lacks (total)"), std::to_string(throws));
}

// Issue 39, item 5: a ball thrown at 1e50 m/s through air (drag) froze without a word: its flight
// stalls at once (the integrator finds no step). Said once, naming the ball, and counted in
// diagnostics; the next state starts a flight that goes on.
core::Scene airScene() {
  core::Scene scene = throwScene();
  scene.effects.drag = true;
  return scene;
}

class AirCycle : public Cycle {
 protected:
  AirCycle() : Cycle(airScene()) {}
};

TEST_F(AirCycle, Issue39_Item5_AFlightThatStallsIsSaidAndCounted) {
  const ros::Time start(1000, 0);
  send({state("ball", start, {0, 0, 1}, {1e50, 0, 0})});
  for (int k = 1; k <= 5; ++k) send({state("ball", at(start, 0.01 * k), {0, 0, 1}, {1e50, 0, 0})});
  // Each state's flight stalls at its start, said by the update after it (which integrates it).
  EXPECT_EQ(reportsOf(Reason::kFlightStalled), 5u);
  const Report* report = firstReport(Reason::kFlightStalled);
  ASSERT_NE(report, nullptr);
  EXPECT_EQ(report->text.find("the flight through air of 'ball' stalled 0.01 s before"), 0u)
      << report->text;
  EXPECT_FALSE(isDrop(Reason::kFlightStalled));
  MonitorDiagnostics diagnostics;
  for (const Report& item : reports_) diagnostics.count(item.reason, item.count);
  diagnostic_updater::DiagnosticStatusWrapper status;
  diagnostics.report(status, cycle_, 0);
  EXPECT_EQ(diagnosticValue(status, "flights through air stalled (total)"), "5");
  reports_.clear();
  send({state("ball", at(start, 0.06), {0, 0, 1}, {5, 0, 0})});
  EXPECT_EQ(reportsOf(Reason::kFlightStalled), 1u) << "the flight of the state at 0.05 s";
  reports_.clear();
  for (int k = 7; k <= 10; ++k) send({state("ball", at(start, 0.01 * k), {0, 0, 1}, {5, 0, 0})});
  EXPECT_EQ(reportsOf(Reason::kFlightStalled), 0u);
}

TEST_F(Cycle, EveryReasonHasItsOwnCounter) {
  std::set<std::string> names;
  for (int i = 0; i < kReasonCount; ++i) names.insert(counterName(static_cast<Reason>(i)));
  EXPECT_EQ(names.size(), static_cast<std::size_t>(kReasonCount));
  EXPECT_EQ(std::string(counterName(Reason::kUnknownId)), "dropped: unknown id");
  EXPECT_TRUE(isDrop(Reason::kImpactNotFinite));
  EXPECT_FALSE(isDrop(Reason::kClockJumpedBack));
}

// Issue 41, item 3: a robot of any size. Ball 'a' (radius 0.1 m, e = 0.5) at x = t moving
// +1 m/s towards the fixed wall x = 1 (normal -x): it touches at x = 0.9, t = 0.9 s, and leaves
// at -e v = -0.5 m/s (impulse (1 + e) m v = 1.5 N s); its source applies the bounce, so it sends
// x = 0.9 - 0.5 (t - 0.9) after. Beside it a robot of `links` spheres of radius 0.05 m on frames
// link_0000, ..., 9 m and more away: on /tf_static each at its place, or as a chain (each frame
// 0.2 m along x from its parent), or not on tf at all.
core::Scene ballWallAndRobotScene(int links) {
  core::Scene scene = twoBallScene();
  core::ObstacleSpec wall;
  wall.id = "wall";
  wall.material = "test_half";
  wall.normal = -Eigen::Vector3d::UnitX();
  wall.offset = -1.0;
  scene.obstacles.push_back(wall);
  for (int i = 0; i < links; ++i) {
    core::ObstacleSpec link;
    link.shape = core::ObstacleShape::kSphere;
    link.radius = 0.05;
    link.material = "test_half";
    link.frame = "link_" + std::to_string(10000 + i).substr(1);
    link.id = link.frame;
    scene.obstacles.push_back(link);
  }
  return scene;
}

class RobotCycle : public Cycle {
 protected:
  static constexpr int kLinks = 2000;
  RobotCycle() : Cycle(ballWallAndRobotScene(kLinks)) {}

  enum class Links { kStatic, kChain, kMissing };
  void publishLinks(Links links) {
    for (int i = 0; i < kLinks && links != Links::kMissing; ++i) {
      geometry_msgs::TransformStamped frame;
      const bool chain = links == Links::kChain && i > 0;
      frame.header.frame_id = chain ? "link_" + std::to_string(10000 + i - 1).substr(1) : "world";
      frame.child_frame_id = "link_" + std::to_string(10000 + i).substr(1);
      frame.transform.translation.x = chain ? 0.2 : 10.0 + 0.2 * (i % 50);
      frame.transform.translation.y = links == Links::kChain ? 0.0 : 0.2 * (i / 50);
      frame.transform.rotation.w = 1.0;
      tf_.setTransform(frame, "test", /*is_static=*/true);
    }
  }

  /// The ball's 1.5 s at 100 Hz; each update's obstacle work into work_.
  void playBallOnWall() {
    for (int k = 0; k <= 150; ++k) {
      const double t = 0.01 * k;
      const bool after = t > 0.9;
      const double x = after ? 0.9 - 0.5 * (t - 0.9) : t;
      send({state("a", at(clock_, t), {x, 0, 0}, {after ? -0.5 : 1.0, 0, 0})});
      work_.push_back(cycle_.obstacleWork());
    }
  }

  void expectTheBounceOnce() const {
    ASSERT_EQ(impacts_.size(), 1u);
    const Impact& impact = impacts_[0];
    EXPECT_EQ(impact.body_b, "wall");
    EXPECT_NEAR((impact.header.stamp - clock_).toSec(), 0.9, 1e-9);
    EXPECT_NEAR(impact.contact_point.x, 1.0, 1e-9);
    EXPECT_NEAR(impact.velocity_a_after.linear.x, -0.5, 1e-9);
    EXPECT_NEAR(impact.impulse, 1.5, 1e-9);
  }

  std::vector<MonitorCycle::ObstacleWork> work_;
};

TEST_F(RobotCycle, Issue41_Item3_TwoThousandStaticLinksAreLookedUpOnceAndCostNothingAfter) {
  publishLinks(Links::kStatic);
  playBallOnWall();
  expectTheBounceOnce();
  EXPECT_EQ(reportsOf(Reason::kObstacleTransform), 0u);
  // The first update looks every link up and places it; from then on a static link is where it
  // was: a few are looked up again in turn, none placed again.
  ASSERT_EQ(work_.size(), 151u);
  EXPECT_EQ(work_[0].lookups, static_cast<std::size_t>(kLinks));
  EXPECT_EQ(work_[0].placements, static_cast<std::size_t>(kLinks));
  for (std::size_t k = 1; k < work_.size(); ++k) {
    EXPECT_LE(work_[k].lookups, MonitorCycle::kStaticRechecks) << "update " << k;
    EXPECT_EQ(work_[k].placements, 0u) << "update " << k;
  }
}

// As a chain 2,000 deep, each link 0.2 m along x from its parent (link_0000 at x = 10 m): tf2
// walks at most tf2::BufferCore::MAX_GRAPH_DEPTH (1,000) frames and takes a deeper chain for a
// loop, its text listing every frame (2,000 of them, in each of the 1,000 failures of each
// lookup pass: the 1.1 GB of issue 41). The links past it are composed hop by hop
// (FrameChains), each hop once: every link is placed where its chain puts it, link_i at
// x = 10 + 0.2 i, once.
TEST_F(RobotCycle, Issue41_Item3_AChainTwoThousandDeepIsLookedUpOnceToItsEnd) {
  publishLinks(Links::kChain);
  playBallOnWall();
  expectTheBounceOnce();
  EXPECT_EQ(reportsOf(Reason::kObstacleTransform), 0u);
  EXPECT_EQ(work_[0].placements, static_cast<std::size_t>(kLinks));
  for (std::size_t k = 1; k < work_.size(); ++k) {
    EXPECT_LE(work_[k].lookups, MonitorCycle::kStaticRechecks) << "update " << k;
    EXPECT_EQ(work_[k].placements, 0u) << "update " << k;
  }
  const core::ImpactMonitor& monitor = cycle_.monitor();
  for (std::size_t o = 0; o < monitor.obstacleCount(); ++o) {
    const std::string& id = monitor.obstacle(o).id;
    if (id == "wall") continue;
    const auto pose = monitor.obstaclePose(o);
    ASSERT_TRUE(pose.has_value()) << id;
    const int i = std::stoi(id.substr(5));
    EXPECT_NEAR(pose->pose.transform.translation().x(), 10.0 + 0.2 * i, 1e-9) << id;
    EXPECT_EQ(pose->pose.velocity.norm(), 0.0) << id;
  }
}

TEST_F(RobotCycle, Issue41_Item3_TwoThousandMissingLinksAreOneReportAnUpdate) {
  publishLinks(Links::kMissing);
  playBallOnWall();
  expectTheBounceOnce();
  // Each update says once that the links keep their last known motion (never placed: counted,
  // not warned), counting every link, and looks each up once.
  std::size_t reports = 0;
  for (const Report& report : reports_) {
    if (report.reason != Reason::kObstacleTransform) continue;
    ++reports;
    EXPECT_EQ(report.count, static_cast<std::size_t>(kLinks));
    EXPECT_FALSE(report.warn);
    EXPECT_EQ(report.text.find("obstacles 'link_0000', 'link_0001', 'link_0002', 'link_0003' and "
                               "1996 more keep their last known motion; the first's: "
                               "link_0000: no transform to 'world'"),
              0u)
        << report.text;
  }
  EXPECT_EQ(reports, work_.size());
  for (std::size_t k = 0; k < work_.size(); ++k) {
    EXPECT_EQ(work_[k].lookups, static_cast<std::size_t>(kLinks)) << "update " << k;
    EXPECT_EQ(work_[k].placements, 0u) << "update " << k;
  }
}

// Moving links on /tf: `far` spheres (radius 0.05 m) at x >= 10 m moving +1 m/s along y, and a
// `paddle` sphere (radius 0.1 m) at x = 2.06 - t moving -1 m/s towards ball 'a' at x = t: they
// touch when 2.06 - 2 t = 0.2, t = 0.93 s; against the immovable paddle the ball leaves at
// v_p - e (v_a - v_p) = -1 - 0.5 (1 + 1) = -2 m/s, impulse m (1 + 2) = 3 N s.
core::Scene ballAndMovingRobotScene(int far) {
  core::Scene scene = twoBallScene();
  for (int i = 0; i <= far; ++i) {
    core::ObstacleSpec link;
    link.shape = core::ObstacleShape::kSphere;
    link.radius = i == far ? 0.1 : 0.05;
    link.material = "test_half";
    link.frame = i == far ? "paddle" : "link_" + std::to_string(10000 + i).substr(1);
    link.id = link.frame;
    scene.obstacles.push_back(link);
  }
  return scene;
}

class MovingRobotCycle : public Cycle {
 protected:
  static constexpr int kFar = 200;
  MovingRobotCycle() : Cycle(ballAndMovingRobotScene(kFar)) {
    // tf from 0.1 s before the clock (the frames' velocities look 0.02 s back) to 1.5 s after.
    for (int k = -10; k <= 150; ++k) {
      const double t = 0.01 * k;
      for (int i = 0; i <= kFar; ++i) {
        geometry_msgs::TransformStamped frame;
        frame.header.stamp = at(clock_, t);
        frame.header.frame_id = "world";
        frame.child_frame_id = i == kFar ? "paddle" : "link_" + std::to_string(10000 + i).substr(1);
        frame.transform.translation.x = i == kFar ? 2.06 - t : 10.0 + 0.2 * i;
        frame.transform.translation.y = i == kFar ? 0.0 : t;
        frame.transform.rotation.w = 1.0;
        tf_.setTransform(frame, "test", /*is_static=*/false);
      }
    }
  }
};

TEST_F(MovingRobotCycle, Issue41_Item3_FarMovingLinksArePlacedOnceAnUpdateTheNearOneEveryPeriod) {
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.01 * k;
    const bool after = t > 0.93;
    const double x = after ? 0.93 - 2.0 * (t - 0.93) : t;
    send({state("a", at(clock_, t), {x, 0, 0}, {after ? -2.0 : 1.0, 0, 0})});
    const MonitorCycle::ObstacleWork& work = cycle_.obstacleWork();
    // Every link once at the update's end; the paddle, once near the ball, at each of the
    // update's 10 periods of 1 ms.
    EXPECT_LE(work.near, 1u) << "update " << k;
    EXPECT_EQ(work.lookups, kFar + 1 + 9 * work.near) << "update " << k;
    EXPECT_EQ(work.placements, work.lookups) << "update " << k;
    if (k == 93) {
      EXPECT_EQ(work.near, 1u) << "the update of the impact";
    }
    if (k < 50) {
      EXPECT_EQ(work.near, 0u) << "update " << k << ": the paddle is 1 m away";
    }
  }
  EXPECT_EQ(reportsOf(Reason::kObstacleTransform), 0u);
  ASSERT_EQ(impacts_.size(), 1u);
  const Impact& impact = impacts_[0];
  EXPECT_EQ(impact.body_b, "paddle");
  EXPECT_NEAR((impact.header.stamp - clock_).toSec(), 0.93, 1e-9);
  EXPECT_NEAR(impact.velocity_a_after.linear.x, -2.0, 1e-9);
  EXPECT_NEAR(impact.impulse, 3.0, 1e-9);
}

// Two spheres (radius 0.1 m) on frames near ball 'a' at rest at the origin, and an update 1 s
// long (the ball's states 1 s apart): the spheres pass it at y = +-0.25 m moving +0.1 m/s along
// x (never touching: 0.25 > 0.2), so both may reach it. 1,000 periods of 1 ms, two obstacles to
// place again at each of the 999 within: 1,998 placements; the bound allows 1,000, so 500
// instants 1/501 s apart (1,000 placements, and 2 at the end), and counts the 998 left out.
core::Scene ballBetweenTwoMovingSpheresScene() {
  core::Scene scene = twoBallScene();
  for (const char* id : {"left", "right"}) {
    core::ObstacleSpec sphere;
    sphere.shape = core::ObstacleShape::kSphere;
    sphere.radius = 0.1;
    sphere.material = "test_half";
    sphere.frame = id;
    sphere.id = id;
    scene.obstacles.push_back(sphere);
  }
  return scene;
}

class LateUpdateCycle : public Cycle {
 protected:
  LateUpdateCycle() : Cycle(ballBetweenTwoMovingSpheresScene()) {}
};

TEST_F(LateUpdateCycle, Issue41_Item3_ALateUpdatesPlacementsAreBoundedAndWhatIsLeftOutCounted) {
  for (int k = -10; k <= 110; ++k) {
    for (const char* id : {"left", "right"}) {
      geometry_msgs::TransformStamped frame;
      frame.header.stamp = at(clock_, 0.01 * k);
      frame.header.frame_id = "world";
      frame.child_frame_id = id;
      frame.transform.translation.x = 0.001 * k;
      frame.transform.translation.y = id[0] == 'l' ? 0.25 : -0.25;
      frame.transform.rotation.w = 1.0;
      tf_.setTransform(frame, "test", /*is_static=*/false);
    }
  }
  send({state("a", clock_, {0, 0, 0}, {0, 0, 0})});
  send({state("a", at(clock_, 1.0), {0, 0, 0}, {0, 0, 0})});
  const MonitorCycle::ObstacleWork& work = cycle_.obstacleWork();
  EXPECT_EQ(work.near, 2u);
  EXPECT_EQ(work.placements, 2u + 2u * 500u);
  EXPECT_LE(work.placements, MonitorCycle::kMaxPlacements + 2u);
  EXPECT_EQ(reportsOf(Reason::kObstaclePlacementsLeftOut), 998u);
  const Report* report = firstReport(Reason::kObstaclePlacementsLeftOut);
  ASSERT_NE(report, nullptr);
  EXPECT_EQ(
      report->text.find("placed the 2 tf-attached obstacle(s) that may reach a body "
                        "('left', 'right') every 0.001996007984031936 s over this update's 1 s "
                        "instead of "
                        "every ~obstacle_update_period (0.001 s): at most 1000 placements "
                        "an update; 998 left out"),
      0u)
      << report->text;
  EXPECT_TRUE(impacts_.empty());
}

// Issue 41, item 8: a frame that jumps. Sphere 'paddle' (radius 0.1 m) on frame "paddle", whose
// tf samples (every 10 ms) put it at x = 2 m until t = 0.49 s and at x = 5 m from t = 0.5 s:
// tf interpolates the 3 m over 10 ms, so its backward difference of second order (frame_motion.h)
// at t = 0.5 s is 300 + (300 - 0) / 2 = 450 m/s and at t = 0.51 s 0 + (0 - 300) / 2 = -150 m/s,
// both above MonitorCycle::kMaxFrameSpeed (100 m/s); from t = 0.52 s it is 0 again. Ball 'a'
// rests at the origin, its states every 10 ms.
TEST_F(MovingRobotCycle, Issue41_Item8_AFrameThatJumpsKeepsItsLastGoodMotionAndIsNamed) {
  tf2::BufferCore tf;
  for (int k = -10; k <= 100; ++k) {
    geometry_msgs::TransformStamped frame;
    frame.header.stamp = at(clock_, 0.01 * k);
    frame.header.frame_id = "world";
    frame.child_frame_id = "paddle";
    frame.transform.translation.x = k < 50 ? 2.0 : 5.0;
    frame.transform.rotation.w = 1.0;
    tf.setTransform(frame, "test", /*is_static=*/false);
  }
  core::Scene scene = twoBallScene();
  scene.obstacles.push_back(ballAndMovingRobotScene(0).obstacles[0]);  // 'paddle'
  MonitorCycle cycle(scene, MonitorParams{});
  std::deque<std::vector<BodyState>> inputs;
  for (int k = 0; k <= 60; ++k) {
    inputs.push_back({state("a", at(clock_, 0.01 * k), {0, 0, 0}, {0, 0, 0})});
    const MonitorCycle::Update update =
        cycle.process({&inputs.back(), "/body_states", "/source", ""}, clock_, false, tf);
    const auto pose = cycle.monitor().obstaclePose(0);
    ASSERT_TRUE(pose.has_value());
    // Never faster than a body could follow; where it was until its frame moves slower again.
    EXPECT_LE(pose->pose.velocity.norm(), MonitorCycle::kMaxFrameSpeed) << "update " << k;
    EXPECT_EQ(pose->pose.velocity.norm(), 0.0) << "update " << k;
    EXPECT_EQ(pose->pose.transform.translation().x(), k < 52 ? 2.0 : 5.0) << "update " << k;
    std::size_t jumped = 0;
    for (const Report& report : update.reports) {
      if (report.reason != Reason::kFrameJumped) continue;
      ++jumped;
      EXPECT_TRUE(report.warn);
      const std::string speed = k == 50 ? "450" : "150";
      EXPECT_EQ(
          report.text.find("obstacle 'paddle' keeps its last known motion: paddle: moves at " +
                           speed + " m/s at "),
          0u)
          << report.text;
      EXPECT_NE(report.text.find("faster than 100 m/s: a jump between its tf samples, which no "
                                 "body could follow"),
                std::string::npos)
          << report.text;
    }
    EXPECT_EQ(jumped, k == 50 || k == 51 ? 1u : 0u) << "update " << k;
    EXPECT_TRUE(update.impacts.impacts.empty());
  }
}

// Issue 41, item 4: a touching 6 x 6 x 6 lattice of balls with friction and spin closing on its
// centre in one message: its joint solves would spend about 490,000 contact iterations in one
// update (0.5 s); past the monitor's impact work bound (100,000) its impacts are cut short, and
// the cycle says so: counted with the bodies' number, warned naming the first of them.
core::Scene closingLatticeScene() {
  core::Scene scene;
  scene.effects.friction = true;
  scene.effects.spin = true;
  scene.materials.addMaterial("clay", core::Material{0.5, 0.3}, "materials");
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      for (int k = 0; k < 6; ++k) {
        core::BodySpec body;
        body.id = "ball_" + std::to_string(i) + std::to_string(j) + std::to_string(k);
        body.mass = 0.1;
        body.radius = 0.05;
        body.material = "clay";
        body.position = Eigen::Vector3d(0.1 * i, 0.1 * j, 0.1 * k);
        scene.bodies.push_back(body);
      }
    }
  }
  core::BodySpec clock;  // far from the lattice: the later messages' only state
  clock.id = "clock";
  clock.mass = 0.1;
  clock.radius = 0.05;
  clock.material = "clay";
  clock.position = Eigen::Vector3d(10, 0, 0);
  scene.bodies.push_back(clock);
  return scene;
}

class ClosingLatticeCycle : public Cycle {
 protected:
  ClosingLatticeCycle() : Cycle(closingLatticeScene()) {}
};

TEST_F(ClosingLatticeCycle, AnImpactPastTheImpactWorkBoundIsNamedAndCounted) {
  const ros::Time start(1000, 0);
  std::vector<BodyState> first;
  const Eigen::Vector3d centre = Eigen::Vector3d::Constant(0.25);
  std::mt19937_64 engine(3);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (const core::BodySpec& body : cycle_.scene().bodies) {
    const bool ball = body.id != "clock";
    const Eigen::Vector3d offset = body.position - centre;
    BodyState s = state(body.id, start, body.position,
                        ball ? Eigen::Vector3d(-offset + Eigen::Vector3d::UnitZ().cross(offset))
                             : Eigen::Vector3d::Zero());
    if (ball) {  // each spinning at up to 10 rad/s about an axis of its own (seeded)
      s.twist.angular.x = 10 * unit(engine);
      s.twist.angular.y = 10 * unit(engine);
      s.twist.angular.z = 10 * unit(engine);
    }
    first.push_back(s);
  }
  send(first);
  const MonitorCycle::Update update =
      send({state("clock", at(start, 0.01), {10, 0, 0}, {0, 0, 0})});
  EXPECT_FALSE(update.impacts.impacts.empty());
  EXPECT_EQ(reportsOf(Reason::kOverImpactWork), 216u) << "every ball of the lattice, not the clock";
  ASSERT_NE(firstReport(Reason::kOverImpactWork), nullptr);
  const Report& report = *firstReport(Reason::kOverImpactWork);
  EXPECT_EQ(report.text.find("the impacts of 'ball_000', 'ball_001'"), 0u) << report.text;
  EXPECT_NE(report.text.find("and 208 more at one instant ran over the update's impact work "
                             "(100000 contact iterations)"),
            std::string::npos)
      << report.text;
  EXPECT_FALSE(isDrop(Reason::kOverImpactWork));
  EXPECT_STREQ(counterName(Reason::kOverImpactWork),
               "bodies of impacts over the impact work bound");
}

// Issue 41: bodies of stepped clusters held past an update's stepped work are counted on their
// own line of /diagnostics, not as lost states and not as a wedge's hold (the core's test
// SteppedClusters.PastTheStepsSteppedWorkItsBodiesAreHeldNeverInsideAnything holds the bound).
TEST(OverSteppedWork, IsCountedOnItsOwnLineNotAsALoss) {
  EXPECT_FALSE(isDrop(Reason::kOverSteppedWork));
  EXPECT_STREQ(counterName(Reason::kOverSteppedWork), "bodies held over the stepped work bound");
  EXPECT_STRNE(counterName(Reason::kOverSteppedWork), counterName(Reason::kSteppedHeld));
}

// A loop in tf (a's parent b, b's parent a, both static) is no chain to a root: FrameChains says
// so at once. It walked a million hops an update, each under tf's lock, and then took the loop
// for a static root.
TEST(FrameChainsLoop, ALoopIsNeitherRootedNorStatic) {
  tf2::BufferCore tf;
  geometry_msgs::TransformStamped hop;
  hop.transform.rotation.w = 1.0;
  hop.header.frame_id = "world";
  hop.child_frame_id = "base";
  ASSERT_TRUE(tf.setTransform(hop, "test", /*is_static=*/true));
  hop.header.frame_id = "b";
  hop.child_frame_id = "a";
  ASSERT_TRUE(tf.setTransform(hop, "test", /*is_static=*/true));
  hop.header.frame_id = "a";
  hop.child_frame_id = "b";
  tf.setTransform(hop, "test", /*is_static=*/true);
  FrameChains chains(tf, "world");
  EXPECT_FALSE(chains.wholeStatic("a"));
  EXPECT_FALSE(static_cast<bool>(chains.motion("a", ros::Time(100), ros::Duration(0.01))));
  EXPECT_TRUE(chains.wholeStatic("base"));
}
}  // namespace
}  // namespace collision_response
