// The node's and the scene player's private parameters as they read them (the whole `~` tree,
// as ros::param::get returns it), against the README's tables; and the scene's body topics.
// No master needed.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include <ros/names.h>

#include "collision_response/ros/monitor_params.h"
#include "collision_response/ros/scene_loader.h"
#include "collision_response/ros/scene_player.h"
#include "readme_tables.h"

namespace collision_response {
namespace {

const std::string kNs = "/collision_response";

std::string loadError(const XmlRpc::XmlRpcValue& tree) {
  const auto params = MonitorParams::load(tree, kNs);
  return params ? "" : params.error().message();
}

XmlRpc::XmlRpcValue minimalScene() {
  XmlRpc::XmlRpcValue scene;
  scene["fixed_frame"] = "world";
  return scene;
}

/// A valid value of every parameter of the node.
std::map<std::string, XmlRpc::XmlRpcValue> nodeExamples() {
  return {{"scene", minimalScene()},
          {"player", XmlRpc::XmlRpcValue()},
          {"transform_timeout", 0.25},
          {"frame_velocity_interval", 0.02},
          {"obstacle_update_period", 0.005},
          {"body_timeout", 2.0},
          {"contact_tolerance", 1e-6},
          {"clock_jump_back", 3},  // an integer is a number
          {"future_stamp_tolerance", 30.0},
          {"queue_size", 7},
          {"max_states", 11},
          {"marker_rate", 10.0},
          {"impact_marker_lifetime", 1.5},
          {"impulse_marker_scale", 0.3},
          {"force_marker_scale", 0.05},
          {"plane_marker_size", 2.0},
          {"contact_marker_diameter", 0.05},
          {"diagnostic_period", 0.5},
          {"detection", "discrete"},
          {"restitution_threshold", 0.1},
          {"restitution_combine", "max"},
          {"prediction_cpu_budget", 0.25},
          {"calibration_window", 2.5}};
}

std::vector<std::string> documentedNames(const testing::Table& table) {
  std::vector<std::string> names;
  for (const auto& row : table) {
    for (const std::string& name : row) {
      if (name.rfind("~", 0) == 0) names.push_back(name.substr(1));
    }
  }
  return names;
}

TEST(MonitorParams, DefaultsWhenNothingIsSet) {
  const auto params = MonitorParams::load(XmlRpc::XmlRpcValue(), kNs);
  ASSERT_TRUE(params.ok());
  EXPECT_EQ(params->transform_timeout, 0.1);
  EXPECT_EQ(params->queue_size, 1000);
  EXPECT_EQ(params->max_states, 100000);
  EXPECT_EQ(params->future_stamp_tolerance, 300.0);
  EXPECT_EQ(params->prediction_cpu_budget, 1.0);
  EXPECT_EQ(params->calibration_window, 10.0);
}

// "A test fails if any documented parameter is refused": every `~name` of the README's table
// is read, and a valid value of it loads and arrives; every parameter read is documented.
TEST(MonitorParams, EveryDocumentedParameterLoadsAndEveryReadOneIsDocumented) {
  const auto tables = testing::readmeTables("### Parameters");
  ASSERT_GE(tables.size(), 2u) << "README.md: the node's and the scene player's tables";
  const std::vector<std::string> documented = documentedNames(tables[0]);
  const std::vector<std::string> read = keyNames(MonitorParams::keys());
  const auto examples = nodeExamples();
  XmlRpc::XmlRpcValue tree;
  for (const std::string& name : documented) {
    EXPECT_NE(std::find(read.begin(), read.end(), name), read.end())
        << "~" << name << " is documented but the node does not read it";
    ASSERT_EQ(examples.count(name), 1u) << "no example value for the documented ~" << name;
    if (examples.at(name).getType() != XmlRpc::XmlRpcValue::TypeInvalid) {
      tree[name] = examples.at(name);
    }
  }
  for (const std::string& name : read) {
    EXPECT_NE(std::find(documented.begin(), documented.end(), name), documented.end())
        << "~" << name << " is read but not documented in README.md";
  }
  tree["player"]["frames"].setSize(0);
  const auto params = MonitorParams::load(tree, kNs);
  ASSERT_TRUE(params.ok()) << "a documented parameter is refused: " << params.error().message();
  EXPECT_EQ(params->transform_timeout, 0.25);
  EXPECT_EQ(params->frame_velocity_interval, 0.02);
  EXPECT_EQ(params->obstacle_update_period, 0.005);
  EXPECT_EQ(params->body_timeout, 2.0);
  EXPECT_EQ(params->contact_tolerance, 1e-6);
  EXPECT_EQ(params->clock_jump_back, 3.0);
  EXPECT_EQ(params->future_stamp_tolerance, 30.0);
  EXPECT_EQ(params->queue_size, 7);
  EXPECT_EQ(params->max_states, 11);
  EXPECT_EQ(params->prediction_cpu_budget, 0.25);
  EXPECT_EQ(params->markers.rate, 10.0);
  EXPECT_EQ(params->markers.impact_lifetime, 1.5);
  EXPECT_EQ(params->markers.impulse_scale, 0.3);
  EXPECT_EQ(params->markers.plane_size, 2.0);
  EXPECT_EQ(params->markers.contact_diameter, 0.05);
  EXPECT_EQ(params->diagnostic_period, 0.5);
  EXPECT_EQ(params->calibration_window, 2.5);
}

TEST(ScenePlayerParams, EveryDocumentedParameterLoadsAndEveryReadOneIsDocumented) {
  const auto tables = testing::readmeTables("### Parameters");
  ASSERT_GE(tables.size(), 2u);
  const std::vector<std::string> documented = documentedNames(tables[1]);
  const std::vector<std::string> read = keyNames(ScenePlayerParams::keys());
  const std::map<std::string, XmlRpc::XmlRpcValue> examples = {
      {"scene", minimalScene()},   {"rate", 50},
      {"duration", 2.5},           {"start_delay", 0.0},
      {"contact_tolerance", 1e-7}, {"report_restitution", true},
      {"replay_window", 0.5}};
  XmlRpc::XmlRpcValue tree;
  for (const std::string& name : documented) {
    EXPECT_NE(std::find(read.begin(), read.end(), name), read.end())
        << "~" << name << " is documented but the scene player does not read it";
    if (name == "player") {
      tree["player"]["frames"].setSize(0);
      continue;
    }
    ASSERT_EQ(examples.count(name), 1u) << "no example value for the documented ~" << name;
    tree[name] = examples.at(name);
  }
  for (const std::string& name : read) {
    EXPECT_NE(std::find(documented.begin(), documented.end(), name), documented.end())
        << "~" << name << " is read but not documented in README.md";
  }
  const auto params = ScenePlayerParams::load(tree, "/scene_player");
  ASSERT_TRUE(params.ok()) << "a documented parameter is refused: " << params.error().message();
  EXPECT_EQ(params->rate, 50.0);
  EXPECT_EQ(params->duration, 2.5);
  EXPECT_EQ(params->start_delay, 0.0);
  EXPECT_EQ(params->contact_tolerance, 1e-7);
  EXPECT_TRUE(params->report_restitution);
}

// Issue 13, item 8: wrong-typed parameters once started the node with the defaults, without a
// word. Each is now a start-up error naming the key and what it got.
TEST(MonitorParams, WrongTypesAreErrorsNamingTheKey) {
  XmlRpc::XmlRpcValue list;
  list[0] = 1;
  list[1] = 2;
  const std::vector<std::pair<std::string, XmlRpc::XmlRpcValue>> cases = {
      {"transform_timeout", "abc"}, {"max_states", "lots"}, {"queue_size", true},
      {"body_timeout", list},       {"queue_size", 2.5},    {"marker_rate", "fast"},
      {"diagnostic_period", false}, {"detection", 3},       {"scene", "drop_test.yaml"}};
  for (const auto& [key, value] : cases) {
    XmlRpc::XmlRpcValue tree;
    tree[key] = value;
    const std::string error = loadError(tree);
    EXPECT_EQ(error.rfind(kNs + "/" + key + ": must be ", 0), 0u) << key << ": " << error;
  }
  XmlRpc::XmlRpcValue tree;
  tree["transform_timeout"] = "abc";
  EXPECT_EQ(loadError(tree), kNs + "/transform_timeout: must be a number, got a string ('abc')");
  tree = XmlRpc::XmlRpcValue();
  tree["queue_size"] = true;
  EXPECT_EQ(loadError(tree), kNs + "/queue_size: must be an integer, got a boolean (true)");
}

// Issue 13, item 7: `contact_tolerance: 1e6` (a fraction) was accepted and bodies 10 m apart
// "touched".
TEST(MonitorParams, ValuesOutOfRangeAreErrors) {
  const std::vector<std::pair<std::string, XmlRpc::XmlRpcValue>> cases = {
      {"contact_tolerance", 1e6},
      {"contact_tolerance", 1.0},
      {"contact_tolerance", -1e-9},
      {"transform_timeout", -0.1},
      {"body_timeout", 0.0},
      {"clock_jump_back", -1.0},
      {"queue_size", 0},
      {"max_states", -5},
      {"future_stamp_tolerance", 0.0},
      {"marker_rate", std::numeric_limits<double>::infinity()},
      {"frame_velocity_interval", 0.0},
      {"obstacle_update_period", -0.001},
      {"diagnostic_period", -1.0},
      {"prediction_cpu_budget", -1.0},
      {"calibration_window", -1.0},
      {"calibration_window", std::numeric_limits<double>::quiet_NaN()}};
  for (const auto& [key, value] : cases) {
    XmlRpc::XmlRpcValue tree;
    tree[key] = value;
    const std::string error = loadError(tree);
    EXPECT_EQ(error.rfind(kNs + "/" + key + ": ", 0), 0u) << key << ": " << error;
  }
  XmlRpc::XmlRpcValue tree;
  tree["contact_tolerance"] = 1e6;
  EXPECT_NE(loadError(tree).find("[0, 1)"), std::string::npos) << loadError(tree);
}

TEST(MonitorParams, AnUnknownParameterIsAnErrorNamingIt) {
  XmlRpc::XmlRpcValue tree;
  tree["transform_timout"] = 0.5;  // a typo would be a silent default
  const std::string error = loadError(tree);
  EXPECT_EQ(error.rfind(kNs + "/transform_timout: unknown key", 0), 0u) << error;
  EXPECT_NE(error.find("transform_timeout"), std::string::npos) << "the known ones are listed";
}

core::Scene sceneWithTopics(const std::vector<std::string>& topics) {
  core::Scene scene;
  for (std::size_t i = 0; i < topics.size(); ++i) {
    core::BodySpec body;
    body.id = "b" + std::to_string(i);
    body.material = "tennis_ball";
    body.radius = 0.1;
    body.topic = topics[i];
    scene.bodies.push_back(body);
  }
  return scene;
}

std::string topicError(const std::vector<std::string>& topics, const std::string& ns = "/") {
  const auto status =
      checkBodyTopics(sceneWithTopics(topics), ns,
                      ros::names::resolve(ns, std::string("body_states")), "/cr/scene");
  return status ? "" : status.error().message();
}

// Issue 13, items 6 and 7: a body topic that is not a valid name, or is `body_states`, aborted
// the node (ros::InvalidNameException, ConflictingSubscriptionException; as a nodelet "Failed to
// load"); two bodies on one topic were accepted and a right state was then warned as the other
// body's. Each is now an error naming the body's key.
// Issue 27, item 4: a duration past what a ros::Duration holds (its seconds an int32, at most
// 2^31 - 1 = 2147483647 s) passed the start-up check, then killed or blinded the node:
// `~diagnostic_period: 1e10` ended it with "Duration is out of dual 32-bit range", naming no
// key; `~frame_velocity_interval: 1e10` and `~impact_marker_lifetime: 1e10` made every message
// an internal error. Every duration is now checked at start-up, the key named: 2147483647 s
// (exactly representable) is the longest accepted, and one nanosecond the shortest nonzero.
const std::vector<std::string> kDurationKeys = {"transform_timeout",      "frame_velocity_interval",
                                                "body_timeout",           "clock_jump_back",
                                                "future_stamp_tolerance", "impact_marker_lifetime",
                                                "diagnostic_period",      "obstacle_update_period"};

std::string durationError(const std::string& key, double seconds) {
  XmlRpc::XmlRpcValue tree;
  tree[key] = seconds;
  return loadError(tree);
}

TEST(MonitorParams, EveryDurationIsBoundedByWhatARosDurationHolds) {
  for (const std::string& key : kDurationKeys) {
    EXPECT_EQ(durationError(key, 2147483647.0), "") << key;
    EXPECT_EQ(durationError(key, 1e-9), "") << key;
    EXPECT_EQ(durationError(key, 1e10),
              kNs + "/" + key + ": 1e+10 s is longer than a ros::Duration can hold (2147483647 s)");
    EXPECT_EQ(
        durationError(key, 2147483648.0),
        kNs + "/" + key + ": 2147483648 s is longer than a ros::Duration can hold (2147483647 s)");
    EXPECT_EQ(durationError(key, 1e-10),
              kNs + "/" + key +
                  ": 1e-10 s is shorter than a ros::Duration can hold (1e-09 s, one nanosecond)");
  }
  EXPECT_EQ(durationError("transform_timeout", 0.0), "");       // 0: never wait, as before
  EXPECT_EQ(durationError("obstacle_update_period", 0.0), "");  // 0: once an update
  EXPECT_EQ(durationError("diagnostic_period", 0.0),
            kNs + "/diagnostic_period: must be a finite number of seconds > 0, got 0");
}

// A rate's period 1/rate is the duration: 2^-30 Hz (period 2^30 s) and 1e9 Hz (1/1e9 rounds to
// the double nearest 1e-9, as the literal 1e-9 does) are the accepted edges; 2^-31 Hz (period
// 2^31 = 2147483648 s) and 2^30 Hz (period 2^-30 s, 9.3e-10 s) are past them.
TEST(MonitorParams, AMarkerRateWhosePeriodNoRosDurationHoldsIsAnError) {
  EXPECT_EQ(durationError("marker_rate", 9.313225746154785e-10), "");
  EXPECT_EQ(durationError("marker_rate", 1e9), "");
  EXPECT_EQ(durationError("marker_rate", 4.656612873077393e-10),
            kNs +
                "/marker_rate: 4.656612873077393e-10 Hz is too slow: its period, 2147483648 s, "
                "is longer than a ros::Duration can hold (2147483647 s)");
  EXPECT_EQ(durationError("marker_rate", 1073741824.0),
            kNs +
                "/marker_rate: 1073741824 Hz is too fast: its period, 9.313225746154785e-10 s, "
                "is shorter than a ros::Duration can hold (1e-09 s, one nanosecond)");
}

std::string playerError(const std::string& key, double value) {
  XmlRpc::XmlRpcValue tree;
  tree["scene"] = minimalScene();
  tree[key] = value;
  const auto params = ScenePlayerParams::load(tree, "/scene_player");
  return params ? "" : params.error().message();
}

TEST(ScenePlayerParams, ItsRateDurationAndStartDelayAreBoundedAsDurations) {
  EXPECT_EQ(playerError("rate", 9.313225746154785e-10), "");
  EXPECT_EQ(playerError("rate", 1e9), "");
  EXPECT_EQ(playerError("rate", 4.656612873077393e-10),
            "/scene_player/rate: 4.656612873077393e-10 Hz is too slow: its period, 2147483648 s, "
            "is longer than a ros::Duration can hold (2147483647 s)");
  EXPECT_EQ(playerError("rate", 1e-10).rfind("/scene_player/rate: 1e-10 Hz is too slow", 0), 0u);
  for (const std::string key : {"duration", "start_delay"}) {
    EXPECT_EQ(playerError(key, 0.0), "") << key;
    EXPECT_EQ(playerError(key, 2147483647.0), "") << key;
    EXPECT_EQ(playerError(key, 1e10), "/scene_player/" + key +
                                          ": 1e+10 s is longer than a ros::Duration can hold "
                                          "(2147483647 s)");
  }
}

// Issue 41, item 10: ~replay_window keeps one model of the scene per period: a duration >= 0 of
// at most 1,000 periods of ~rate (the default, 0.25 s, shrinks to 1,000 periods above 4 kHz).
TEST(ScenePlayerParams, ItsReplayWindowIsADurationOfAtMostAThousandPeriods) {
  EXPECT_EQ(playerError("replay_window", 0.0), "");
  EXPECT_EQ(playerError("replay_window", 10.0), "");  // 1,000 periods at the default 100 Hz
  EXPECT_EQ(playerError("replay_window", 10.5),
            "/scene_player/replay_window: 10.5 s at ~rate 100 Hz is 1050 periods: at most 1000");
  EXPECT_EQ(playerError("replay_window", -1.0),
            "/scene_player/replay_window: must be a finite number of seconds >= 0, got -1");
  XmlRpc::XmlRpcValue tree;
  tree["scene"] = minimalScene();
  tree["rate"] = 1e6;
  const auto fast = ScenePlayerParams::load(tree, "/scene_player");
  ASSERT_TRUE(fast.ok());
  EXPECT_EQ(fast->replay_window, 1e-3);
}

// The re-read of one key while the node runs (~diagnostic_period) is the start-up's reader:
// a refused value names the key and leaves the value in use as it was.
TEST(MonitorParams, AReReadKeyIsCheckedAsAtStartUp) {
  MonitorParams params;
  params.diagnostic_period = 0.2;
  const auto status = readKey(XmlRpc::XmlRpcValue(1e10), MonitorParams::keys(), "diagnostic_period",
                              kNs + "/diagnostic_period", params);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message(),
            kNs +
                "/diagnostic_period: 1e+10 s is longer than a ros::Duration can hold "
                "(2147483647 s)");
  EXPECT_EQ(params.diagnostic_period, 0.2);
  ASSERT_TRUE(readKey(XmlRpc::XmlRpcValue(3), MonitorParams::keys(), "diagnostic_period",
                      kNs + "/diagnostic_period", params)
                  .ok());
  EXPECT_EQ(params.diagnostic_period, 3.0);
}

TEST(BodyTopics, InvalidConflictingAndSharedTopicsAreErrors) {
  EXPECT_EQ(topicError({"/a/state", "b/state", ""}), "");
  for (const std::string bad : {"bad topic", "1abc", "a//b?", "~private"}) {
    const std::string error = topicError({"/ok", bad});
    EXPECT_EQ(error.rfind("/cr/scene/bodies[1]/topic: '" + bad + "'", 0), 0u) << error;
  }
  EXPECT_EQ(topicError({"body_states"})
                .rfind("/cr/scene/bodies[0]/topic: 'body_states' is "
                       "/body_states",
                       0),
            0u)
      << topicError({"body_states"});
  EXPECT_EQ(topicError({"/robot/body_states"}, "/robot").rfind("/cr/scene/bodies[0]/topic", 0), 0u);
  const std::string shared = topicError({"/a", "/b", "a"});
  EXPECT_EQ(shared.rfind("/cr/scene/bodies[2]/topic: 'a' (/a) is already the topic of 'b0'", 0), 0u)
      << shared;
}

}  // namespace
}  // namespace collision_response
