// The attacks of issue 13 over real topics, services and parameters, beside the catalogue of
// rejected input (test_rejected_input.cpp): each a named test with the attack's numbers, each
// failing on the node as it was before the fix. After each, the node is still right: the
// two-ball closed form of test_monitor_frames.cpp (1 kg, radius 0.1 m, e = 0.5; contact 0.43 s
// after the first state; v_a' = -0.5, v_b' = +0.5).
#include <XmlRpcClient.h>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <ros/master.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "collision_response/ContactArray.h"
#include "collision_response/EstimateRestitution.h"
#include "monitor_harness.h"

namespace collision_response::testing {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The node's process id, from its own XML-RPC API (getPid).
int pidOf(const std::string& node) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, result, payload, true)) return 0;
  const std::string uri = payload;
  const std::size_t host_start = uri.find("//") + 2;
  const std::size_t port_start = uri.find(':', host_start);
  const std::string host = uri.substr(host_start, port_start - host_start);
  const int port = std::stoi(uri.substr(port_start + 1));
  XmlRpc::XmlRpcClient client(host.c_str(), port, "/");
  XmlRpc::XmlRpcValue request, response;
  request[0] = ros::this_node::getName();
  if (!client.execute("getPid", request, response) || response.size() < 3) return 0;
  return static_cast<int>(response[2]);
}

/// The process's peak resident memory (VmHWM), MB.
double peakMegabytes(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return -1.0;
}

class HostileInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { base_ = baseStamp(); }
  void SetUp() override {
    ASSERT_TRUE(harness_.connect());
    ros::WallDuration(0.3).sleep();  // let the new connections settle before the first message
  }

  /// Each test its own 10 s window of stamps.
  static ros::Time window() {
    static int next = 0;
    return base_ + ros::Duration(10.0 * next++);
  }

  /// The two-ball case at 10 Hz from `start`; `extra(k)` is published beside state k.
  void playTwoBalls(const ros::Time& start, const std::string& a = "a", const std::string& b = "b",
                    const std::function<void(int)>& extra = nullptr) {
    for (int k = 0; k <= 10; ++k) {
      const double t = 0.1 * k;
      harness_.publish(start + ros::Duration(0, 100000000 * k),
                       {StateSpec{a, Eigen::Vector3d(t, 0, 0), Eigen::Vector3d(1, 0, 0)},
                        StateSpec{b, Eigen::Vector3d(1.06 - t, 0, 0), Eigen::Vector3d(-1, 0, 0)}});
      if (extra) extra(k);
      ros::WallDuration(0.01).sleep();
    }
  }

  /// The impacts of `a` since `before` impacts had been received: exactly one, the closed form.
  void expectTwoBallImpact(const std::string& a, const ros::Time& start, std::size_t before = 0,
                           double instant_tolerance = 1e-9) {
    ASSERT_TRUE(MonitorHarness::waitFor(
        [&] {
          std::size_t found = 0;
          for (std::size_t i = before; i < harness_.impacts().size(); ++i) {
            found += harness_.impacts()[i].body_a == a ? 1 : 0;
          }
          return found > 0;
        },
        10.0))
        << "no impact of " << a;
    ros::WallDuration(0.3).sleep();
    ros::spinOnce();
    std::vector<Impact> impacts;
    for (std::size_t i = before; i < harness_.impacts().size(); ++i) {
      if (harness_.impacts()[i].body_a == a) impacts.push_back(harness_.impacts()[i]);
    }
    ASSERT_EQ(impacts.size(), 1u);
    EXPECT_NEAR((impacts[0].header.stamp - start).toSec(), 0.43, instant_tolerance);
    EXPECT_NEAR(impacts[0].velocity_a_after.linear.x, -0.5, 1e-9);
    EXPECT_NEAR(impacts[0].velocity_b_after.linear.x, 0.5, 1e-9);
  }

  /// Every impact received so far has only finite numbers.
  void expectOnlyFiniteImpacts() {
    for (const Impact& impact : harness_.impacts()) {
      for (const double value :
           {impact.impulse, impact.energy_lost, impact.friction_impulse, impact.restitution,
            impact.contact_point.x, impact.normal.x, impact.velocity_a_after.linear.x,
            impact.velocity_a_after.linear.y, impact.velocity_b_after.linear.x,
            impact.velocity_a_before.linear.x}) {
        EXPECT_TRUE(std::isfinite(value)) << "a non-finite number on /impacts: " << impact;
      }
    }
  }

  MonitorHarness harness_;
  static ros::Time base_;
};
ros::Time HostileInput::base_;

// Item 1: if the first state the monitor ever saw was stamped secs 4294967295, every later valid
// message was dropped with "Duration is out of dual 32-bit range", forever. This is the first
// state this node sees.
TEST_F(HostileInput, Item1_AFirstStampAtTheEndOfTimeIsDroppedByNameAndTheMonitorLivesOn) {
  BodyStateArray array;
  array.states.push_back(makeState(
      ros::Time(4294967295u, 0), StateSpec{"a", Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}));
  harness_.publishRaw(array);
  EXPECT_TRUE(harness_.waitForWarning({"'a'", "header.stamp: 4294967295.000000000", "ahead"}));
  const ros::Time start = window();
  playTwoBalls(start);
  expectTwoBallImpact("a", start);
}

// Item 1, mid-stream: the same stamp was dropped without naming header.stamp.
TEST_F(HostileInput, Item1_AStampAtTheEndOfTimeMidStreamIsNamed) {
  ros::WallDuration(1.1).sleep();  // warnings of one reason are throttled to one a second
  const std::size_t logs = harness_.logCount();
  const std::size_t before = harness_.impactCount();
  const ros::Time start = window();
  playTwoBalls(start, "a", "b", [this](int k) {
    if (k != 2) return;
    BodyStateArray array;
    array.states.push_back(
        makeState(ros::Time(4294967295u, 999999999),
                  StateSpec{"b", Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}));
    harness_.publishRaw(array);
  });
  EXPECT_TRUE(harness_.waitForWarning({"'b'", "header.stamp: 4294967295.999999999"}));
  expectTwoBallImpact("a", start, before);
  EXPECT_EQ(harness_.countWarnings({"jumped back"}, logs), 0u) << "one bad stamp resets nothing";
}

// Item 2: bodies of 1e200 kg meeting at 1e110 m/s published `impulse: inf`, `energy_lost: nan`.
// The impact is refused by name, counted in diagnostics, and nothing non-finite is published.
TEST_F(HostileInput, Item2_AnImpactBeyondTheDoublesIsNotPublished) {
  ros::Subscriber diagnostics;
  std::string dropped_total;
  diagnostics = harness_.node().subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10,
      [&dropped_total](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
        for (const auto& status : array->status) {
          for (const auto& pair : status.values) {
            if (pair.key == "impacts dropped: not finite (total)") dropped_total = pair.value;
          }
        }
      });
  // One state of each body, then a state of another body to make the monitor step: the
  // impact falls in that step.
  const ros::Time start = window();
  const auto step_at = [this](const ros::Time& stamp) {
    harness_.publish(stamp, {StateSpec{"b", Eigen::Vector3d(5, 0, 0), Eigen::Vector3d::Zero()}});
  };
  harness_.publish(
      start, {StateSpec{"heavy_a", Eigen::Vector3d(0, 10, 0), Eigen::Vector3d(1e110, 0, 0)},
              StateSpec{"heavy_b", Eigen::Vector3d(1.06, 10, 0), Eigen::Vector3d(-1e110, 0, 0)}});
  step_at(start + ros::Duration(0.1));
  EXPECT_TRUE(harness_.waitForWarning(
      {"did not publish the impact of 'heavy_a' and 'heavy_b'", "is beyond the range of double"}));
  ros::WallDuration(1.1).sleep();  // warnings of one reason are throttled to one a second
  // Touching balls at the top of the doubles: a's normal speed 1.3e308 (0.6 + 0.8) overflows.
  const Eigen::Vector3d fast(1.3e308, 1.3e308, 0);
  harness_.publish(start + ros::Duration(1.0),
                   {StateSpec{"fast_a", Eigen::Vector3d(0, 20, 0), fast},
                    StateSpec{"fast_b", Eigen::Vector3d(0.12, 20.16, 0), Eigen::Vector3d::Zero()}});
  step_at(start + ros::Duration(1.1));
  EXPECT_TRUE(harness_.waitForWarning({"did not publish the impact of 'fast_a' and 'fast_b'"}));
  // An ordinary impact after them: anything published before it has arrived by then.
  const std::size_t before = harness_.impactCount();
  const ros::Time later = start + ros::Duration(3.0);
  playTwoBalls(later);
  expectTwoBallImpact("a", later, before);
  expectOnlyFiniteImpacts();
  EXPECT_TRUE(harness_.impactsOf("heavy_a").empty());
  EXPECT_TRUE(harness_.impactsOf("fast_a").empty());
  ASSERT_TRUE(MonitorHarness::waitFor([&] { return !dropped_total.empty(); }, 5.0));
  EXPECT_GE(std::stoi(dropped_total), 2);
}

// Item 3: a finite state far away and fast (p = (5, -1.76e13, 5), v = (1.05e8, 7.04e13, 0), the
// next input 0.5 s later) had the grid walk and store cells until memory ran out (1-2 GB).
TEST_F(HostileInput, Item3_AFarFastStateCostsNeitherMemoryNorTime) {
  const int pid = pidOf("/collision_response");
  ASSERT_GT(pid, 0);
  const ros::Time start = window();
  const Eigen::Vector3d position(5, -1.76e13, 5), velocity(1.05e8, 7.04e13, 0);
  harness_.publish(start, {StateSpec{"far", position, velocity},
                           StateSpec{"a", Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::Zero()},
                           StateSpec{"b", Eigen::Vector3d(3, 0, 0), Eigen::Vector3d::Zero()}});
  harness_.publish(start + ros::Duration(0.5),
                   {StateSpec{"far", position + 0.5 * velocity, velocity},
                    StateSpec{"a", Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::Zero()},
                    StateSpec{"b", Eigen::Vector3d(3, 0, 0), Eigen::Vector3d::Zero()}});
  const std::size_t before = harness_.impactCount();
  const ros::Time later = start + ros::Duration(2.0);
  playTwoBalls(later);
  expectTwoBallImpact("a", later, before);
  EXPECT_LT(peakMegabytes(pid), 400.0) << "the node's peak resident memory";
}

// Item 4: 1,000 distinct unknown ids a message at 10 Hz gave 300,000 warnings in 30 s and a
// throttle map that grew for ever; the same with distinct unknown frames. One warning a second
// a reason now, whatever the ids or frames.
TEST_F(HostileInput, Item4_FloodsOfDistinctIdsAndFramesAreThrottledByReason) {
  const std::size_t logs = harness_.logCount();
  const ros::Time start = window();
  const ros::WallTime began = ros::WallTime::now();
  for (int k = 0; k < 20; ++k) {
    BodyStateArray ghosts, frames;
    for (int i = 0; i < 1000; ++i) {
      const ros::Time stamp = start + ros::Duration(0.1 * k);
      ghosts.states.push_back(
          makeState(stamp, StateSpec{"ghost_" + std::to_string(k) + "_" + std::to_string(i),
                                     Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}));
      frames.states.push_back(
          makeState(stamp + ros::Duration(0, static_cast<std::int32_t>(i)),
                    StateSpec{"framed", Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                              "nowhere_" + std::to_string(k) + "_" + std::to_string(i)}));
    }
    harness_.publishRaw(ghosts);
    harness_.publishRaw(frames);
    ros::WallDuration(0.1).sleep();
    ros::spinOnce();
  }
  EXPECT_TRUE(harness_.waitForWarning({"unknown body 'ghost_"}));
  EXPECT_TRUE(harness_.waitForWarning({"'framed'", "header.frame_id: nowhere_"}));
  ros::WallDuration(0.5).sleep();
  ros::spinOnce();
  const double seconds = (ros::WallTime::now() - began).toSec();
  const std::size_t unknown = harness_.countWarnings({"unknown body"}, logs);
  const std::size_t frames = harness_.countWarnings({"header.frame_id: nowhere_"}, logs);
  // One a second for each, and the first: 20,000 of each were sent.
  EXPECT_GE(unknown, 1u);
  EXPECT_LE(static_cast<double>(unknown), seconds + 1.0) << unknown << " in " << seconds << " s";
  EXPECT_LE(static_cast<double>(frames), seconds + 1.0) << frames << " in " << seconds << " s";
  EXPECT_GE(harness_.countWarnings({"more in this message"}, logs), 1u)
      << "a warning says how many it stands for";
}

// Item 5: two sources whose clocks differ by 5 s gave a "time jumped back" warning per message
// and reset every track each time: no impact was ever found. The lagging source is shifted onto
// the time line, said once; the impact is found (its instant as good as the alignment: one
// message period).
TEST_F(HostileInput, Item5_TwoSourcesWhoseClocksDifferBy5s) {
  ros::Publisher own = harness_.node().advertise<BodyState>("/clock_b/state", 100);
  ASSERT_TRUE(MonitorHarness::waitFor([&own] { return own.getNumSubscribers() > 0; }, 10.0));
  ros::WallDuration(0.5).sleep();
  const std::size_t logs = harness_.logCount();
  const std::size_t before = harness_.impactCount();
  const ros::Time start = window();
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.1 * k;
    const ros::Time stamp = start + ros::Duration(0, 100000000 * k);
    harness_.publish(stamp,
                     {StateSpec{"clock_a", Eigen::Vector3d(t, 30, 0), Eigen::Vector3d(1, 0, 0)}});
    ros::WallDuration(0.02).sleep();
    own.publish(
        makeState(stamp - ros::Duration(5.0),
                  StateSpec{"", Eigen::Vector3d(1.06 - t, 30, 0), Eigen::Vector3d(-1, 0, 0)}));
    ros::WallDuration(0.02).sleep();
  }
  expectTwoBallImpact("clock_a", start, before, 0.1 + 1e-9);
  EXPECT_EQ(harness_.countWarnings({"jumped back"}, logs), 0u);
  // The line keeps this node's clock, and this file's windows of stamps run ahead of it: the
  // lagging source may read behind or ahead of the line (the unit test has the clocks of a
  // real pair of machines and reads "5 s behind"). Said once either way.
  EXPECT_EQ(harness_.countWarnings({"/clock_b/state", "s behind the time line"}, logs) +
                harness_.countWarnings({"/clock_b/state", "s ahead of the time line"}, logs),
            1u)
      << "said once";
}

// Item 7: the same id twice in one array was dropped as "not newer", without naming the id or
// the duplicate.
TEST_F(HostileInput, Item7_TheSameIdTwiceInOneArrayIsNamed) {
  const ros::Time start = window();
  BodyStateArray array;
  array.states.push_back(
      makeState(start, StateSpec{"twice", Eigen::Vector3d(0, 40, 0), Eigen::Vector3d::Zero()}));
  array.states.push_back(
      makeState(start, StateSpec{"a", Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::Zero()}));
  array.states.push_back(
      makeState(start, StateSpec{"twice", Eigen::Vector3d(0, 41, 0), Eigen::Vector3d::Zero()}));
  harness_.publishRaw(array);
  EXPECT_TRUE(harness_.waitForWarning({"states[2] ('twice')", "is also states[0]"}));
}

// Item 7: a plane normal of length 1e-200 (documented "any length") was accepted and the plane
// was never hit (normalising underflowed). The floor of this scene has that normal.
TEST_F(HostileInput, Item7_APlaneWhoseNormalIs1e200ShortIsHit) {
  // 0.5 m above the floor at z = -100, falling at 2 m/s: the surface meets it after 0.2335 s.
  const ros::Time start = window();
  for (int k = 0; k <= 4; ++k) {
    const double t = 0.1 * k;
    harness_.publish(
        start + ros::Duration(0, 100000000 * k),
        {StateSpec{"dropped", Eigen::Vector3d(0, 50, -99.5 - 2 * t), Eigen::Vector3d(0, 0, -2)}});
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_TRUE(harness_.waitForImpact("dropped"));
  const Impact impact = harness_.impactsOf("dropped").at(0);
  EXPECT_EQ(impact.body_b, "floor");
  EXPECT_NEAR((impact.header.stamp - start).toSec(), 0.2335, 1e-9);
  EXPECT_NEAR(impact.normal.z, -1.0, 1e-12);
  EXPECT_NEAR(impact.velocity_a_after.linear.z, 0.712 * 2, 1e-9);
}

dynamic_reconfigure::Config reconfigure(const std::string& node, double threshold,
                                        const std::string& detection = "") {
  dynamic_reconfigure::Reconfigure call;
  dynamic_reconfigure::DoubleParameter parameter;
  parameter.name = "restitution_threshold";
  parameter.value = threshold;
  if (!std::isnan(threshold)) call.request.config.doubles.push_back(parameter);
  if (!detection.empty()) {
    dynamic_reconfigure::StrParameter text;
    text.name = "detection";
    text.value = detection;
    call.request.config.strs.push_back(text);
  }
  EXPECT_TRUE(ros::service::waitForService(node + "/set_parameters", 20000));
  EXPECT_TRUE(ros::service::call(node + "/set_parameters", call));
  return call.response.config;
}

double thresholdOf(const dynamic_reconfigure::Config& config) {
  for (const auto& parameter : config.doubles) {
    if (parameter.name == "restitution_threshold") return parameter.value;
  }
  return NAN;
}

// Item 8: dynamic_reconfigure clamped restitution_threshold to 1000 before the node's check:
// .inf and 1e6 became 1000 silently, -inf was reported as "got -1000", and a scene's 5000
// became 1000 on an unrelated change of detection. The node's own check speaks now.
TEST_F(HostileInput, Item8_LiveTuningIsCheckedByTheNodeNotClamped) {
  const std::size_t logs = harness_.logCount();
  EXPECT_EQ(thresholdOf(reconfigure("/collision_response", kInf)), 0.0);
  EXPECT_TRUE(harness_.waitForWarning(
      {"restitution_threshold: must be a finite number >= 0 m/s, got inf"}));
  EXPECT_EQ(thresholdOf(reconfigure("/collision_response", -kInf)), 0.0);
  EXPECT_TRUE(harness_.waitForWarning({"got -inf"}));
  EXPECT_EQ(thresholdOf(reconfigure("/collision_response", 1e6)), 1e6) << "a valid value stays";
  EXPECT_EQ(thresholdOf(reconfigure("/collision_response", 0.0)), 0.0);
  EXPECT_EQ(harness_.countWarnings({"-1000"}, logs), 0u);
  // The scene's 5000, kept through a change of detection.
  EXPECT_EQ(thresholdOf(reconfigure("/tuning", NAN, "discrete")), 5000.0);
}

// Item 10 is in the catalogue (test_rejected_input.cpp); its service is this node's too.
TEST_F(HostileInput, Item10_DropHeightsAtTheEndsOfTheDoubles) {
  EstimateRestitution srv;
  srv.request.drop_height = 1e300;
  srv.request.bounce_height = 1e-300;
  ASSERT_TRUE(ros::service::call("/collision_response/estimate_restitution", srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_NEAR(srv.response.restitution, 1e-300, 1e-315);
  srv.request.drop_height = 1.0;
  srv.request.bounce_height = -0.0;
  ASSERT_TRUE(ros::service::call("/collision_response/estimate_restitution", srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.restitution, 0.0);
  EXPECT_FALSE(std::signbit(srv.response.restitution));
}

// Issue 27, item 3: a second source sent one state stamped now + 299 s (inside
// ~future_stamp_tolerance): the tracker's states were then shifted onto the line by about
// 299 s, and every impact afterwards was stamped as much late. Here the second source is this
// node's publisher on /clock_b/state (another topic: another source) and its state is of a body
// out of the pair's way. Expected: that source gets a clock of its own, said naming it and
// header.stamp; the tracker's impact is found once, with the closed form, stamped in the
// tracker's clock: start + 0.43 s (within 1 ms); nothing is reset.
TEST_F(HostileInput, Issue27_Item3_OneStateFromASecondPublisher299sAheadShiftsNoImpact) {
  ros::Publisher own = harness_.node().advertise<BodyState>("/clock_b/state", 100);
  ASSERT_TRUE(MonitorHarness::waitFor([&own] { return own.getNumSubscribers() > 0; }, 10.0));
  ros::WallDuration(0.5).sleep();
  const std::size_t logs = harness_.logCount();
  const std::size_t before = harness_.impactCount();
  own.publish(makeState(ros::Time::now() + ros::Duration(299.0),
                        StateSpec{"", Eigen::Vector3d(0, 60, 0), Eigen::Vector3d::Zero()}));
  EXPECT_TRUE(MonitorHarness::waitFor(
      [&] {
        return harness_.countWarnings({"/clock_b/state", "header.stamp", "ahead of the time line"},
                                      logs) > 0;
      },
      5.0))
      << "the odd source is named";
  const ros::Time start = window();
  playTwoBalls(start);
  expectTwoBallImpact("a", start, before, 1e-3);
  EXPECT_EQ(harness_.countWarnings({"jumped back"}, logs), 0u);
}

// Issue 27, item 3: one publisher interleaving two clocks reset every track on every message,
// and the pair's impact was never found. Here this node's /body_states publisher sends a's
// states on its clock and, 0.05 s after each, b's on a clock 299 s behind it. Expected: no
// reset; b's clock is placed on the line on its own (said, naming the source and
// header.stamp); the impact once, with the closed form, stamped in a's clock: start + 0.43 s,
// within 0.05 s (half the period between the two clocks' messages: b's clock is aligned by
// the node's clock at its messages' arrival).
TEST_F(HostileInput, Issue27_Item3_OnePublisherInterleavingTwoClocks) {
  // The warning is said once, and warnings are throttled per topic and reason (1 s): one of an
  // earlier test's on /body_states within the second would hold it back (twice, on a loaded
  // fresh machine, it never came). A throttle period first.
  ros::WallDuration(1.1).sleep();
  const std::size_t logs = harness_.logCount();
  const std::size_t before = harness_.impactCount();
  const ros::Time start = window();
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.1 * k;
    harness_.publish(start + ros::Duration(t),
                     {StateSpec{"a", Eigen::Vector3d(t, 0, 0), Eigen::Vector3d(1, 0, 0)}});
    ros::WallDuration(0.05).sleep();
    harness_.publish(
        start + ros::Duration(t + 0.05 - 299.0),
        {StateSpec{"b", Eigen::Vector3d(1.06 - (t + 0.05), 0, 0), Eigen::Vector3d(-1, 0, 0)}});
    ros::WallDuration(0.05).sleep();
  }
  expectTwoBallImpact("a", start, before, 0.05);
  EXPECT_EQ(harness_.countWarnings({"jumped back"}, logs), 0u);
  // Said on /rosout, which may arrive after the impact (a fresh machine's full suite, its
  // second lane compiling beside it, once counted none at this point): waited for.
  EXPECT_TRUE(MonitorHarness::waitFor(
      [&] {
        return harness_.countWarnings({"/body_states from", "header.stamp", "clock"}, logs) > 0;
      },
      5.0));
}

/// The messages on /diagnostics of `node` (its status named "<node>: impact monitor") while
/// `during` runs and `seconds` after.
std::vector<diagnostic_msgs::DiagnosticStatus> diagnosticsOf(const std::string& node,
                                                             const std::function<void()>& during,
                                                             double seconds) {
  std::vector<diagnostic_msgs::DiagnosticStatus> received;
  ros::NodeHandle handle;
  const std::string name = node.substr(1) + ": impact monitor";
  ros::Subscriber subscriber = handle.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
        for (const auto& status : array->status) {
          if (status.name == name) received.push_back(status);
        }
      });
  MonitorHarness::waitFor([&] { return subscriber.getNumPublishers() > 0; }, 10.0);
  if (during) during();
  MonitorHarness::waitFor([] { return false; }, seconds);
  return received;
}

// Issue 27, item 4: `rosparam set ~diagnostic_period 1e10` while the node ran aborted it
// (diagnostic_updater re-read the value and ros::Duration(1e10) threw from its timer: SIGABRT
// within 3 s, the services gone). The re-read is checked as at start-up: the value is refused
// with a warning naming the key, the period in use (0.2 s, from the launch file) is kept, and
// the node keeps answering, publishing diagnostics and finding impacts.
TEST_F(HostileInput, Issue27_Item4_ADiagnosticPeriodNoRosDurationHoldsSetWhileRunningIsRefused) {
  const std::string key = "/collision_response/diagnostic_period";
  const auto diagnostics = diagnosticsOf(
      "/collision_response", [&] { ros::param::set(key, 1e10); }, 4.0);
  EXPECT_TRUE(harness_.waitForWarning(
      {key + ": 1e+10 s is longer than a ros::Duration can hold (2147483647 s)", "kept 0.2 s"}));
  // Still published every 0.2 s: over the 4 s after the set, about 20 (at least 10).
  EXPECT_GE(diagnostics.size(), 10u);
  EstimateRestitution srv;
  srv.request.drop_height = 1.0;
  srv.request.bounce_height = 0.25;  // e = sqrt(0.25 / 1) = 0.5
  ASSERT_TRUE(ros::service::call("/collision_response/estimate_restitution", srv))
      << "the node's services are gone";
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.restitution, 0.5);
  // A good value is taken again, and the node is still right.
  ros::param::set(key, 0.2);
  const ros::Time start = window();
  playTwoBalls(start);
  expectTwoBallImpact("a", start);
}

// Issue 27, item 5: the lasting-contact stack (config/scenes/stack.yaml: three 0.2 kg balls of
// radius 0.05 m on the floor) placed at x = 1.7e308 gave one empty `contacts` array and no word:
// past 2^1023 the monitor's sums of two bodies' coordinates overflow, and the stack fell through
// its floor. Each state is now dropped at intake with a warning naming the body and the field,
// shown in /diagnostics, and nothing is published as a contact; the same stack at x = 0 still
// rests, each contact carrying the weight above it (2 m g, 3 m g, m g in the order of pairs).
TEST_F(HostileInput, Issue27_Item5_AStackPlacedAtXOf1point7e308IsRefusedByName) {
  ASSERT_TRUE(harness_.connect(20.0, "/far/stack"));
  ros::NodeHandle handle;
  ros::Publisher states = handle.advertise<BodyStateArray>("/far/body_states", 10);
  std::vector<ContactArray> contacts;
  ros::Subscriber subscriber = handle.subscribe<ContactArray>(
      "/far/contacts", 100,
      [&contacts](const ContactArray::ConstPtr& array) { contacts.push_back(*array); });
  ASSERT_TRUE(MonitorHarness::waitFor(
      [&] { return states.getNumSubscribers() > 0 && subscriber.getNumPublishers() > 0; }, 20.0));
  const auto stack = [&](const ros::Time& stamp, double x) {
    BodyStateArray array;
    array.header.stamp = stamp;
    const char* ids[] = {"bottom", "middle", "top"};
    for (int i = 0; i < 3; ++i) {
      array.states.push_back(makeState(
          stamp,
          StateSpec{ids[i], Eigen::Vector3d(x, 0, 0.05 + 0.1 * i), Eigen::Vector3d::Zero()}));
    }
    states.publish(array);
  };
  const std::string why =
      "pose.position.x: 1.7e+308 m is beyond where the monitor can resolve a contact (|x| must be "
      "below 2^1022 = 4.49423283715579e+307 m";
  const ros::Time far = window();
  const auto diagnostics = diagnosticsOf(
      "/far/stack",
      [&] {
        for (int k = 0; k <= 10; ++k) {
          stack(far + ros::Duration(0, 100000000 * k), 1.7e308);
          MonitorHarness::waitFor([] { return false; }, 0.05);
        }
      },
      1.0);
  EXPECT_TRUE(harness_.waitForWarning({"dropped states[0] ('bottom'): " + why}, 5.0, "/far/stack"));
  EXPECT_TRUE(contacts.empty()) << "a contact was published for states the node refused";
  bool counted = false, named = false;
  for (const auto& status : diagnostics) {
    for (const auto& value : status.values) {
      counted = counted || (value.key == "dropped: position beyond resolution (total)" &&
                            std::stoi(value.value) >= 3);
      named = named || (value.key == "last state beyond resolution" &&
                        value.value.find("('top'): " + why) != std::string::npos);
    }
  }
  EXPECT_TRUE(counted) << "no count of the dropped states in /diagnostics";
  EXPECT_TRUE(named) << "/diagnostics does not name the body and the field";
  // The node lives, and the stack at x = 0 rests.
  const ros::Time near = window();
  for (int k = 0; k <= 10; ++k) {
    stack(near + ros::Duration(0, 100000000 * k), 0.0);
    MonitorHarness::waitFor([] { return false; }, 0.05);
  }
  ASSERT_TRUE(MonitorHarness::waitFor(
      [&] { return !contacts.empty() && contacts.back().contacts.size() == 3; }, 5.0));
  const double weight = 0.2 * 9.81;
  const auto& last = contacts.back().contacts;
  EXPECT_NEAR(last[0].normal_force, 2 * weight, 1e-9);
  EXPECT_NEAR(last[1].normal_force, 3 * weight, 1e-9);
  EXPECT_NEAR(last[2].normal_force, weight, 1e-9);
  for (const ContactArray& array : contacts) {
    for (const Contact& contact : array.contacts) {
      for (const double value : {contact.normal_force, contact.contact_point.x,
                                 contact.contact_point.z, contact.normal.z}) {
        EXPECT_TRUE(std::isfinite(value)) << "a non-finite number on /far/contacts";
      }
    }
  }
}

}  // namespace
}  // namespace collision_response::testing

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "hostile_input_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
